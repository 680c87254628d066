"""The node's log lines reach rclpy's logger whatever came before them: rclpy keeps a logging
call's context (severity, throttling) by its call site and refuses a different one there with
ValueError, which loses the line (and, on the cmd_vel thread, costs a pause). The library's events
of every severity go through one method (RangerNode._log_at), and the node's own warnings come
from several sites, throttled and not."""

import types

import pytest
import rclpy
import rclpy.logging
from geometry_msgs.msg import Twist

from ranger_base import conversions
from ranger_base.node import RangerNode


@pytest.fixture
def node_stub():
    """What _log_at and _on_cmd_vel use of a RangerNode: a logger of rclpy's, a driver that takes
    every command, the message reader."""
    rclpy.init()
    commands = []
    logger = rclpy.logging.get_logger("ranger_test_logging")
    stub = types.SimpleNamespace(
        get_logger=lambda: logger, _twist_values=conversions.twist_values,
        driver=types.SimpleNamespace(command=lambda *a, **k: commands.append((a, k))),
        commands=commands)
    stub._drive = lambda values, age=None: RangerNode._drive(stub, values, age)
    yield stub
    rclpy.try_shutdown()


def test_events_of_every_severity_in_any_order_are_logged(node_stub):
    for severity in ("info", "error", "warn", "debug", "info", "warn", "error", "debug"):
        RangerNode._log_at(node_stub, severity, f"a line at {severity}")


def test_a_throttled_warning_after_an_unthrottled_one_is_logged(node_stub):
    RangerNode._log_at(node_stub, "warn", "an event's warning, not throttled")
    twist = Twist()
    twist.linear.x, twist.linear.z = 0.2, 0.1  # linear.z: the throttled "ignored" warning
    RangerNode._on_cmd_vel(node_stub, twist)
    RangerNode._on_cmd_vel(node_stub, twist)
    assert len(node_stub.commands) == 2
    assert node_stub.commands[0] == ((0.2, 0.0, 0.0), {"vz": 0.1, "wx": 0.0, "wy": 0.0})
