"""The ROS 2 node's parameters are the library's table (ranger_can.parameters(), the ROS 1 node's
rows) and diagnostic_period (diagnostic_updater's own in ROS 1): nothing declared beside them,
nothing of them left out, each descriptor made from its row. Fails when the node's declarations
drift from the library's table."""

import pytest
import rclpy
from rcl_interfaces.msg import ParameterType as PT
from rclpy.parameter import Parameter

import ranger_can
from ranger_base import parameters, rclpy_fast


def test_declared_names_are_the_librarys_table_and_diagnostic_period():
    table = [r.name for r in ranger_can.parameters()]
    assert parameters.declared_names() == table + ["diagnostic_period"]


def test_descriptors_come_from_the_rows():
    for row in ranger_can.parameters():
        d = parameters.descriptor(row)
        assert d.name == parameters.ros2_name(row.name)
        assert d.read_only == (row.name not in ("publish_rate", "state_publish_rate")), row.name
        assert row.valid in d.additional_constraints, row.name
        assert d.description.startswith(row.meaning), row.name
        if row.type == "double" and row.has_range:
            assert (d.floating_point_range[0].from_value,
                    d.floating_point_range[0].to_value) == (row.lo, row.hi), row.name
    rows = {r.name: r for r in ranger_can.parameters()}
    assert parameters.descriptor(rows["mode_switch_max_attempts"]).type == PT.PARAMETER_INTEGER
    assert parameters.descriptor(rows["sim/errors"]).type == PT.PARAMETER_STRING_ARRAY
    assert parameters.default_of(rows["wheelbase"]) is None  # the model's
    assert parameters.default_of(rows["publish_rate"]) == 50.0


def test_declaration_hands_the_library_what_was_given(ros):
    node = rclpy.create_node("declare_test", parameter_overrides=[
        Parameter("odom_frame", value="robot1/odom"), Parameter("tx_dlc", value=8),
        Parameter("linear.x.max_velocity", value=1.5), Parameter("diagnostic_period", value=2.0)])
    try:
        declared = parameters.declare_all(node, "/declare_test.")
        assert declared.errors == []
        assert declared.diagnostic_period == 2.0
        # tx_dlc given as a number (as ROS 1 YAML may): refused by its string descriptor, handed
        # to the library, which takes it as its text.
        assert declared.given == {"odom_frame": "robot1/odom", "tx_dlc": 8,
                                  "linear/x/max_velocity": 1.5}
        declared_names = {n.replace(".", "/") for n in node._parameters}
        assert set(parameters.declared_names()) <= declared_names
        with ranger_can.Driver("sim", params=declared.given, start=False) as d:
            assert d.settings["odom_frame"] == "robot1/odom"
    finally:
        node.destroy_node()


@pytest.mark.parametrize("path", [rclpy_fast.FAST, rclpy_fast.PUBLIC])
def test_each_path_hands_the_library_what_was_given_and_what_rclpy_refused(ros, monkeypatch,
                                                                           path):
    """The fast path reads rclpy's overrides; the public one the declared values and, for a value
    rclpy refuses, a declaration without constraints: the library gets the same either way."""
    monkeypatch.setattr(rclpy_fast, "_choice", rclpy_fast.Choice(path, "this test"))
    node = rclpy.create_node(f"declare_{path}", parameter_overrides=[
        Parameter("odom_frame", value="robot1/odom"), Parameter("tx_dlc", value=8),
        Parameter("publish_rate", value=100.0), Parameter("wheelbase", value=0.6),
        Parameter("cmd_vel_timeout", value=0.4)])
    try:
        declared = parameters.declare_all(node, f"/declare_{path}.")
        assert declared.errors == []
        assert declared.given == {"odom_frame": "robot1/odom", "tx_dlc": 8, "publish_rate": 100.0,
                                  "wheelbase": 0.6, "cmd_vel_timeout": 0.4}, path
        # The refused ones are declared nonetheless, with their descriptors.
        assert node.describe_parameter("publish_rate").read_only is False
        assert node.describe_parameter("tx_dlc").read_only is True
    finally:
        node.destroy_node()
