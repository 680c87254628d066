#!/usr/bin/python3
"""ranger_base_node refuses to start on invalid parameters (node_bad_parameters.test): exit
status 2 and, for every bad parameter, a message naming it and its valid range."""

import os
import subprocess
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
        for expected in ("publish_rate", "(0, 1000] Hz", "odometry_source",
                         '"wheels" or "motion"', "cmd_vel_timeout", "[0.02, 60] s",
                         "not started"):
            self.assertIn(expected, out)

    def test_a_wrong_type_is_reported(self):
        result = self.run_node("_publish_odom_tf:=maybe", "_port_name:=sim")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("publish_odom_tf", result.stdout + result.stderr)
        self.assertIn("expected true or false", result.stdout + result.stderr)


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_bad_parameters", BadParameters)
