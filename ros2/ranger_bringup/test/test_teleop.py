"""The ROS 2 keyboard teleop through a pseudo-terminal: keys become cmd_vel in each motion mode,
Ctrl-D ends it with a stop and the terminal restored; without a terminal it refuses to run."""

import os
import pty
import subprocess
import sys
import threading
import time

import pytest
import rclpy
from ament_index_python.packages import get_package_prefix
from geometry_msgs.msg import Twist

NS = f"/teleop{os.getpid()}"


def executable():
    return os.path.join(get_package_prefix("ranger_bringup"), "lib", "ranger_bringup",
                        "ranger_teleop_keyboard")


@pytest.fixture(scope="module")
def received():
    rclpy.init()
    node = rclpy.create_node(f"teleop_test_{os.getpid()}")
    log, lock, stop = [], threading.Lock(), threading.Event()

    def add(msg):
        with lock:
            log.append((msg.linear.x, msg.linear.y, msg.angular.z))
    node.create_subscription(Twist, f"{NS}/cmd_vel", add, 50)

    def spin():
        while not stop.is_set():
            rclpy.spin_once(node, timeout_sec=0.05)
    t = threading.Thread(target=spin, daemon=True)
    t.start()

    def since(n=0):
        with lock:
            return list(log[n:])
    yield since
    stop.set()
    t.join()
    node.destroy_node()
    rclpy.shutdown()


def wait_for(predicate, timeout=30.0, what="condition", pace=None):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if pace:
            pace()
        if predicate():
            return
        time.sleep(0.03)
    raise AssertionError(f"timed out waiting for {what}")


def test_keys_drive_every_mode_and_ctrl_d_stops(received):
    pid, fd = pty.fork()
    if pid == 0:
        os.execv(executable(), [executable(), "--ros-args", "-r", f"__ns:={NS}",
                                "-p", "speed:=0.4"])
    try:
        for key, check in (("w", lambda m: m[0] > 0.3 and m[1] == 0 and m[2] == 0),
                           ("a", lambda m: m[1] > 0.3 and m[0] == 0),
                           ("j", lambda m: m[2] > 0.1 and m[0] == 0 and m[1] == 0)):
            n = len(received())
            wait_for(lambda: any(check(m) for m in received(n)), what=f"key {key}",
                     pace=lambda: os.write(fd, key.encode()))
        n = len(received())
        os.write(fd, b"\x04")
        _, status = os.waitpid(pid, 0)
        assert os.WEXITSTATUS(status) == 0
        wait_for(lambda: received(n) and received(n)[-1] == (0.0, 0.0, 0.0), what="the stop")
    finally:
        try:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass
        os.close(fd)


def test_refuses_without_a_terminal():
    result = subprocess.run([executable()], stdin=subprocess.DEVNULL, capture_output=True,
                            text=True, timeout=60, check=False)
    assert result.returncode == 1 and "stdin is not a terminal" in result.stderr
