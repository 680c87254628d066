#!/usr/bin/python3
"""Measures ranger_base_node's cost and command latency against the in-process virtual chassis
(port_name:=sim, so the chassis's full feedback, ~790 frames/s, flows through the real CAN thread,
controller and odometry). A benchmark, not a test: it prints figures, it asserts nothing.

  1. CPU and memory: the node drives at 20 Hz cmd_vel for --duration seconds with 50 Hz odometry;
     CPU share (of one core) from /proc/<pid>/stat and per thread from /proc/<pid>/task, RSS from
     /proc/<pid>/status. The node process also runs the virtual chassis (its thread is reported
     separately): the driver's own share is the node total minus that thread.
  2. Latency cmd_vel -> 0x111: a new twist is published every 50-70 ms (random, so every phase
     against the 20 ms keep-alive occurs); the node (publish_cmd:=true)
     stamps each 0x111 with its send time on cmd_vel_out; latency = that stamp - the time the
     twist was published (same host clock). Includes the ROS transport of cmd_vel.

  ranger_base/scripts/measure_performance.py [--duration 30] [--samples 400] [--json FILE]

Needs a built and sourced workspace (ranger_base_node findable by rospack/catkin).
"""

import argparse
import json
import os
import platform
import random
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time

CLK_TCK = os.sysconf("SC_CLK_TCK")
PAGE = os.sysconf("SC_PAGE_SIZE")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, timeout=60.0, interval=0.02):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(interval)
    return condition()


def cpu_seconds(stat_path):
    """utime + stime of a process or thread, in seconds."""
    with open(stat_path) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def thread_times(pid):
    out = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm") as f:
                name = f.read().strip()
            out[tid] = (name, cpu_seconds(f"/proc/{pid}/task/{tid}/stat"))
        except FileNotFoundError:
            pass  # thread ended
    return out


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def percentile(values, p):
    ordered = sorted(values)
    k = max(0, min(len(ordered) - 1, int(round(p / 100.0 * (len(ordered) - 1)))))
    return ordered[k]


class Environment:
    """A private rosmaster with a throwaway ROS_HOME."""

    def __init__(self):
        self.home = tempfile.mkdtemp(prefix="ranger-perf-roshome-")
        port = free_port()
        os.environ.update(ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOME=self.home,
                          ROS_LOG_DIR=os.path.join(self.home, "log"), ROS_HOSTNAME="localhost")
        self.master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def close(self):
        self.master.send_signal(signal.SIGINT)
        try:
            self.master.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.master.kill()
        shutil.rmtree(self.home, ignore_errors=True)


def start_node(name, *params):
    import roslib.packages
    exe = roslib.packages.find_node("ranger_base", "ranger_base_node")
    if not exe:
        sys.exit("ranger_base_node not found: build and source the workspace first")
    return subprocess.Popen([exe[0], f"__name:={name}", "_port_name:=sim", *params],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def stop_node(node):
    node.send_signal(signal.SIGINT)
    try:
        node.wait(timeout=20)
    except subprocess.TimeoutExpired:
        node.kill()


def wait_for_command_mode(rospy, ns):
    from ranger_msgs.msg import SystemState
    state = {}
    sub = rospy.Subscriber(f"/{ns}/system_state", SystemState, lambda m: state.update(m=m))
    ok = wait_for(lambda: "m" in state and state["m"].link_up
                  and state["m"].control_mode == SystemState.CONTROL_MODE_CAN)
    sub.unregister()
    if not ok:
        sys.exit("the node did not reach CAN command mode")


def measure_load(rospy, duration, extra_args=()):
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Twist
    ns = "perf_load"
    node = start_node("ranger_base_node", f"__ns:=/{ns}", "_publish_rate:=50", *extra_args)
    try:
        wait_for_command_mode(rospy, ns)
        pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1)
        rates = []

        def on_diagnostics(msg):
            for status in msg.status:
                if status.name.endswith("Frame rates"):
                    for kv in status.values:
                        if kv.key == "Total (frames/s)":
                            rates.append(float(kv.value))
        diag = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
        stop = threading.Event()

        def teleop():  # an operator at 20 Hz, driving a slow circle
            cmd = Twist()
            cmd.linear.x, cmd.angular.z = 0.4, 0.2
            while not stop.is_set():
                pub.publish(cmd)
                time.sleep(0.05)
        driver = threading.Thread(target=teleop, daemon=True)
        driver.start()
        time.sleep(3.0)  # settle: mode switch done, steady state

        pid = node.pid
        wall0, cpu0, threads0 = time.monotonic(), cpu_seconds(f"/proc/{pid}/stat"), thread_times(pid)
        rss = []
        while time.monotonic() - wall0 < duration:
            rss.append(rss_kib(pid))
            time.sleep(0.5)
        wall1, cpu1, threads1 = time.monotonic(), cpu_seconds(f"/proc/{pid}/stat"), thread_times(pid)
        stop.set()
        driver.join()
        diag.unregister()

        wall = wall1 - wall0
        per_thread = {}
        for tid, (name, t1) in threads1.items():
            t0 = threads0.get(tid, (name, 0.0))[1]
            label = f"{name} ({tid})"
            per_thread[label] = 100.0 * (t1 - t0) / wall
        return {
            "duration_s": round(wall, 1),
            "node_cpu_percent_of_one_core": round(100.0 * (cpu1 - cpu0) / wall, 2),
            "threads_cpu_percent": {k: round(v, 2) for k, v in sorted(
                per_thread.items(), key=lambda kv: -kv[1])},
            "rss_kib_median": int(statistics.median(rss)),
            "rss_kib_max": max(rss),
            "feedback_frames_per_s": round(statistics.median(rates), 1) if rates else None,
        }
    finally:
        stop_node(node)


def measure_latency(rospy, samples, extra_args=()):
    from geometry_msgs.msg import Twist, TwistStamped
    ns = "perf_latency"
    node = start_node("ranger_base_node", f"__ns:=/{ns}", "_publish_cmd:=true",
                      "_cmd_vel_timeout:=1.0", *extra_args)
    try:
        wait_for_command_mode(rospy, ns)
        lock = threading.Lock()
        sent = {}      # value in mm/s -> publish time
        latencies = []

        def on_command(msg):
            key = round(msg.twist.linear.x * 1000.0)
            with lock:
                t = sent.pop(key, None)
            if t is not None:
                latencies.append(msg.header.stamp.to_sec() - t)
        sub = rospy.Subscriber(f"/{ns}/cmd_vel_out", TwistStamped, on_command, queue_size=1000,
                               tcp_nodelay=True)
        pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and sub.get_num_connections() > 0)
        cmd = Twist()
        for k in range(samples + 20):
            # Distinct forward speeds (1 mm/s apart, the wire's resolution), 200..399 mm/s.
            value = 200 + (k % 200)
            cmd.linear.x = value / 1000.0
            with lock:
                sent[value] = time.time()  # each value recurs only after 10 s
            pub.publish(cmd)
            # 50-70 ms apart, at random: every phase against the node's 20 ms keep-alive occurs.
            time.sleep(random.uniform(0.05, 0.07))
        time.sleep(0.5)
        sub.unregister()
        data = latencies[20:] if len(latencies) > 40 else latencies  # skip the warm-up
        if not data:
            sys.exit("no cmd_vel_out matched: is publish_cmd working?")
        ms = [1000.0 * v for v in data]
        return {
            "samples": len(ms),
            "p50_ms": round(percentile(ms, 50), 3),
            "p90_ms": round(percentile(ms, 90), 3),
            "p99_ms": round(percentile(ms, 99), 3),
            "max_ms": round(max(ms), 3),
        }
    finally:
        stop_node(node)


def machine():
    model = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": model, "cores": os.cpu_count(), "kernel": platform.release(),
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=30.0, help="load phase, s")
    parser.add_argument("--samples", type=int, default=400, help="latency samples")
    parser.add_argument("--json", help="also write the figures to this file")
    parser.add_argument("--node-arg", action="append", default=[],
                        help="extra node argument (both phases), e.g. _min_command_interval:=0.001")
    parser.add_argument("--skip-latency", action="store_true")
    args = parser.parse_args()

    env = Environment()
    try:
        import rospy
        wait_for(lambda: subprocess.run(["rosnode", "list"], capture_output=True).returncode == 0)
        rospy.init_node("ranger_perf", anonymous=True, disable_signals=True)
        figures = {"machine": machine(),
                   "command": " ".join([os.path.relpath(sys.argv[0])] + sys.argv[1:]),
                   "mode": "port_name:=sim (in-process virtual chassis, loopback bus)",
                   "load": measure_load(rospy, args.duration, args.node_arg)}
        if not args.skip_latency:
            figures["latency_cmd_vel_to_0x111"] = measure_latency(rospy, args.samples,
                                                                  args.node_arg)
    finally:
        env.close()

    print(json.dumps(figures, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)


if __name__ == "__main__":
    main()
