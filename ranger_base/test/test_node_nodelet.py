#!/usr/bin/python3
"""ranger_base/RangerNodelet in a nodelet manager (node_nodelet.test): load, drive, unload.

The manager (/manager) is started by the launch file; each case loads the driver into it with
the virtual chassis (port_name sim), waits until it is in CAN command mode, drives it with
cmd_vel until its odometry has moved, then unloads it. After the unload the manager no longer
lists it, the last cmd_vel_out is the stop (a zero twist, sent after the unload was asked) and
nothing publishes its odom any more. Every wait is on an observable condition, bounded only so
that a broken build fails instead of hanging."""

import os
import subprocess
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from nodelet.srv import NodeletList, NodeletLoad, NodeletUnload
from ranger_msgs.msg import SystemState

MANAGER = "/manager"
NODELET_TYPE = "ranger_base/RangerNodelet"


def wait_for(condition, timeout=60.0):
    """Polls condition(); the timeout only bounds how long a failing test waits."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return bool(condition())


def publishers_of(topic):
    """The nodes the master lists as publishing `topic`."""
    publishers, _, _ = rosgraph.Master("/test_node_nodelet").getSystemState()
    for name, nodes in publishers:
        if name == topic:
            return nodes
    return []


class Robot:
    """The topics of one driver under namespace `ns`: system_state, odom, cmd_vel_out, cmd_vel."""

    def __init__(self, ns):
        self.ns = ns
        self.lock = threading.Lock()
        self.state = None
        self.odom = []
        self.commands = []
        self.subs = [
            rospy.Subscriber(f"/{ns}/system_state", SystemState, self._on_state, queue_size=10),
            rospy.Subscriber(f"/{ns}/odom", Odometry, self._on_odom, queue_size=100),
            rospy.Subscriber(f"/{ns}/cmd_vel_out", TwistStamped, self._on_command,
                             queue_size=1000)]
        self.cmd = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=10)
        self.driving = threading.Event()
        self.driver = threading.Thread(target=self._drive, daemon=True)

    def _on_state(self, msg):
        self.state = msg

    def _on_odom(self, msg):
        with self.lock:
            self.odom.append(msg)

    def _on_command(self, msg):
        with self.lock:
            self.commands.append(msg)

    def _drive(self):
        """A teleop at 20 Hz while driving is set."""
        twist = Twist()
        twist.linear.x = 0.3
        while self.driving.is_set():
            self.cmd.publish(twist)
            time.sleep(0.05)

    def in_command_mode(self):
        return (self.state is not None and self.state.link_up
                and self.state.control_mode == SystemState.CONTROL_MODE_CAN
                and self.cmd.get_num_connections() > 0)

    def x(self):
        with self.lock:
            return self.odom[-1].pose.pose.position.x if self.odom else 0.0

    def close(self):
        self.driving.clear()
        for s in self.subs:
            s.unregister()
        self.cmd.unregister()


class NodeletLifecycle(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_nodelet")
        for service in ("load_nodelet", "unload_nodelet", "list"):
            rospy.wait_for_service(f"{MANAGER}/{service}", timeout=60)
        cls.load = rospy.ServiceProxy(f"{MANAGER}/load_nodelet", NodeletLoad)
        cls.unload = rospy.ServiceProxy(f"{MANAGER}/unload_nodelet", NodeletUnload)
        cls.list = rospy.ServiceProxy(f"{MANAGER}/list", NodeletList)

    def drive_and_stop(self, robot, name, unload):
        """Drives the loaded driver `name` until its odometry moved, then `unload()`s it and
        checks that it stopped the chassis and went away."""
        self.assertTrue(wait_for(robot.in_command_mode),
                        f"{name} never reached CAN command mode (state {robot.state})")
        robot.driving.set()
        robot.driver.start()
        self.assertTrue(wait_for(lambda: robot.x() > 0.05),
                        f"{name} did not drive: odom x {robot.x()}")
        requested = rospy.Time.now()
        unload()
        robot.driving.clear()
        self.assertTrue(wait_for(lambda: name not in self.list().nodelets),
                        f"{name} still loaded: {self.list().nodelets}")
        self.assertTrue(wait_for(lambda: not publishers_of(f"/{robot.ns}/odom")),
                        f"/{robot.ns}/odom still published by {publishers_of(f'/{robot.ns}/odom')}")
        # The stop was the last thing it sent: a zero twist, sent after the unload was asked.
        with robot.lock:
            self.assertTrue(robot.commands, "no cmd_vel_out at all")
            last = robot.commands[-1]
        self.assertEqual((last.twist.linear.x, last.twist.linear.y, last.twist.angular.z),
                         (0.0, 0.0, 0.0), f"last cmd_vel_out {last}")
        self.assertGreaterEqual(last.header.stamp, requested)

    def test_load_drive_unload(self):
        name = "/nodelet_robot/ranger_base_node"
        for param, value in (("port_name", "sim"), ("protocol", "manual"), ("publish_cmd", True)):
            rospy.set_param(f"{name}/{param}", value)
        robot = Robot("nodelet_robot")
        try:
            response = self.load(name=name, type=NODELET_TYPE, remap_source_args=[],
                                 remap_target_args=[], my_argv=[], bond_id="")
            self.assertTrue(response.success)
            self.assertIn(name, self.list().nodelets)
            self.drive_and_stop(robot, name, lambda: self.assertTrue(self.unload(name=name).success))
        finally:
            robot.close()

    def test_launch_file_loads_it(self):
        """ranger_minimal.launch nodelet_manager:=/manager: the launch's `nodelet load` process
        loads the driver; ending the launch unloads it."""
        name = "/launched_robot/ranger_base_node"
        robot = Robot("launched_robot")
        launch = subprocess.Popen(
            ["roslaunch", "ranger_bringup", "ranger_minimal.launch", "sim:=true",
             "protocol:=manual", "ns:=launched_robot", f"nodelet_manager:={MANAGER}",
             "robot_state_publisher:=false", "diagnostics_aggregator:=false"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=os.environ,
            start_new_session=True)
        lines = []
        reader = threading.Thread(target=lambda: lines.extend(launch.stdout), daemon=True)
        reader.start()
        try:
            self.assertTrue(wait_for(lambda: name in self.list().nodelets),
                            "the launch did not load the nodelet:\n" + "".join(lines))
            # publish_cmd is not set by the launch file: the stop shows in the system state.
            self.assertTrue(wait_for(robot.in_command_mode),
                            f"never reached CAN command mode:\n{''.join(lines)}")
            robot.driving.set()
            robot.driver.start()
            self.assertTrue(wait_for(lambda: robot.x() > 0.05),
                            f"did not drive: odom x {robot.x()}\n{''.join(lines)}")
            robot.driving.clear()
            launch.send_signal(subprocess.signal.SIGINT)
            launch.wait(timeout=60)
            self.assertTrue(wait_for(lambda: name not in self.list().nodelets),
                            f"still loaded after the launch ended: {self.list().nodelets}")
            self.assertTrue(wait_for(lambda: not publishers_of("/launched_robot/odom")))
        finally:
            robot.close()
            if launch.poll() is None:
                launch.kill()
                launch.wait()


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_nodelet", NodeletLifecycle)
