"""Measures the ROS 2 ranger_base_node's cost and command latency against the in-process virtual
chassis, the way ranger_base/scripts/measure_performance.py measures the ROS 1 node (a
benchmark: it prints figures, it asserts nothing).

  1. load: subscribers on odom, /tf and joint_states in a process of their own, cmd_vel at 20 Hz
     for --duration s: CPU (% of one core) of the node process, and without its virtual
     chassis's thread (ranger_sim: not the driver's cost); RSS.
  2. latency cmd_vel -> 0x111: --samples twists 50-70 ms apart (at random, so every phase
     against the 20 ms keep-alive occurs); the node (publish_cmd) stamps each 0x111 with its
     send time on cmd_vel_out; latency = that stamp - the time the twist was published.

  ros2 run ranger_base measure_performance [--duration 30] [--samples 400] [--json FILE]

Needs a sourced ROS 2 workspace; set ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST and a domain id.
"""

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import threading
import time

import rclpy
from geometry_msgs.msg import Twist, TwistStamped

CLK_TCK = os.sysconf("SC_CLK_TCK")
NS = f"/perf{os.getpid()}"

SUBSCRIBERS = """
import sys, rclpy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
rclpy.init()
n = rclpy.create_node("perf_subscribers")
ns = sys.argv[1]
for topic, t in ((ns + "/odom", Odometry), ("/tf", TFMessage), (ns + "/joint_states", JointState)):
    n.create_subscription(t, topic, lambda m: None, 10)
try:
    rclpy.spin(n)
except BaseException:
    pass
"""


def cpu_ticks(pid, tid=None):
    path = f"/proc/{pid}/stat" if tid is None else f"/proc/{pid}/task/{tid}/stat"
    with open(path, encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])


def threads(pid):
    out = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        with open(f"/proc/{pid}/task/{tid}/comm", encoding="ascii") as f:
            out[tid] = f.read().strip()
    return out


def rss_mb(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


def start_node(publish_cmd):
    from ament_index_python.packages import get_package_prefix
    exe = os.path.join(get_package_prefix("ranger_base"), "lib", "ranger_base", "ranger_base_node")
    return subprocess.Popen([exe, "--ros-args", "-r", f"__ns:={NS}", "-p", "port_name:=sim",
                             "-p", "protocol:=manual", "-p", f"publish_cmd:={str(publish_cmd).lower()}",
                             "--log-level", "warn"])


def measure(duration, samples):
    rclpy.init()
    node = rclpy.create_node(f"perf_driver_{os.getpid()}")
    pub = node.create_publisher(Twist, f"{NS}/cmd_vel", 10)
    sent = []
    lock = threading.Lock()

    def on_out(msg):
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        with lock:
            sent.append((t, msg.twist.linear.x))
    node.create_subscription(TwistStamped, f"{NS}/cmd_vel_out", on_out, 1000)
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            rclpy.spin_once(node, timeout_sec=0.05)
    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    proc = start_node(True)
    subs = subprocess.Popen([sys.executable, "-c", SUBSCRIBERS, NS])
    try:
        twist = Twist()
        # Warm up: the chassis heard, in CAN command mode, driving.
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            twist.linear.x = 0.2
            pub.publish(twist)
            time.sleep(0.05)
            with lock:
                if any(abs(v - 0.2) < 1e-3 for _, v in sent):
                    break
        # 1. load
        names = threads(proc.pid)
        sim_tids = [t for t, n in names.items() if n == "ranger_sim"]
        t0, c0 = time.monotonic(), cpu_ticks(proc.pid)
        s0 = sum(cpu_ticks(proc.pid, t) for t in sim_tids)
        while time.monotonic() - t0 < duration:
            twist.linear.x = 0.2
            pub.publish(twist)
            time.sleep(0.05)
        elapsed = time.monotonic() - t0
        total = (cpu_ticks(proc.pid) - c0) / CLK_TCK / elapsed * 100.0
        sim = (sum(cpu_ticks(proc.pid, t) for t in sim_tids) - s0) / CLK_TCK / elapsed * 100.0
        load = {"cpu_percent": round(total, 2), "sim_thread_percent": round(sim, 2),
                "driver_percent": round(total - sim, 2), "rss_mb": round(rss_mb(proc.pid), 1)}
        # 2. latency
        latencies = []
        for i in range(samples):
            v = 0.2 + 0.01 * (i % 2 + 1)
            with lock:
                n0 = len(sent)
            twist.linear.x = v
            published = time.time()
            pub.publish(twist)
            time.sleep(random.uniform(0.05, 0.07))
            with lock:
                after = [t for t, x in sent[n0:] if abs(x - v) < 2e-3]
            if after:
                latencies.append((after[0] - published) * 1000.0)
        latencies.sort()

        def pct(p):
            return round(latencies[min(len(latencies) - 1, int(p / 100 * len(latencies)))], 3)
        latency = {"samples": len(latencies), "p50_ms": pct(50), "p90_ms": pct(90),
                   "p99_ms": pct(99), "mean_ms": round(statistics.mean(latencies), 3)}
        return {"load": load, "latency": latency}
    finally:
        subs.terminate()
        proc.send_signal(2)
        proc.wait(30)
        subs.wait(30)
        stop.set()
        spinner.join()
        node.destroy_node()
        rclpy.shutdown()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    result = measure(args.duration, args.samples)
    text = json.dumps(result, indent=2)
    print(text)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
