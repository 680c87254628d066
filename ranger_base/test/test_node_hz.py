#!/usr/bin/python3
"""The publication rates (node_sim_hz.test): odom, joint_states and /tf at publish_rate (25 Hz
there) and system_state at state_publish_rate (5 Hz), each within the bound rostest's hztest
used (rate ± 3 Hz and ± 1 Hz over 5 s, from the first message to the last).

Measured as hztest measures, the four topics over the same 5 s, and each rate printed with its
bound ([measured] lines: scripts/test.sh's summary shows them, the margin this run had)."""

import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

DURATION_S = 5.0
# topic: (type, rate, allowed error), as node_sim_hz.test's parameters
EXPECTED = {
    "odom": (Odometry, 25.0, 3.0),
    "joint_states": (JointState, 25.0, 3.0),
    "/tf": (TFMessage, 25.0, 3.0),
    "system_state": (SystemState, 5.0, 1.0),
}


class Rates(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_hz")
        cls.stamps = {topic: [] for topic in EXPECTED}
        subs = [rospy.Subscriber(topic, msg_type, cls._stamp(topic))
                for topic, (msg_type, _, _) in EXPECTED.items()]
        # Every topic heard, then one window of DURATION_S for all four (a failing start is
        # bounded only so that it fails).
        end = time.monotonic() + 60.0
        while not all(cls.stamps.values()) and time.monotonic() < end:
            time.sleep(0.02)
        for stamps in cls.stamps.values():
            stamps.clear()
        rospy.sleep(DURATION_S)
        for sub in subs:
            sub.unregister()

    @classmethod
    def _stamp(cls, topic):
        def callback(_):
            cls.stamps[topic].append(time.monotonic())
        return callback

    def check(self, topic):
        _, rate, error = EXPECTED[topic]
        stamps = self.stamps[topic]
        self.assertGreater(len(stamps), 1, f"{topic}: {len(stamps)} messages in {DURATION_S} s")
        measured = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        print(f"[measured] {topic}: {measured:.2f} Hz over {DURATION_S:g} s "
              f"(bound {rate - error:g}-{rate + error:g} Hz, margin "
              f"{min(measured - (rate - error), rate + error - measured):.2f} Hz)", flush=True)
        self.assertGreaterEqual(measured, rate - error, topic)
        self.assertLessEqual(measured, rate + error, topic)

    def test_odom(self):
        self.check("odom")

    def test_joint_states(self):
        self.check("joint_states")

    def test_tf(self):
        self.check("/tf")

    def test_system_state(self):
        self.check("system_state")


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_sim_hz", Rates)
