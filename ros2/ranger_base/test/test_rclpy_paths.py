"""rclpy's private API (ranger_base/rclpy_fast.py: cmd_vel on a wait set of its own, the
parameter overrides) and its public fallback: the path is chosen once at start-up and said once
in the log; RANGER_RCLPY_PATH=public forces the public one. The node's key behaviour on each path,
on each distribution this stage runs: it drives (the ground truth moves), answers services (a
success and a refusal) and drives again, publishes odometry in the frame it was given, and
refuses bad parameters at start-up naming each."""

import os
import subprocess

import pytest
from std_srvs.srv import SetBool, Trigger

from ranger_base import rclpy_fast
from support import node_executable, ros_args

NS_PREFIX = "path"
PATHS = [rclpy_fast.FAST, rclpy_fast.PUBLIC]


def env_of(path):
    # "auto" for the fast path: the default choice, which takes it where rclpy has it.
    return {rclpy_fast.ENV: "public" if path == rclpy_fast.PUBLIC else "auto"}


# ---- the choice ------------------------------------------------------------------------------

def test_the_fast_path_is_chosen_where_rclpy_has_it_and_public_when_asked():
    assert rclpy_fast.missing_private_names() == []  # both distributions tested here have it
    assert rclpy_fast.decide({}).path == rclpy_fast.FAST
    forced = rclpy_fast.decide({rclpy_fast.ENV: "public"})
    assert forced.path == rclpy_fast.PUBLIC
    assert forced.line() == f"rclpy: the public path ({rclpy_fast.ENV}=public)"
    assert "unknown" in rclpy_fast.decide({rclpy_fast.ENV: "quick"}).line()


def test_an_rclpy_without_the_private_names_gets_the_public_path(monkeypatch):
    impl = rclpy_fast._private_api()
    monkeypatch.delattr(impl, "WaitSet")
    chosen = rclpy_fast.decide({})
    assert chosen.path == rclpy_fast.PUBLIC
    assert "_rclpy.WaitSet" in chosen.why, chosen.why


# ---- the node on each path -------------------------------------------------------------------

@pytest.mark.parametrize("path", PATHS)
def test_on_each_path_the_node_drives_answers_and_publishes_odometry(robots, path):
    r = robots("sim", env=env_of(path), odom_frame="path_odom")
    r.wait_ready()
    line = f"rclpy: the {path} path ("
    r.client.wait_for(lambda: line in r.process.output(), 30, f"'{line}' in the log")

    def drives(what):
        r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.4
                          and r.odom().twist.twist.linear.x > 0.4, 30, what,
                          pace=lambda: r.send(vx=0.5))
        r.client.wait_for(lambda: abs(r.truth().twist.twist.linear.x) < 1e-3, 30, "rest",
                          pace=lambda: r.send())
    drives(f"driving on the {path} path")
    assert r.odom().header.frame_id == "path_odom"  # the parameter given reached the driver
    resumed = r.client.call(Trigger, f"{r.ns}/resume", Trigger.Request())
    assert resumed.success, resumed.message
    parked = r.client.call(SetBool, f"{r.ns}/park", SetBool.Request(data=True))
    assert not parked.success and "park: unsupported" in parked.message, parked.message
    drives(f"driving after the services on the {path} path")
    assert r.process.output().count("rclpy: the ") == 1  # said once


@pytest.mark.parametrize("path", PATHS)
def test_on_each_path_bad_parameters_refuse_start_up_naming_each(path):
    # Refused by rclpy for their range (cmd_vel_timeout, publish_rate, wheelbase: read back by the
    # path's own means), and given values the library refuses (model, base_frame).
    params = {"port_name": "sim", "cmd_vel_timeout": 100.0, "publish_rate": 100.0,
              "model": "ranger_maxi", "wheelbase": -1.0, "base_frame": "odom"}
    result = subprocess.run([node_executable()] + ros_args(params, f"/bad_{path}"),
                            capture_output=True, text=True, timeout=60, check=False,
                            env=dict(os.environ, **env_of(path)))
    out = result.stdout + result.stderr
    assert result.returncode == 2, out
    prefix = f"parameter /bad_{path}/ranger_base_node."
    for expected in (
            prefix + "cmd_vel_timeout = 100 is out of range: valid [0.02, 60] s",
            prefix + "publish_rate = 100 is out of range: valid (0, 50] Hz",
            prefix + "model = \"ranger_maxi\": expected one of ranger, ranger_mini_v1",
            prefix + "wheelbase = -1 is out of range: valid (0, 10] m",
            prefix + "base_frame = \"odom\" must differ from odom_frame"):
        assert expected in out, out

