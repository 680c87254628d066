#!/usr/bin/python3
"""cmd_vel_stamped on the ROS 1 node (node_cmd_vel_stamped.test), as the ROS 2 node's
test_cmd_vel_stamped.py has it: with `true` a TwistStamped drives, one stamped longer ago than
cmd_vel_timeout is not obeyed (system_state says stale_command) and a zero stamp means now; with
`false` a Twist drives; with `auto` (the default) a publisher of each type in turn drives, and the
log says each change of type, once. Judged by the virtual chassis's ground truth, system_state and
/rosout, never by a wall-clock duration."""

import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState
from rosgraph_msgs.msg import Log


class Robot:
    """One driver's ground truth and system_state, by namespace."""

    def __init__(self, ns):
        self.ns = ns
        self.lock = threading.Lock()
        self.truth = None
        self.state = None
        self.subs = [
            rospy.Subscriber(f"/{ns}/sim/ground_truth", Odometry, self._on_truth, queue_size=1),
            rospy.Subscriber(f"/{ns}/system_state", SystemState, self._on_state, queue_size=1)]

    def _on_truth(self, m):
        with self.lock:
            self.truth = m

    def _on_state(self, m):
        with self.lock:
            self.state = m

    def vx(self):
        with self.lock:
            return None if self.truth is None else self.truth.twist.twist.linear.x

    def last_state(self):
        with self.lock:
            return self.state


class CmdVelStamped(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_cmd_vel_stamped")
        cls.logs = []
        cls.logs_lock = threading.Lock()
        cls.rosout = rospy.Subscriber("/rosout", Log, cls._on_log, queue_size=1000)
        cls.robots = {ns: Robot(ns) for ns in ("auto", "stamped", "plain")}

    @classmethod
    def _on_log(cls, m):
        with cls.logs_lock:
            cls.logs.append((m.name, m.msg))

    def logged(self, ns, text):
        with self.logs_lock:
            return [msg for name, msg in self.logs if name == f"/{ns}/ranger_base_node"
                    and text in msg]

    def wait_for(self, condition, what, pace=None, timeout=60.0):
        """Until condition() holds, calling pace() (a publication) every 50 ms; the timeout only
        bounds how long a failing test waits."""
        end = time.monotonic() + timeout
        while time.monotonic() < end and not rospy.is_shutdown():
            if pace:
                pace()
            if condition():
                return
            time.sleep(0.05)
        self.fail(f"not within {timeout} s: {what}")

    def wait_ready(self, robot):
        def ready():
            s = robot.last_state()
            return (s is not None and s.link_up and s.control_mode_name == "can"
                    and s.motion_inhibited_reason in ("", "cmd_timeout"))
        self.wait_for(ready, f"{robot.ns} ready")

    def drives(self, robot, pub, make, what):
        self.wait_for(lambda: (robot.vx() or 0.0) > 0.2, what, pace=lambda: pub.publish(make()))

    def rests(self, robot, pub, make, what):
        self.wait_for(lambda: robot.vx() is not None and abs(robot.vx()) < 1e-3, what,
                      pace=lambda: pub.publish(make()))

    @staticmethod
    def stamped(vx, age=0.0, zero=False):
        m = TwistStamped()
        if not zero:
            m.header.stamp = rospy.Time.now() - rospy.Duration.from_sec(age)
        m.twist.linear.x = vx
        return m

    @staticmethod
    def plain(vx):
        t = Twist()
        t.linear.x = vx
        return t

    def test_stamped_drives_a_stale_stamp_does_not_and_a_zero_stamp_is_now(self):
        r = self.robots["stamped"]
        self.wait_ready(r)
        pub = rospy.Publisher("/stamped/cmd_vel", TwistStamped, queue_size=10)
        try:
            self.drives(r, pub, lambda: self.stamped(0.4), "driving on fresh stamps")
            # Stamped a second ago: older than cmd_vel_timeout (0.5 s), so not obeyed, and said.
            self.wait_for(lambda: (r.last_state() or SystemState()).motion_inhibited_reason
                          == "stale_command", "stale_command in system_state",
                          pace=lambda: pub.publish(self.stamped(0.4, age=1.0)))
            self.assertIn("older than cmd_vel_timeout", r.last_state().motion_inhibited_detail)
            self.rests(r, pub, lambda: self.stamped(0.4, age=1.0), "rest on stale stamps")
            self.drives(r, pub, lambda: self.stamped(0.4, zero=True), "driving on zero stamps")
            self.assertNotEqual(r.last_state().motion_inhibited_reason, "stale_command")
            self.rests(r, pub, lambda: self.stamped(0.0), "rest on a zero twist")
        finally:
            pub.unregister()

    def test_plain_drives_with_cmd_vel_stamped_false(self):
        r = self.robots["plain"]
        self.wait_ready(r)
        pub = rospy.Publisher("/plain/cmd_vel", Twist, queue_size=10)
        try:
            self.drives(r, pub, lambda: self.plain(0.4), "driving on Twist")
            self.rests(r, pub, lambda: self.plain(0.0), "rest on a zero Twist")
        finally:
            pub.unregister()

    def test_auto_follows_a_publisher_of_each_type_in_turn(self):
        r = self.robots["auto"]
        self.wait_ready(r)
        for msg_type, make in ((TwistStamped, lambda: self.stamped(0.4)),
                               (Twist, lambda: self.plain(0.4)),
                               (TwistStamped, lambda: self.stamped(0.4, zero=True))):
            pub = rospy.Publisher("/auto/cmd_vel", msg_type, queue_size=10)
            try:
                self.drives(r, pub, make, f"driving on {msg_type.__name__}")
                self.rests(r, pub, lambda: msg_type(), f"rest on a zero {msg_type.__name__}")
            finally:
                pub.unregister()
        # Each change of type said once, as it came (the log reaches /rosout in order).
        said = "(cmd_vel_stamped auto: the type of its publishers)"
        self.wait_for(lambda: len(self.logged("auto", said)) >= 3, "the log of each change")
        self.assertEqual(self.logged("auto", said),
                         [f"cmd_vel: taken as geometry_msgs/{t} {said}"
                          for t in ("TwistStamped", "Twist", "TwistStamped")])


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_cmd_vel_stamped", CmdVelStamped)
