"""Test support: ranger_base_node in a process of its own (as owners run it) and a client node in
the test's process, spun on a thread; conditions are waited for on what the node publishes,
never on a wall-clock duration (durations only pace the commands, as a teleop would)."""

import itertools
import math
import os
import signal
import subprocess
import sys
import threading
import time

import rclpy
from ament_index_python.packages import get_package_prefix
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from ranger_msgs.msg import SystemState
from std_msgs.msg import String

# The margins of the waits below, reported at the end of the run (scripts/pytest_wait_margins.py).
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import pytest_wait_margins as wait_margins  # noqa: E402

_names = itertools.count(1)

def node_executable():
    return os.path.join(get_package_prefix("ranger_base"), "lib", "ranger_base", "ranger_base_node")


def ros_args(params, ns=None):
    args = ["--ros-args"]
    if ns:
        args += ["-r", f"__ns:={ns}"]
    for name, value in params.items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        args += ["-p", f"{name}:={value}"]
    return args


class NodeProcess:
    def __init__(self, ns, params, log_dir, env=None):
        self.ns = ns
        self.log_path = os.path.join(log_dir, f"{ns.strip('/').replace('/', '_') or 'root'}.log")
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen([node_executable()] + ros_args(params, ns), stdout=self.log,
                                     stderr=subprocess.STDOUT, start_new_session=True,
                                     env=dict(os.environ, **env) if env else None)

    def output(self):
        if not self.log.closed:
            self.log.flush()
        with open(self.log_path, encoding="utf-8", errors="replace") as f:
            return f.read()

    def stop(self, sig=signal.SIGINT, timeout=20):
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.log.close()
        return self.proc.returncode


class Client:
    """A test node: subscriptions keep the latest message (and every one, for cmd_vel_out)."""

    def __init__(self):
        self.node = rclpy.create_node(f"ranger_test_client_{next(_names)}_{os.getpid()}")
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.latest = {}
        self.history = {}
        self.lock = threading.Lock()
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self):
        while not self._stop.is_set():
            self.executor.spin_once(timeout_sec=0.05)

    def close(self):
        self._stop.set()
        self.thread.join()
        self.executor.shutdown()
        self.node.destroy_node()

    def listen(self, topic, msg_type, keep=False):
        def store(msg):
            with self.lock:
                self.latest[topic] = msg
                if keep:
                    self.history.setdefault(topic, []).append(msg)
        self.node.create_subscription(msg_type, topic, store, 50)

    def get(self, topic):
        with self.lock:
            return self.latest.get(topic)

    def wait_for(self, predicate, timeout=30.0, what="condition", pace=None):
        start = time.monotonic()
        deadline = start + timeout
        while time.monotonic() < deadline:
            if pace:
                pace()
            try:
                if predicate():
                    wait_margins.record(what, time.monotonic() - start, timeout)
                    return True
            except (AttributeError, TypeError):
                pass
            time.sleep(0.05)
        raise AssertionError(f"timed out waiting for {what}")

    def call(self, srv_type, name, request, timeout=30.0):
        client = self.node.create_client(srv_type, name)
        assert client.wait_for_service(timeout_sec=timeout), f"no service {name}"
        future = client.call_async(request)
        start = time.monotonic()
        deadline = start + timeout
        while not future.done():
            assert time.monotonic() < deadline, f"{name}: no response"
            time.sleep(0.02)
        wait_margins.record(f"{name} answered", time.monotonic() - start, timeout)
        self.node.destroy_client(client)
        return future.result()


class Robot:
    """One ranger_base_node under `ns` with a client listening to it."""

    def __init__(self, client, ns, log_dir, cmd_type=Twist, env=None, **params):
        """cmd_type: the type of the test's cmd_vel publisher (`cmd`; None: none); env: variables
        added to the node's environment."""
        self.client, self.ns = client, ns
        params.setdefault("port_name", "sim")
        self.process = NodeProcess(ns, params, log_dir, env)
        c = client
        c.listen(f"{ns}/system_state", SystemState)
        c.listen(f"{ns}/odom", Odometry)
        c.listen(f"{ns}/sim/ground_truth", Odometry, keep=True)
        c.listen(f"{ns}/cmd_vel_out", TwistStamped, keep=True)
        self.cmd = (c.node.create_publisher(cmd_type, f"{ns}/cmd_vel", 10) if cmd_type
                    else None)
        self.inject_pub = c.node.create_publisher(String, f"{ns}/sim/inject", 10)

    def state(self):
        return self.client.get(f"{self.ns}/system_state")

    def truth(self):
        return self.client.get(f"{self.ns}/sim/ground_truth")

    def odom(self):
        return self.client.get(f"{self.ns}/odom")

    def send(self, vx=0.0, vy=0.0, wz=0.0):
        t = Twist()
        t.linear.x, t.linear.y, t.angular.z = float(vx), float(vy), float(wz)
        self.cmd.publish(t)

    def inject(self, line):
        # Delivered once the node's subscription matched; the state says whether it took.
        self.client.wait_for(lambda: self.inject_pub.get_subscription_count() > 0,
                             what="sim/inject subscriber")
        self.inject_pub.publish(String(data=line))

    def wait_state(self, predicate, timeout=30.0, what="state", pace=None):
        self.client.wait_for(lambda: predicate(self.state()), timeout, what, pace)
        return self.state()

    def wait_ready(self, timeout=60.0):
        return self.wait_state(lambda s: s.link_up and s.control_mode_name == "can"
                               and s.identification in ("", "decided")
                               and s.motion_inhibited_reason in ("", "cmd_timeout"),
                               timeout, f"{self.ns} ready")

    def truth_path(self):
        """The ground truth's path length and turned angle so far, from its poses."""
        with self.client.lock:
            poses = list(self.client.history.get(f"{self.ns}/sim/ground_truth", []))
        dist = turned = 0.0
        for a, b in zip(poses, poses[1:]):
            pa, pb = a.pose.pose, b.pose.pose
            dist += math.hypot(pb.position.x - pa.position.x, pb.position.y - pa.position.y)
            turned += abs(math.remainder(yaw(pb.orientation) - yaw(pa.orientation), 2 * math.pi))
        return dist, turned

    def stop(self, sig=signal.SIGINT):
        return self.process.stop(sig)


def yaw(q):
    return 2.0 * math.atan2(q.z, q.w)
