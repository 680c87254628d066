#!/usr/bin/python3
"""Two namespaced ranger_base_node instances (node_namespaces.test): names stay in their
namespace, and a cmd_vel for one robot never moves the other."""

import math
import time
import unittest

import rosgraph
import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState

# Global by their own conventions, not by our choice.
GLOBAL_TOPICS = {"/tf", "/diagnostics", "/rosout"}
ROBOTS = ("robot1", "robot2")


def wait_for(condition, timeout=30.0):
    """Polls condition(); the timeout only bounds how long a failing test waits."""
    end = time.monotonic() + timeout
    while not rospy.is_shutdown() and time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.02)
    return bool(condition())


class TwoRobots(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_namespaces")
        cls.truth = {}
        cls.odom = {}
        cls.state = {}
        cls.subs = []
        cls.pubs = {}
        for robot in ROBOTS:
            cls.subs.append(rospy.Subscriber(f"/{robot}/sim/ground_truth", Odometry,
                                             cls._store(cls.truth, robot)))
            cls.subs.append(rospy.Subscriber(f"/{robot}/odom", Odometry,
                                             cls._store(cls.odom, robot)))
            cls.subs.append(rospy.Subscriber(f"/{robot}/system_state", SystemState,
                                             cls._store(cls.state, robot)))
            cls.pubs[robot] = rospy.Publisher(f"/{robot}/cmd_vel", Twist, queue_size=10)

    @staticmethod
    def _store(table, key):
        def callback(msg):
            table[key] = msg
        return callback

    def setUp(self):
        # protocol auto (the default): each node identifies its chassis before it drives.
        self.assertTrue(wait_for(lambda: all(
            r in self.state and self.state[r].link_up
            and self.state[r].control_mode == SystemState.CONTROL_MODE_CAN
            and self.state[r].identification == "decided"
            and r in self.truth and self.pubs[r].get_num_connections() > 0 for r in ROBOTS)),
            "both nodes should reach CAN command mode with their protocol settings identified")

    def test_names_are_relative(self):
        master = rosgraph.Master("/test_node_namespaces")
        publishers, subscribers, services = master.getSystemState()
        for robot in ROBOTS:
            node = f"/{robot}/ranger_base_node"
            published = {topic for topic, nodes in publishers if node in nodes}
            subscribed = {topic for topic, nodes in subscribers if node in nodes}
            offered = {srv for srv, nodes in services if node in nodes}
            self.assertIn(f"/{robot}/odom", published)
            self.assertIn(f"/{robot}/cmd_vel", subscribed)
            self.assertIn(f"/{robot}/clear_errors", offered)
            for name in published | subscribed:
                self.assertTrue(name.startswith(f"/{robot}/") or name in GLOBAL_TOPICS,
                                f"{node} uses {name} outside its namespace")
            for name in offered:
                self.assertTrue(name.startswith(f"/{robot}/"), f"{node} offers {name}")
        self.assertEqual(self.odom["robot1"].header.frame_id, "robot1/odom")
        self.assertEqual(self.odom["robot2"].child_frame_id, "robot2/base_link")

    def _drive(self, robot, twist, until):
        end = time.monotonic() + 30.0
        while not rospy.is_shutdown() and time.monotonic() < end:
            self.pubs[robot].publish(twist)
            if wait_for(until, 0.05):
                return True
        return False

    def test_commands_do_not_cross_talk(self):
        forward = Twist()
        forward.linear.x = 0.5
        for mover, other in (("robot1", "robot2"), ("robot2", "robot1")):
            start = self.truth[mover].pose.pose.position
            other_start = self.truth[other].pose.pose.position
            moved = self._drive(mover, forward, lambda: math.hypot(
                self.truth[mover].pose.pose.position.x - start.x,
                self.truth[mover].pose.pose.position.y - start.y) > 0.5)
            self.assertTrue(moved, f"{mover} should move on its own cmd_vel")
            p = self.truth[other].pose.pose.position
            self.assertAlmostEqual(p.x, other_start.x, delta=1e-6)
            self.assertAlmostEqual(p.y, other_start.y, delta=1e-6)
            self.assertLess(abs(self.truth[other].twist.twist.linear.x), 1e-6)
            self.pubs[mover].publish(Twist())
            self.assertTrue(wait_for(lambda: abs(self.truth[mover].twist.twist.linear.x) < 1e-3))


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_namespaces", TwoRobots)
