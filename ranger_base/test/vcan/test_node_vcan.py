#!/usr/bin/python3
"""ranger_base_node over SocketCAN (vcan0) against `ranger_can sim vcan0` in another process
(node_vcan.test). The bus traffic is recorded with candump and read back through
`ranger_can decode --json`, so the assertions use the kernel's frame timestamps and the order of
frames on the bus, and no protocol knowledge of their own.

  * handshake to CAN command mode, driving, odometry against the simulator's ground truth;
  * SIGINT and `rosnode kill`: the node's last 0x111 is a stop, sent while the chassis was still
    being commanded (its 500 ms watchdog never tripped): the node stopped it, not the chassis;
  * SIGKILL: no stop from the node; the chassis's own 500 ms watchdog trips and it comes to rest.

Waits are bounded only so that a broken build fails instead of hanging. The VM emulates its CPU,
so nothing here depends on how fast the node reacts, only on what it sent and in which order.
"""

import json
import math
import os
import shutil
import signal
import socket
import struct
import subprocess
import tempfile
import time
import unittest

import roslib.packages
import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState

IFACE = "vcan0"
WATCHDOG_S = 0.5          # the chassis stops 500 ms after the last 0x111 (manual)
FRAME_PERIOD_S = 0.02     # 0x211 / 0x221 period
# Allowance for scheduling (the VM emulates its CPU): added to protocol times, never the subject.
SLACK_S = 0.3
MARKER_ID = 0x7FE         # the test's own frames in the log (no RANGER frame has this id)


def wait_for(condition, timeout=60.0, interval=0.02):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(interval)
    return condition()


def find_executable(name, package_dirs=("bin",)):
    found = shutil.which(name)
    if found:
        return found
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        for sub in package_dirs:
            candidate = os.path.join(prefix, sub, name)
            if os.access(candidate, os.X_OK):
                return candidate
    raise RuntimeError(f"{name} not found on PATH or under CMAKE_PREFIX_PATH")


class VcanNode(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_node_vcan")
        cls.tmp = tempfile.mkdtemp(prefix="ranger-vcan-test-")
        cls.ranger_can = find_executable("ranger_can")
        cls.node_exe = roslib.packages.find_node("ranger_base", "ranger_base_node")[0]
        cls.candump_log = os.path.join(cls.tmp, "candump.log")
        cls.pose_log = os.path.join(cls.tmp, "pose.jsonl")
        # Line-buffered (stdbuf): candump writes through stdio, which holds up to 4 KB of lines
        # back when its output is a file, and a test reading the log would miss the newest
        # frames (the node's stop, seen missing once under load).
        # A receive buffer of 8 MB (-r; root sets it past rmem_max): with the default one a
        # candump that the loaded VM did not run for a moment dropped frames, once the node's
        # stop, which the chassis had received (it decelerated at once). -d prints a DROPCOUNT
        # line for any frame still dropped, which frames() refuses to judge.
        cls.candump = subprocess.Popen(["stdbuf", "-oL", "candump", "-L", "-d", "-r", "8388608",
                                        IFACE], stdout=open(cls.candump_log, "w"))
        cls.sim = subprocess.Popen([cls.ranger_can, "sim", IFACE, "--no-stdin", "--quiet",
                                    "--pose-out", cls.pose_log, "--pose-rate", "50"])
        assert wait_for(lambda: cls.truth() is not None), "ranger_can sim wrote no pose"

    @classmethod
    def tearDownClass(cls):
        for p in (cls.sim, cls.candump):
            p.send_signal(signal.SIGINT)
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()

    # ---- helpers ------------------------------------------------------------------------------

    @classmethod
    def truth(cls):
        """The simulator's latest ground-truth line, or None."""
        try:
            with open(cls.pose_log) as f:
                lines = f.read().splitlines()
        except FileNotFoundError:
            return None
        for line in reversed(lines):
            try:
                return json.loads(line)
            except ValueError:
                continue  # a line being written
        return None

    def frames(self):
        """Every frame recorded so far, decoded by ranger_can (JSON objects, in bus order)."""
        with open(self.candump_log) as f:
            drops = [line.strip() for line in f if "DROPCOUNT" in line]
        self.assertFalse(drops, "candump dropped frames: the log is not the bus")
        result = subprocess.run([self.ranger_can, "decode", "--json", self.candump_log],
                                capture_output=True, text=True, timeout=120)
        return [json.loads(line) for line in result.stdout.splitlines() if line.strip()]

    def sync_log(self):
        """Returns once candump has logged everything sent on the bus before this call: a marker
        frame of the test's own goes out after it, and candump reads one socket, in order. (A
        fixed wait is not enough: the VM emulates its CPU, and on a loaded host candump has been
        seen more than 10 s behind.)"""
        VcanNode.markers = getattr(VcanNode, "markers", 0) + 1
        payload = struct.pack("<I", VcanNode.markers)
        with socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW) as s:
            s.bind((IFACE,))
            s.send(struct.pack("=IB3x8s", MARKER_ID, len(payload), payload))
        text = f" {IFACE} {MARKER_ID:03X}#{payload.hex().upper()}"

        def logged():
            with open(self.candump_log) as f:
                return text in f.read()
        self.assertTrue(wait_for(logged, timeout=300, interval=0.1),
                        f"candump logged the marker{text}")

    def start_node(self, ns):
        # link_timeout: the emulated VM can starve a process for longer than the default 0.1 s.
        # protocol manual: these tests are about stopping the chassis, not the identification
        # (which node_sim_identify*.test cover); `ranger_can sim` speaks the manual's protocol.
        node = subprocess.Popen([self.node_exe, f"__ns:=/{ns}", "__name:=ranger_base_node",
                                 f"_port_name:={IFACE}", "_link_timeout:=0.5",
                                 "_cmd_vel_timeout:=5.0", "_protocol:=manual"])
        state = {}
        sub = rospy.Subscriber(f"/{ns}/system_state", SystemState,
                               lambda m: state.update(msg=m))
        odom = {}
        odom_sub = rospy.Subscriber(f"/{ns}/odom", Odometry, lambda m: odom.update(msg=m))
        pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=10)
        self.addCleanup(sub.unregister)
        self.addCleanup(odom_sub.unregister)
        self.addCleanup(pub.unregister)
        self.addCleanup(lambda: node.poll() is None and node.kill())
        self.assertTrue(wait_for(lambda: "msg" in state and state["msg"].link_up
                                 and state["msg"].control_mode == SystemState.CONTROL_MODE_CAN
                                 and pub.get_num_connections() > 0),
                        "handshake to CAN command mode over vcan0")
        return node, pub, odom

    def drive_forward(self, pub, speed=0.5):
        cmd = Twist()
        cmd.linear.x = speed
        def moving():
            pub.publish(cmd)
            t = self.truth()
            return t and t["vx"] > 0.8 * speed
        self.assertTrue(wait_for(moving, interval=0.05), "the chassis should drive")
        for _ in range(20):  # keep driving for a while (1 s at 20 Hz)
            pub.publish(cmd)
            time.sleep(0.05)

    def assert_node_stopped_the_chassis(self, t_signal):
        """The last 0x111 is a stop that followed the driving commands without the chassis's
        watchdog tripping in between, and the chassis came to rest."""
        self.assertTrue(wait_for(lambda: abs(self.truth()["vx"]) < 1e-3), "chassis at rest")

        def logged_stop():  # candump has written a zero 0x111 after the signal
            commands = [f for f in self.frames() if f["name"] == "motion_command"]
            return commands and commands[-1]["t"] >= t_signal - FRAME_PERIOD_S and (
                commands[-1]["linear_speed"], commands[-1]["spin_speed"]) == (0.0, 0.0)

        wait_for(logged_stop, timeout=10, interval=0.2)  # mostly there by now
        self.sync_log()  # and now certainly: the log holds whatever the node sent
        frames = self.frames()
        commands = [i for i, f in enumerate(frames) if f["name"] == "motion_command"]
        self.assertTrue(commands, "the node sent 0x111")
        last = frames[commands[-1]]
        self.assertEqual((last["linear_speed"], last["spin_speed"]), (0.0, 0.0),
                         "the node's last word is a stop")
        self.assertGreaterEqual(last["t"], t_signal - FRAME_PERIOD_S, "sent on the way out")
        # cmd_vel_timeout is long here: the node was still driving until it was told to go.
        self.assertGreater(len(commands), 1)
        self.assertGreater(frames[commands[-2]]["linear_speed"], 0.4, "driving until the stop")
        between = frames[commands[-2]:commands[-1]]
        self.assertFalse([f for f in between if f["name"] == "system_status"
                          and "host_communication_lost" in f.get("errors", [])],
                         "the stop came from the node, before the chassis's own watchdog")

    # ---- tests (run in name order; the simulator carries over) -------------------------------

    def test_1_drive_then_sigint_stops_the_chassis(self):
        node, pub, odom = self.start_node("sigint")
        start_truth = self.truth()
        self.assertTrue(wait_for(lambda: "msg" in odom))
        start_odom = odom["msg"].pose.pose.position
        self.drive_forward(pub)
        # Odometry over the real socket follows the simulator's ground truth.
        travelled = self.truth()["distance"] - start_truth["distance"]
        dx_truth = self.truth()["x"] - start_truth["x"]
        dx_odom = odom["msg"].pose.pose.position.x - start_odom.x
        self.assertGreater(travelled, 0.3)
        self.assertAlmostEqual(dx_odom, dx_truth, delta=0.05 + 0.02 * travelled)

        t_signal = time.time()
        node.send_signal(signal.SIGINT)
        self.assertEqual(node.wait(timeout=60), 0)
        self.assert_node_stopped_the_chassis(t_signal)

    def test_2_rosnode_kill_stops_the_chassis(self):
        node, pub, _ = self.start_node("killed")
        self.drive_forward(pub)
        t_signal = time.time()
        self.assertIn("/killed/ranger_base_node",
                      rosnode.kill_nodes(["/killed/ranger_base_node"])[0])
        self.assertEqual(node.wait(timeout=60), 0)
        self.assert_node_stopped_the_chassis(t_signal)

    def test_3_sigkill_leaves_the_chassis_watchdog_to_stop_it(self):
        node, pub, _ = self.start_node("sigkill")
        self.drive_forward(pub)
        node.kill()
        node.wait(timeout=30)
        self.assertTrue(wait_for(lambda: abs(self.truth()["vx"]) < 1e-3), "chassis at rest")
        self.sync_log()
        frames = self.frames()
        commands = [f for f in frames if f["name"] == "motion_command"]
        last = commands[-1]
        self.assertGreater(last["linear_speed"], 0.4, "a killed node sends no stop")
        after = [f for f in frames if f["t"] > last["t"]]
        tripped = [f for f in after if f["name"] == "system_status"
                   and "host_communication_lost" in f.get("errors", [])]
        self.assertTrue(tripped, "the chassis reports the lost host link")
        delay = tripped[0]["t"] - last["t"]
        self.assertGreaterEqual(delay, WATCHDOG_S - FRAME_PERIOD_S)
        self.assertLessEqual(delay, WATCHDOG_S + 2 * FRAME_PERIOD_S + SLACK_S)
        at_rest = [f for f in after if f["name"] == "motion_feedback"
                   and abs(f["speed"]) < 1e-3 and f["t"] >= tripped[0]["t"]]
        self.assertTrue(at_rest, "the chassis comes to rest by itself")


if __name__ == "__main__":
    rostest.rosrun("ranger_base", "node_vcan", VcanNode)
