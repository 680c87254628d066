#!/usr/bin/python3
"""The parameter commissioning_file (node_commissioning.test): `ranger_can commission
sim:spin_cw --wheels-lifted --output FILE` commissions the virtual chassis whose positive spin
turns clockwise (in simulated time: it takes a fraction of a second), and the node started with
that file drives it right: the settings are the file's (forced, spin_sign cw), logged at start,
and a spin asked counter-clockwise turns counter-clockwise without a plausibility stop. Without
the file, protocol manual on the same variant is stopped (node_sim_implausible.test)."""

import math
import os
import shutil
import subprocess
import tempfile
import threading
import time
import unittest

import roslib.packages
import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState

NS = "commissioned"


def wait_for(condition, timeout=60.0, interval=0.02):
    """Polls condition(); the timeout only bounds how long a failing test waits."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(interval)
    return bool(condition())


def find_executable(name):
    found = shutil.which(name)
    if found:
        return found
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        candidate = os.path.join(prefix, "bin", name)
        if os.access(candidate, os.X_OK):
            return candidate
    raise RuntimeError(f"{name} not found on PATH or under CMAKE_PREFIX_PATH")


class Commissioning(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_commissioning")
        cls.tmp = tempfile.mkdtemp(prefix="ranger-commissioning-test-")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_a_commissioned_chassis_is_driven_with_the_files_settings(self):
        path = os.path.join(self.tmp, "spin_cw.yaml")
        commission = subprocess.run(
            [find_executable("ranger_can"), "commission", "sim:spin_cw", "--wheels-lifted",
             "--output", path], capture_output=True, text=True, timeout=120)
        self.assertEqual(commission.returncode, 0, commission.stdout + commission.stderr)
        with open(path, encoding="utf-8") as f:
            self.assertIn("spin_sign: cw", f.read())

        exe = roslib.packages.find_node("ranger_base", "ranger_base_node")[0]
        node = subprocess.Popen([exe, f"__ns:=/{NS}", "__name:=ranger_base_node",
                                 "_port_name:=sim:spin_cw", f"_commissioning_file:={path}"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                env=dict(os.environ, ROSCONSOLE_STDOUT_LINE_BUFFERED="1"))
        lines = []

        def read():
            for line in node.stdout:
                lines.append(line)
        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        state, truth = {}, {}
        subs = [rospy.Subscriber(f"/{NS}/system_state", SystemState,
                                 lambda m: state.update(m=m)),
                rospy.Subscriber(f"/{NS}/sim/ground_truth", Odometry,
                                 lambda m: truth.update(m=m))]
        cmd = rospy.Publisher(f"/{NS}/cmd_vel", Twist, queue_size=10)
        try:
            self.assertTrue(wait_for(lambda: "m" in state and state["m"].link_up
                                     and state["m"].control_mode == SystemState.CONTROL_MODE_CAN
                                     and "m" in truth and cmd.get_num_connections() > 0),
                            "the node never reached CAN command mode:\n" + "".join(lines))
            s = state["m"]
            self.assertEqual(s.protocol, "forced")
            self.assertEqual(s.identification, "")  # nothing to identify: the file says it
            self.assertEqual(s.protocol_profile, "manual with spin_sign=cw")
            self.assertTrue(wait_for(lambda: any(
                "protocol settings manual with spin_sign=cw (forced: commissioning file " + path
                in line for line in lines), 10), "".join(lines))

            # A spin asked counter-clockwise turns counter-clockwise, and nothing stops it.
            spin = Twist()
            spin.angular.z = 0.5

            def spinning_ccw():
                cmd.publish(spin)
                return truth["m"].twist.twist.angular.z > 0.4
            self.assertTrue(wait_for(spinning_ccw, 30, interval=0.05),
                            f"{truth['m'].twist.twist} / {state['m'].motion_inhibited_detail}")
            yaw0 = truth["m"].pose.pose.orientation
            turned = [0.0]
            last = [2 * math.atan2(yaw0.z, yaw0.w)]

            def turned_a_quarter():
                cmd.publish(spin)
                q = truth["m"].pose.pose.orientation
                yaw = 2 * math.atan2(q.z, q.w)
                turned[0] += math.remainder(yaw - last[0], 2 * math.pi)
                last[0] = yaw
                return turned[0] > math.pi / 2
            self.assertTrue(wait_for(turned_a_quarter, 30, interval=0.05))
            self.assertNotEqual(state["m"].motion_inhibited_reason, "implausible_feedback",
                                state["m"].motion_inhibited_detail)
            self.assertFalse([line for line in lines
                              if "plausibility:" in line or "plausibility stop" in line],
                             "".join(lines))
            cmd.publish(Twist())
        finally:
            for sub in subs:
                sub.unregister()
            cmd.unregister()
            node.terminate()
            node.wait(timeout=30)


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_commissioning", Commissioning)
