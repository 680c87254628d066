"""Measures the ROS 2 ranger_base_node's cost and command latency against the in-process virtual
chassis, phase for phase as ranger_base/scripts/measure_performance.py measures the ROS 1 node,
so that the two compare (a benchmark: it prints figures, it asserts nothing).

Every phase runs a node of its own with subscribers on odom, /tf and joint_states in a process of
their own (as in real use: the node serialises and sends those messages at 50 Hz).
  1. load: cmd_vel at 20 Hz (a slow circle) for --duration s after 3 s of settling, a subscriber
     on /diagnostics: CPU (% of one core) of the node process and of each thread
     (/proc/<pid>/task), without the virtual chassis's thread (ranger_sim: not the driver's cost)
     = the driver's CPU; RSS; what the subscribers received.
  2. floor: the same load on rclpy_floor (this module with --floor): a node that only publishes
     odom, /tf and joint_states at 50 Hz and takes cmd_vel, through the node's own message code
     and threads: what rclpy and the DDS transport alone cost for that traffic.
  3. latency cmd_vel -> 0x111: --samples twists 50-70 ms apart (at random, so every phase
     against the 20 ms keep-alive occurs), each with its own speed; the node (publish_cmd)
     stamps each 0x111 with its send time on cmd_vel_out; latency = that stamp - the time the
     twist was published (its bytes handed to the publisher: serialised beforehand, the
     sender's own work; the first 20 skipped: warm-up). cmd_vel_out is taken on a thread of
     its own, and the subscribers take bytes, so the measurement's own Python work stays small
     beside the node's (two cores: whatever else runs delays the node's threads).

  ros2 run ranger_base measure_performance [--duration 30] [--samples 400] [--json FILE]
      [--phases load,floor,latency]

Needs a sourced ROS 2 workspace; set ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST and a domain id.
"""

import argparse
import json
import os
import platform
import random
import select
import signal
import statistics
import subprocess
import sys
import threading
import time

import rclpy
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.serialization import serialize_message

CLK_TCK = os.sysconf("SC_CLK_TCK")

# The subscribers, in a process of their own: raw subscriptions (the serialised bytes, no Python
# message built), so they cost little themselves, as the ROS 1 measurement's rospy.AnyMsg. They
# print "ready" once every topic has delivered, and when interrupted each topic's rate
# (messages/s between its first and its last message).
SUBSCRIBERS = """
import json, sys, time, rclpy
from rclpy.executors import ExternalShutdownException
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
rclpy.init()
n = rclpy.create_node("perf_subscribers")
ns, topics = sys.argv[1], {"odom": Odometry, "/tf": TFMessage, "joint_states": JointState}
seen = {}
def on(topic):
    def cb(_):
        now = time.monotonic()
        s = seen.setdefault(topic, [0, now, now])
        s[0], s[2] = s[0] + 1, now
        if s[0] == 1 and len(seen) == len(topics):
            print("ready", flush=True)
    return cb
for t, kind in topics.items():
    n.create_subscription(kind, t if t[0] == "/" else f"{ns}/{t}", on(t), 10, raw=True)
try:
    rclpy.spin(n)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
print(json.dumps({t: round((c - 1) / (last - first), 1) if last > first else 0.0
                  for t, (c, first, last) in seen.items()}), flush=True)
"""


def wait_for(condition, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end and not condition():
        time.sleep(0.02)
    return condition()


def cpu_seconds(stat_path):
    """utime + stime of a process or thread."""
    with open(stat_path, encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def thread_times(pid):
    """tid -> (name, CPU seconds)."""
    out = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm", encoding="ascii") as f:
                out[int(tid)] = (f.read().strip(), cpu_seconds(f"/proc/{pid}/task/{tid}/stat"))
        except (FileNotFoundError, ProcessLookupError):
            pass  # the thread ended
    return out


def rss_kib(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))


def percentile(values, p):
    ordered = sorted(values)
    return ordered[max(0, min(len(ordered) - 1, round(p / 100.0 * (len(ordered) - 1))))]


class Robot:
    """ranger_base_node (port_name:=sim) in namespace ns, in CAN command mode (or, floor=True,
    rclpy_floor), with the subscribers of real use connected; on leaving, both stop and .rates
    holds what the subscribers received (messages/s per topic)."""

    def __init__(self, node, ns, params, floor=False):
        from ament_index_python.packages import get_package_prefix
        from ranger_msgs.msg import SystemState
        if floor:
            cmd = [sys.executable, "-m", "ranger_base.measure_performance", "--floor", ns]
        else:
            exe = os.path.join(get_package_prefix("ranger_base"), "lib", "ranger_base",
                               "ranger_base_node")
            cmd = [exe, "--ros-args", "-r", f"__ns:={ns}", "-p", "port_name:=sim",
                   *(a for p in params for a in ("-p", p)), "--log-level", "warn"]
        self.node = subprocess.Popen(cmd, stdout=subprocess.DEVNULL)
        self.subscribers = subprocess.Popen([sys.executable, "-c", SUBSCRIBERS, ns],
                                            stdout=subprocess.PIPE, text=True)
        self.rates = {}
        state = {}
        sub = node.create_subscription(SystemState, f"{ns}/system_state",
                                       lambda m: state.update(m=m), 10)
        # CAN command mode with the protocol settings decided (protocol auto identifies the
        # chassis first; nothing is sent while it listens).
        ok = floor or wait_for(lambda: "m" in state and state["m"].link_up
                               and state["m"].control_mode == SystemState.CONTROL_MODE_CAN
                               and state["m"].identification in ("", "decided"))
        node.destroy_subscription(sub)
        ready = select.select([self.subscribers.stdout], [], [], 30)[0]
        if not ok or not ready or self.subscribers.stdout.readline().strip() != "ready":
            self.__exit__()
            sys.exit("the node did not reach CAN command mode or publish odom, tf, joint_states")

    def __enter__(self):
        return self

    def __exit__(self, *_):
        for p in (self.subscribers, self.node):
            p.send_signal(signal.SIGINT)
        try:
            out = self.subscribers.communicate(timeout=20)[0].strip().splitlines()
            self.node.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.subscribers.kill()
            self.node.kill()
            out = []
        if out and out[-1].startswith("{"):
            self.rates = json.loads(out[-1])


def measure_load(node, duration, params, floor=False):
    from diagnostic_msgs.msg import DiagnosticArray
    ns = f"/perf{os.getpid()}_{'floor' if floor else 'load'}"
    pub = node.create_publisher(Twist, f"{ns}/cmd_vel", 1)
    cmd, stop, rss = Twist(), threading.Event(), []
    cmd.linear.x, cmd.angular.z = 0.4, 0.2  # an operator at 20 Hz, driving a slow circle

    def teleop():
        while not stop.is_set():
            pub.publish(cmd)
            time.sleep(0.05)
    diag = node.create_subscription(DiagnosticArray, "/diagnostics", lambda _: None, 10)
    with Robot(node, ns, params, floor) as robot:
        pid = robot.node.pid
        driver = threading.Thread(target=teleop, daemon=True)
        driver.start()
        time.sleep(3.0)  # settle: mode switch done, steady state
        wall0, cpu0 = time.monotonic(), cpu_seconds(f"/proc/{pid}/stat")
        threads0 = thread_times(pid)
        while time.monotonic() - wall0 < duration:
            rss.append(rss_kib(pid))
            time.sleep(0.5)
        cpu1, threads1 = cpu_seconds(f"/proc/{pid}/stat"), thread_times(pid)
        wall = time.monotonic() - wall0
        stop.set()
        driver.join()
    node.destroy_subscription(diag)
    node.destroy_publisher(pub)

    def share(seconds):
        return round(100.0 * seconds / wall, 2)
    threads = sorted(({"tid": tid, "name": name,
                       "cpu_percent": share(t1 - threads0.get(tid, ("", 0))[1])}
                      for tid, (name, t1) in threads1.items()),
                     key=lambda t: -t["cpu_percent"])
    total = share(cpu1 - cpu0)
    out = {"duration_s": round(wall, 1), "cpu_percent": total, "threads": threads,
           "rss_kib_median": int(statistics.median(rss)), "rss_kib_max": max(rss),
           "subscribers_messages_per_s": robot.rates}
    if not floor:
        chassis = next((t for t in threads if t["name"] == "ranger_sim"), None)
        out["chassis_cpu_percent"] = chassis["cpu_percent"] if chassis else None
        out["driver_cpu_percent"] = round(total - chassis["cpu_percent"], 2) if chassis else None
    return out


def measure_latency(node, samples, params):
    ns = f"/perf{os.getpid()}_latency"
    lock, sent, latencies = threading.Lock(), {}, []  # sent: speed in mm/s -> publish time

    def on_command(msg):
        with lock:
            t = sent.pop(round(msg.twist.linear.x * 1000.0), None)
        if t is not None:
            stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            latencies.append(1000.0 * (stamp - t))
    from .rclpy_fast import OwnThreadGroup, SubscriptionThread
    with Robot(node, ns, ["publish_cmd:=true", "cmd_vel_timeout:=1.0", *params]):
        # cmd_vel_out (50 Hz: every keep-alive) on a thread of its own, as the node takes
        # cmd_vel: not the executor's, whose Python work at every wake-up would hold the GIL
        # while this thread publishes the twists.
        sub = node.create_subscription(TwistStamped, f"{ns}/cmd_vel_out", on_command, 1000,
                                       callback_group=OwnThreadGroup())
        receiver = SubscriptionThread(node, sub, "perf_cmd_vel_out")
        receiver.start()
        pub = node.create_publisher(Twist, f"{ns}/cmd_vel", 1)
        wait_for(lambda: pub.get_subscription_count() > 0 and sub.get_publisher_count() > 0)
        cmd = Twist()
        for k in range(samples + 20):
            value = 200 + k % 200  # distinct speeds, 1 mm/s apart (the wire's resolution)
            cmd.linear.x = value / 1000.0
            data = serialize_message(cmd)  # before the clock starts: the sender's own work
            with lock:
                sent[value] = time.time()
            pub.publish(data)
            time.sleep(random.uniform(0.05, 0.07))
        time.sleep(0.5)
        receiver.stop()
        node.destroy_subscription(sub)
        node.destroy_publisher(pub)
    ms = latencies[20:] if len(latencies) > 40 else latencies  # skip the warm-up
    if not ms:
        sys.exit("no cmd_vel_out matched: is publish_cmd working?")
    return {"samples": len(ms), "max_ms": round(max(ms), 3),
            **{f"p{p}_ms": round(percentile(ms, p), 3) for p in (50, 90, 99)}}


def run_floor(ns):
    """rclpy_floor: odom, /tf and joint_states at 50 Hz and cmd_vel taken, with the node's own
    message code (the binding's serialised bytes, conversions.motion_encoder, where the node uses
    them, else conversions.MotionMessages; cmd_vel's bytes read by conversions.twist_reader)
    and threads (a publication thread waking every
    20 ms, cmd_vel on a thread of its own), no driver: what rclpy and DDS cost for the traffic."""
    from nav_msgs.msg import Odometry
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage

    from . import conversions
    from .rclpy_fast import OwnThreadGroup, SubscriptionThread, name_os_thread
    rclpy.init()
    node = rclpy.create_node("rclpy_floor", namespace=ns)
    odom_pub = node.create_publisher(Odometry, "odom", 10)
    tf_pub = node.create_publisher(TFMessage, "/tf", 100)
    joint_pub = node.create_publisher(JointState, "joint_states", 10)
    read_twist = conversions.twist_reader()  # cmd_vel's bytes read as the node reads them
    sub = node.create_subscription(Twist, "cmd_vel", read_twist or (lambda _: None), 1,
                                   callback_group=OwnThreadGroup(), raw=read_twist is not None)
    commands = SubscriptionThread(node, sub, "ranger_cmd_vel")
    params = {"odom_frame": "odom", "base_frame": "base_link",
              "pose_covariance_diagonal": [1e-4] * 6, "twist_covariance_diagonal": [1e-3] * 6}
    names = [f"joint_{i}" for i in range(8)]
    messages = conversions.MotionMessages(params, names)
    encoder, _ = conversions.motion_encoder(params, names)  # as the node sends them
    stop = threading.Event()

    def publish():
        name_os_thread("ranger_publish")
        due = time.monotonic()
        while not stop.wait(max(0.0, due - time.monotonic())):
            due += 0.02
            now = time.time_ns()
            sec, nanosec = divmod(now, 1_000_000_000)
            odometry = (sec, nanosec, 1.0, 2.0, 0.0, 1.0, 0.4, 0.0, 0.2, 1e-6, 1e-6, 1e-6)
            joints = (sec, nanosec, [0.1] * 8, [0.2] * 8)
            if encoder is not None:
                tf_pub.publish(encoder.transform(odometry))
                odom_pub.publish(encoder.odometry(odometry))
                joint_pub.publish(encoder.joint_state(joints))
                continue
            messages.fill_odometry(odometry)
            messages.fill_joints(joints)
            tf_pub.publish(messages.tf)
            odom_pub.publish(messages.odom)
            joint_pub.publish(messages.joints)
    publisher = threading.Thread(target=publish, daemon=True)
    publisher.start()
    commands.start()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    stop.set()
    publisher.join()
    commands.stop()
    rclpy.try_shutdown()
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=30.0, help="load phase, s")
    parser.add_argument("--samples", type=int, default=400, help="latency samples")
    parser.add_argument("--json", help="also write the figures to this file")
    parser.add_argument("--phases", default="load,floor,latency",
                        help="which measurements, comma-separated")
    parser.add_argument("--node-arg", action="append", default=[],
                        help="extra node parameter (every phase), e.g. protocol:=manual")
    parser.add_argument("--floor", metavar="NS", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.floor:
        return run_floor(args.floor)
    rclpy.init()
    node = rclpy.create_node(f"ranger_perf_{os.getpid()}")
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            rclpy.spin_once(node, timeout_sec=0.05)
    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    with open("/proc/cpuinfo", encoding="ascii") as f:
        cpu = next((line.split(":", 1)[1].strip() for line in f
                    if line.startswith("model name")), "unknown")
    figures = {"machine": {"cpu": cpu, "cores": os.cpu_count(), "kernel": platform.release()},
               "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
               "command": " ".join(["measure_performance"] + sys.argv[1:])}
    measurements = {
        "load": ("load", lambda: measure_load(node, args.duration, args.node_arg)),
        "floor": ("rclpy_floor", lambda: measure_load(node, args.duration, [], floor=True)),
        "latency": ("latency_cmd_vel_to_0x111",
                    lambda: measure_latency(node, args.samples, args.node_arg)),
    }
    phases = args.phases.split(",")
    for phase in phases:
        if phase not in measurements:
            sys.exit(f"unknown phase {phase}: use {','.join(measurements)}")
    try:
        for phase in phases:
            key, measure = measurements[phase]
            figures[key] = measure()
    finally:
        stop.set()
        spinner.join()
        node.destroy_node()
        rclpy.try_shutdown()
    text = json.dumps(figures, indent=2)
    print(text)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
