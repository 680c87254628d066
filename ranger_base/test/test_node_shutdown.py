#!/usr/bin/python3
"""ranger_base_node stops promptly and stops the chassis first (node_shutdown.test).

For SIGINT (Ctrl-C) and `rosnode kill`, while a teleop keeps cmd_vel coming: the node (port_name
sim, its own process, started here) exits within the issue's bound after the request, with exit
status 0, after it logged the stop ("stop sent to the chassis"), and the last message on
cmd_vel_out is that stop: a zero twist, sent after the request. The exit time is the one
wall-clock figure measured here (the issue asks for it); it is printed, and bounded by the issue's
0.3 s. A busy host (the test command compiles beside this stage) can hold any process past a
wall-clock bound without a fault of its own: an attempt over the bound is said and the whole
attempt (a fresh node) repeated, up to ATTEMPTS times; the bound must hold in one of them, and
every other assertion in each. Every other wait is on an observable condition, bounded only so
that a broken build fails instead of hanging."""

import os
import signal
import subprocess
import threading
import time
import unittest

import roslib.packages
import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist, TwistStamped
from ranger_msgs.msg import SystemState

# exit within 0.3 s of Ctrl-C or rosnode kill. A sanitizer's build scales it
# (RANGER_EXIT_BOUND_SCALE, which scripts/test_sanitizers.sh sets for ThreadSanitizer: its runtime
# makes every exit slower, 314-365 ms under load); the bound itself is the plain build's to hold.
EXIT_BOUND_S = 0.3 * float(os.environ.get("RANGER_EXIT_BOUND_SCALE", "1"))
ATTEMPTS = 3  # a measurement over the bound is repeated, said, this many times in all
STOP_LOG = "stop sent to the chassis"


def wait_for(condition, timeout=60.0):
    """Polls condition(); the timeout only bounds how long a failing test waits."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return bool(condition())


class Node:
    """One ranger_base_node in namespace `ns`, its output collected, its topics watched."""

    def __init__(self, ns):
        self.ns = ns
        exe = roslib.packages.find_node("ranger_base", "ranger_base_node")[0]
        self.process = subprocess.Popen(
            [exe, f"__ns:=/{ns}", "_port_name:=sim", "_publish_cmd:=true"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=os.environ)
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        self.lock = threading.Lock()
        self.commands = []
        self.state = None
        self.subs = [
            rospy.Subscriber(f"/{ns}/cmd_vel_out", TwistStamped, self._on_command, queue_size=1000),
            rospy.Subscriber(f"/{ns}/system_state", SystemState, self._on_state, queue_size=10)]
        self.cmd = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=10)
        self.driving = threading.Event()
        self.driver = threading.Thread(target=self._drive, daemon=True)

    def _read(self):
        for line in self.process.stdout:
            self.lines.append(line)

    def _on_command(self, msg):
        with self.lock:
            self.commands.append(msg)

    def _on_state(self, msg):
        self.state = msg

    def _drive(self):
        """A teleop at 20 Hz: cmd_vel keeps coming until the node is gone."""
        twist = Twist()
        twist.linear.x = 0.3
        while self.driving.is_set():
            self.cmd.publish(twist)
            time.sleep(0.05)

    def moving_commands(self):
        with self.lock:
            return [c for c in self.commands if c.twist.linear.x > 0.0]

    def output(self):
        return "".join(self.lines)

    def close(self):
        self.driving.clear()
        for s in self.subs:
            s.unregister()
        self.cmd.unregister()
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


class Shutdown(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_shutdown")

    def stop_and_measure(self, ns, request):
        node = Node(ns)
        try:
            self.assertTrue(wait_for(lambda: node.state is not None and node.state.link_up
                                     and node.state.control_mode == SystemState.CONTROL_MODE_CAN
                                     and node.cmd.get_num_connections() > 0),
                            "the node never reached CAN command mode:\n" + node.output())
            node.driving.set()
            node.driver.start()
            self.assertTrue(wait_for(lambda: len(node.moving_commands()) > 5),
                            "the node never drove:\n" + node.output())
            requested = rospy.Time.now()
            start = time.monotonic()
            request(node)
            node.process.wait(timeout=30)
            exit_s = time.monotonic() - start
            node.driving.clear()
            node.reader.join(timeout=10)
            print(f"[measured] {ns}: exit {exit_s * 1000:.0f} ms after the request "
                  f"(bound {EXIT_BOUND_S * 1000:.0f} ms)", flush=True)
            out = node.output()
            self.assertEqual(node.process.returncode, 0, out)
            self.assertIn(STOP_LOG, out)
            # The stop was the last thing it sent: a zero twist, sent after the request.
            self.assertTrue(wait_for(lambda: node.commands, 10))
            with node.lock:
                last = node.commands[-1]
            self.assertEqual((last.twist.linear.x, last.twist.linear.y, last.twist.angular.z),
                             (0.0, 0.0, 0.0), f"last cmd_vel_out {last}\n{out}")
            self.assertGreaterEqual(last.header.stamp, requested)
            return exit_s, out
        finally:
            node.close()

    def exits_within_bound(self, ns, request):
        measured = []
        for attempt in range(1, ATTEMPTS + 1):
            exit_s, out = self.stop_and_measure(f"{ns}{attempt}", request)
            measured.append(exit_s)
            if exit_s <= EXIT_BOUND_S:
                return
            print(f"[retry] {ns}: attempt {attempt} exited {exit_s * 1000:.0f} ms after the "
                  f"request, over the {EXIT_BOUND_S * 1000:.0f} ms bound (a busy host?)"
                  + ("; trying again with a fresh node" if attempt < ATTEMPTS else ""), flush=True)
        self.fail(f"{ns}: over {EXIT_BOUND_S * 1000:.0f} ms in all {ATTEMPTS} attempts: "
                  + ", ".join(f"{s * 1000:.0f} ms" for s in measured) + "\n" + out)

    def test_sigint(self):
        self.exits_within_bound("sigint_robot", lambda n: n.process.send_signal(signal.SIGINT))

    def test_rosnode_kill(self):
        def kill(node):
            ok, failed = rosnode.kill_nodes([f"/{node.ns}/ranger_base_node"])
            self.assertEqual(failed, [])
        self.exits_within_bound("killed_robot", kill)


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_shutdown", Shutdown)
