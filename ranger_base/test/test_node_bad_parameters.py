#!/usr/bin/python3
"""ranger_base_node refuses to start on invalid parameters (node_bad_parameters.test): exit
status 2 and, for every bad parameter, a message naming it and its valid range (or values: an
unknown model, protocol or interpretation setting value lists the valid ones; a commissioning
file the loader refuses is named with the loader's message)."""

import os
import subprocess
import tempfile
import unittest

import roslib.packages
import rostest


def node_executable():
    found = roslib.packages.find_node("ranger_base", "ranger_base_node")
    if not found:
        raise RuntimeError("ranger_base_node not found (is the workspace sourced?)")
    return found[0]


class BadParameters(unittest.TestCase):
    def run_node(self, *args):
        # Each run gets a name of its own so the private parameters do not leak between runs.
        name = f"bad_params_{self.id().rsplit('.', 1)[-1]}"
        return subprocess.run([node_executable(), f"__name:={name}", *args],
                              capture_output=True, text=True, timeout=30, env=os.environ)

    def test_each_bad_parameter_is_named_with_its_range(self):
        result = self.run_node("_publish_rate:=-5", "_odometry_source:=gps",
                               "_cmd_vel_timeout:=0", "_port_name:=sim")
        self.assertEqual(result.returncode, 2, result.stderr)
        out = result.stdout + result.stderr
        for expected in ("publish_rate", "(0, 50] Hz", "odometry_source",
                         '"wheels" or "motion"', "cmd_vel_timeout", "[0.02, 60] s",
                         "not started"):
            self.assertIn(expected, out)

    def test_unknown_model_protocol_and_setting_values_list_the_valid_ones(self):
        result = self.run_node("_model:=ranger_maxi", "_protocol:=agx_v3",
                               "_steering_unit_111:=mrad", "_tx_dlc:=5", "_port_name:=sim")
        self.assertEqual(result.returncode, 2, result.stderr)
        out = result.stdout + result.stderr
        for expected in ("model", "ranger, ranger_mini_v1, ranger_mini_v2, ranger_mini_v3",
                         "protocol", "auto, manual, agx_v2", "steering_unit_111",
                         "centideg, millirad", "tx_dlc", "0, 8", "not started"):
            self.assertIn(expected, out)

    def test_a_bad_commissioning_file_is_refused_with_the_loaders_message(self):
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            f.write("protocol: manual\nspin_sign: backwards\n")
        try:
            result = self.run_node(f"_commissioning_file:={f.name}", "_port_name:=sim")
        finally:
            os.unlink(f.name)
        self.assertEqual(result.returncode, 2, result.stderr)
        out = result.stdout + result.stderr
        for expected in ("commissioning_file", f.name, "line 2", "spin_sign", "ccw|cw"):
            self.assertIn(expected, out)
        missing = self.run_node("_commissioning_file:=/nonexistent/ranger.yaml", "_port_name:=sim")
        self.assertEqual(missing.returncode, 2, missing.stderr)
        self.assertIn("/nonexistent/ranger.yaml", missing.stdout + missing.stderr)

    def test_a_wrong_type_is_reported(self):
        result = self.run_node("_publish_odom_tf:=maybe", "_port_name:=sim")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("publish_odom_tf", result.stdout + result.stderr)
        self.assertIn("expected true or false", result.stdout + result.stderr)


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_bad_parameters", BadParameters)
