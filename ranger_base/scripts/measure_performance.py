#!/usr/bin/python3
"""Measures ranger_base_node's cost and command latency against the in-process virtual chassis
(port_name:=sim: the chassis's full feedback, ~790 frames/s, flows through the real CAN thread,
controller and odometry). A benchmark: it prints figures, it asserts nothing.

Both phases run a node of their own with subscribers on odom, /tf and joint_states (a separate
process, as in real use, so the node serialises and sends those messages at 50 Hz).
  1. Load: cmd_vel at 20 Hz for --duration s. CPU (% of one core) of the node process and of
     each thread from /proc/<pid>/task, RSS from /proc/<pid>/status. The process also hosts the
     virtual chassis: its thread (named ranger_sim; before the driver rewrite unnamed, created
     just before the CAN thread) is not the driver's cost: driver CPU = node total - that thread.
     The same load on roscpp_floor (a node that only publishes odom, /tf and joint_states at
     50 Hz and subscribes to cmd_vel, through the node's own conversions) gives the floor:
     what roscpp's transport alone costs for that traffic, which no roscpp driver goes below.
  2. Latency cmd_vel -> 0x111: --samples twists 50-70 ms apart (at random, so every phase
     against the 20 ms keep-alive occurs); the node (publish_cmd:=true) stamps each 0x111 with its
     send time on cmd_vel_out; latency = that stamp - the time the twist was published.
  3. keepalive: the 0x111 keep-alive's period with a subscriber on every topic the node
     advertises (and two slow ones, 0.2 s per message, on odom and /tf): one twist, then no
     command for --duration s (cmd_vel_timeout 60 s), so that every 0x111 is a scheduled one;
     deviation = |interval between consecutive cmd_vel_out stamps - 20 ms|. keepalive_fifo: the
     same with the driver thread under SCHED_FIFO 50 (chrt; root), as on a busy robot computer.
  4. nodelet: the driver as a nodelet (ranger_base/RangerNodelet) in a manager of its own, with
     the subscriber nodelet ranger_base/PerfSubscriber on odom, /tf and joint_states in the same
     manager (no serialisation), cmd_vel at 20 Hz: CPU of the manager process and its threads.
  5. fleet: --robots nodes, each with its own virtual chassis, at once, each driven in its own
     circle at 10 Hz: total and per-robot CPU and RSS; then each is stopped and its odometry
     compared with its chassis's ground truth (sim/ground_truth).

  ranger_base/scripts/measure_performance.py [--duration 30] [--samples 400] [--json FILE]
      [--phases load,floor,latency,keepalive,keepalive_fifo,nodelet,fleet] [--robots 10]

Needs a built and sourced workspace (ranger_base_node findable by rospack).
"""

import argparse
import json
import os
import platform
import random
import select
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
CAN_THREADS = ("ranger_driver", "ranger_can_link")  # after / before the driver rewrite

# The subscribers, in a process of their own: rospy.AnyMsg, so they cost little themselves.
# They print one line once every topic has delivered, and when interrupted each topic's rate
# (messages/s between its first and its last message).
SUBSCRIBERS = """
import json, sys, time, rospy
ns, topics = sys.argv[1], ["odom", "/tf", "joint_states"]
seen = {}  # topic -> [count, first, last]
def on(topic):
    def cb(_):
        now = time.monotonic()
        s = seen.setdefault(topic, [0, now, now])
        s[0], s[2] = s[0] + 1, now
        if s[0] == 1 and len(seen) == len(topics):
            print("ready", flush=True)
    return cb
rospy.init_node("perf_subscribers", anonymous=True)
subs = [rospy.Subscriber(t if t[0] == "/" else f"/{ns}/{t}", rospy.AnyMsg, on(t)) for t in topics]
rospy.spin()
print(json.dumps({t: round((n - 1) / (last - first), 1) if last > first else 0.0
                  for t, (n, first, last) in seen.items()}), flush=True)
"""


def wait_for(condition, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end and not condition():
        time.sleep(0.02)
    return condition()


def cpu_seconds(stat_path):
    """utime + stime of a process or thread."""
    with open(stat_path) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def thread_times(pid):
    """tid -> (name, CPU seconds)."""
    out = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm") as f:
                out[int(tid)] = (f.read().strip(), cpu_seconds(f"/proc/{pid}/task/{tid}/stat"))
        except (FileNotFoundError, ProcessLookupError):
            pass  # the thread ended
    return out


def chassis_thread(pid, threads):
    """The virtual chassis's thread: by its name, else (before the rewrite, when it is unnamed)
    the last unnamed thread created before the CAN thread (the chassis is built first)."""
    named = [t for t, (name, _) in threads.items() if name == "ranger_sim"]
    if named:
        return named[0]
    can = [t for t, (name, _) in threads.items() if name in CAN_THREADS]
    unnamed = [t for t, (name, _) in threads.items()
               if can and name == threads[pid][0] and t != pid and t < min(can)]
    return max(unnamed, default=None)


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))


def percentile(values, p):
    ordered = sorted(values)
    return ordered[max(0, min(len(ordered) - 1, round(p / 100.0 * (len(ordered) - 1))))]


class Robot:
    """ranger_base_node (port_name:=sim) in namespace ns, in CAN command mode (or, floor=True,
    roscpp_floor), with the subscribers of real use connected; on leaving, both stop and .rates
    holds what the subscribers received (messages/s per topic)."""

    def __init__(self, rospy, ns, params, floor=False):
        import roslib.packages
        from ranger_msgs.msg import SystemState
        name = "roscpp_floor" if floor else "ranger_base_node"
        exe = roslib.packages.find_node("ranger_base", name)
        if not exe:
            sys.exit(f"{name} not found: build and source the workspace first")
        args = [] if floor else ["_port_name:=sim", *params]
        self.node = subprocess.Popen([exe[0], f"__name:={name}", f"__ns:=/{ns}", *args],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.subscribers = subprocess.Popen([sys.executable, "-c", SUBSCRIBERS, ns],
                                            stdout=subprocess.PIPE, text=True)
        self.rates = {}
        state = {}
        sub = rospy.Subscriber(f"/{ns}/system_state", SystemState, lambda m: state.update(m=m))
        # CAN command mode with the protocol settings decided (protocol auto identifies the
        # chassis first; nothing is sent while it listens).
        ok = floor or wait_for(lambda: "m" in state and state["m"].link_up
                               and state["m"].control_mode == SystemState.CONTROL_MODE_CAN
                               and state["m"].identification in ("", "decided"))
        sub.unregister()
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


def measure_load(rospy, duration, params, floor=False):
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Twist
    ns = "perf_floor" if floor else "perf_load"
    pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1)
    cmd, stop, rates, rss = Twist(), threading.Event(), [], []
    cmd.linear.x, cmd.angular.z = 0.4, 0.2  # an operator at 20 Hz, driving a slow circle

    def teleop():
        while not stop.is_set():
            pub.publish(cmd)
            time.sleep(0.05)

    def on_diagnostics(msg):
        rates.extend(float(kv.value) for s in msg.status if s.name.endswith("Frame rates")
                     for kv in s.values if kv.key == "Total (frames/s)")
    with Robot(rospy, ns, params, floor) as robot:
        pid = robot.node.pid
        diag = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
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
        diag.unregister()

    def share(seconds):
        return round(100.0 * seconds / wall, 2)
    threads = [{"tid": tid, "name": name, "cpu_percent": share(t1 - threads0.get(tid, ("", 0))[1])}
               for tid, (name, t1) in threads1.items()]
    if floor:
        return {"duration_s": round(wall, 1), "cpu_percent": share(cpu1 - cpu0),
                "threads": sorted(threads, key=lambda t: -t["cpu_percent"]),
                "subscribers_messages_per_s": robot.rates}
    chassis = chassis_thread(pid, threads1)
    chassis_cpu = next((t["cpu_percent"] for t in threads if t["tid"] == chassis), None)
    total = share(cpu1 - cpu0)
    return {
        "duration_s": round(wall, 1),
        "node_cpu_percent": total,
        "chassis_thread": f"{threads1[chassis][0]} {chassis}" if chassis else None,
        "chassis_cpu_percent": chassis_cpu,
        "driver_cpu_percent": round(total - chassis_cpu, 2) if chassis_cpu is not None else None,
        "threads": sorted(threads, key=lambda t: -t["cpu_percent"]),
        "rss_kib_median": int(statistics.median(rss)),
        "rss_kib_max": max(rss),
        "feedback_frames_per_s": round(statistics.median(rates), 1) if rates else None,
        "subscribers_messages_per_s": robot.rates,
    }


def measure_latency(rospy, samples, params):
    from geometry_msgs.msg import Twist, TwistStamped
    lock, sent, latencies = threading.Lock(), {}, []  # sent: speed in mm/s -> publish time

    def on_command(msg):
        with lock:
            t = sent.pop(round(msg.twist.linear.x * 1000.0), None)
        if t is not None:
            latencies.append(1000.0 * (msg.header.stamp.to_sec() - t))
    with Robot(rospy, "perf_latency", ["_publish_cmd:=true", "_cmd_vel_timeout:=1.0", *params]):
        sub = rospy.Subscriber("/perf_latency/cmd_vel_out", TwistStamped, on_command,
                               queue_size=1000, tcp_nodelay=True)
        pub = rospy.Publisher("/perf_latency/cmd_vel", Twist, queue_size=1, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and sub.get_num_connections() > 0)
        cmd = Twist()
        for k in range(samples + 20):
            value = 200 + k % 200  # distinct speeds, 1 mm/s apart (the wire's resolution)
            cmd.linear.x = value / 1000.0
            with lock:
                sent[value] = time.time()
            pub.publish(cmd)
            time.sleep(random.uniform(0.05, 0.07))
        time.sleep(0.5)
        sub.unregister()
    ms = latencies[20:] if len(latencies) > 40 else latencies  # skip the warm-up
    if not ms:
        sys.exit("no cmd_vel_out matched: is publish_cmd working?")
    return {"samples": len(ms), "max_ms": round(max(ms), 3),
            **{f"p{p}_ms": round(percentile(ms, p), 3) for p in (50, 90, 99)}}


# Every topic the node advertises, and two slow subscribers (0.2 s per message) on odom and /tf.
ALL_SUBSCRIBERS = """
import sys, time, rospy
ns = sys.argv[1]
rospy.init_node("perf_all_subscribers", anonymous=True)
topics = sorted(t for t, _ in rospy.get_published_topics()
                if t.startswith(f"/{ns}/") or t in ("/tf", "/diagnostics"))
subs = [rospy.Subscriber(t, rospy.AnyMsg, lambda _: None, queue_size=100) for t in topics]
subs += [rospy.Subscriber(t, rospy.AnyMsg, lambda _: time.sleep(0.2), queue_size=1)
         for t in (f"/{ns}/odom", "/tf")]
print(len(topics), flush=True)
rospy.spin()
"""


def measure_keepalive(rospy, duration, params, fifo=False):
    """fifo: the driver thread under SCHED_FIFO 50 (`chrt`, needs root), as a robot whose
    computer runs other work would run it; otherwise at the default priority."""
    from geometry_msgs.msg import Twist, TwistStamped
    ns, stamps = "perf_keepalive_fifo" if fifo else "perf_keepalive", []
    with Robot(rospy, ns, ["_publish_cmd:=true", "_cmd_vel_timeout:=60", *params]) as robot:
        if fifo:
            tids = [t for t, (name, _) in thread_times(robot.node.pid).items()
                    if name in CAN_THREADS]
            if not tids or subprocess.run(["chrt", "-f", "-p", "50", str(tids[0])]).returncode:
                raise RuntimeError("cannot put the driver thread under SCHED_FIFO (root?)")
        extra = subprocess.Popen([sys.executable, "-c", ALL_SUBSCRIBERS, ns],
                                 stdout=subprocess.PIPE, text=True)
        try:
            ready = select.select([extra.stdout], [], [], 60)[0]
            topics = int(extra.stdout.readline()) if ready else 0
            sub = rospy.Subscriber(f"/{ns}/cmd_vel_out", TwistStamped,
                                   lambda m: stamps.append(m.header.stamp.to_sec()),
                                   queue_size=10000, tcp_nodelay=True)
            pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1, latch=True)
            wait_for(lambda: pub.get_num_connections() > 0 and sub.get_num_connections() > 0)
            cmd = Twist()
            cmd.linear.x, cmd.angular.z = 0.3, 0.1
            pub.publish(cmd)  # the only command: every 0x111 after it is a scheduled keep-alive
            time.sleep(2.0)
            del stamps[:]
            time.sleep(min(duration, 50.0))
            sub.unregister()
            pub.unregister()
        finally:
            extra.send_signal(signal.SIGINT)
            try:
                extra.wait(timeout=20)
            except subprocess.TimeoutExpired:
                extra.kill()
    ms = [1000.0 * (b - a) for a, b in zip(stamps, stamps[1:])]
    if len(ms) < 10:
        raise RuntimeError("too few cmd_vel_out messages to measure the keep-alive")
    deviation = [abs(m - 20.0) for m in ms]
    return {"intervals": len(ms), "topics_subscribed": topics,
            "period_ms_mean": round(statistics.mean(ms), 3),
            **{f"deviation_p{p}_ms": round(percentile(deviation, p), 3) for p in (50, 90, 99)},
            "deviation_max_ms": round(max(deviation), 3)}


def node_params(args):
    """_name:=value arguments -> {name: value} (values read as YAML, as rosrun does)."""
    import yaml
    out = {}
    for a in args:
        name, value = a.split(":=", 1)
        out[name.lstrip("_")] = yaml.safe_load(value)
    return out


def measure_nodelet(rospy, duration, params):
    import roslib.packages
    from geometry_msgs.msg import Twist
    from nodelet.srv import NodeletLoad, NodeletUnload
    from ranger_msgs.msg import SystemState
    exe = roslib.packages.find_node("nodelet", "nodelet")
    if not exe:
        raise RuntimeError("nodelet not found (libnodeletlib-tools)")
    ns, manager_name = "perf_nodelet", "/perf_manager"
    driver, subscriber = f"/{ns}/ranger_base_node", f"/{ns}/perf_subscriber"
    report = tempfile.NamedTemporaryFile(prefix="ranger-perf-nodelet-", suffix=".json",
                                         delete=False).name
    for name, value in {"port_name": "sim", **node_params(params)}.items():
        rospy.set_param(f"{driver}/{name}", value)
    rospy.set_param(f"{subscriber}/report", report)
    manager = subprocess.Popen([exe[0], "manager", f"__name:={manager_name[1:]}"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    stop, state = threading.Event(), {}
    try:
        rospy.wait_for_service(f"{manager_name}/load_nodelet", timeout=60)
        load = rospy.ServiceProxy(f"{manager_name}/load_nodelet", NodeletLoad)
        unload = rospy.ServiceProxy(f"{manager_name}/unload_nodelet", NodeletUnload)
        for name, kind in ((driver, "ranger_base/RangerNodelet"),
                           (subscriber, "ranger_base/PerfSubscriber")):
            if not load(name=name, type=kind, remap_source_args=[], remap_target_args=[],
                        my_argv=[], bond_id="").success:
                raise RuntimeError(f"cannot load {kind}")
        sub = rospy.Subscriber(f"/{ns}/system_state", SystemState, lambda m: state.update(m=m))
        if not wait_for(lambda: "m" in state and state["m"].link_up
                        and state["m"].control_mode == SystemState.CONTROL_MODE_CAN
                        and state["m"].identification in ("", "decided")):
            raise RuntimeError("the nodelet did not reach CAN command mode")
        sub.unregister()
        pub = rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1)
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = 0.4, 0.2

        def teleop():
            while not stop.is_set():
                pub.publish(cmd)
                time.sleep(0.05)
        threading.Thread(target=teleop, daemon=True).start()
        time.sleep(3.0)
        pid = manager.pid
        wall0, cpu0, threads0 = time.monotonic(), cpu_seconds(f"/proc/{pid}/stat"), thread_times(pid)
        rss = []
        while time.monotonic() - wall0 < duration:
            rss.append(rss_kib(pid))
            time.sleep(0.5)
        cpu1, threads1 = cpu_seconds(f"/proc/{pid}/stat"), thread_times(pid)
        wall = time.monotonic() - wall0
        stop.set()
        for name in (subscriber, driver):
            unload(name=name)
    finally:
        stop.set()
        manager.send_signal(signal.SIGINT)
        try:
            manager.wait(timeout=20)
        except subprocess.TimeoutExpired:
            manager.kill()
    with open(report) as f:
        rates = json.loads(f.read() or "{}")
    os.unlink(report)

    def share(seconds):
        return round(100.0 * seconds / wall, 2)
    threads = [{"tid": tid, "name": name, "cpu_percent": share(t1 - threads0.get(tid, ("", 0))[1])}
               for tid, (name, t1) in threads1.items()]
    chassis = next((t for t in threads if t["name"] == "ranger_sim"), None)
    total = share(cpu1 - cpu0)
    return {"duration_s": round(wall, 1), "manager_cpu_percent": total,
            "chassis_cpu_percent": chassis and chassis["cpu_percent"],
            "driver_cpu_percent": round(total - chassis["cpu_percent"], 2) if chassis else None,
            "threads": sorted(threads, key=lambda t: -t["cpu_percent"]),
            "rss_kib_median": int(statistics.median(rss)),
            "subscriber_nodelet_messages_per_s": rates}


def measure_fleet(rospy, duration, robots, params):
    import math
    import roslib.packages
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from ranger_msgs.msg import SystemState
    exe = roslib.packages.find_node("ranger_base", "ranger_base_node")[0]
    names = [f"fleet{i + 1}" for i in range(robots)]
    nodes = [subprocess.Popen([exe, f"__ns:=/{ns}", "_port_name:=sim", *params],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
             for ns in names]
    stop = threading.Event()
    try:
        states = {}
        subs = [rospy.Subscriber(f"/{ns}/system_state", SystemState,
                                 lambda m, ns=ns: states.__setitem__(ns, m)) for ns in names]
        ok = wait_for(lambda: all(ns in states and states[ns].link_up and
                                  states[ns].control_mode == SystemState.CONTROL_MODE_CAN and
                                  states[ns].identification in ("", "decided") for ns in names),
                      timeout=120)
        for s in subs:
            s.unregister()
        if not ok:
            raise RuntimeError("not every robot reached CAN command mode: " + ", ".join(
                ns for ns in names if ns not in states or not states[ns].link_up))
        pubs = [rospy.Publisher(f"/{ns}/cmd_vel", Twist, queue_size=1) for ns in names]
        wait_for(lambda: all(p.get_num_connections() > 0 for p in pubs))
        twists = []
        for i in range(robots):  # each its own circle
            t = Twist()
            t.linear.x, t.angular.z = 0.3 + 0.02 * i, 0.1 + 0.02 * i
            twists.append(t)

        def teleop():
            while not stop.is_set():
                for p, t in zip(pubs, twists):
                    p.publish(t)
                time.sleep(0.1)
        threading.Thread(target=teleop, daemon=True).start()
        time.sleep(3.0)
        pids = [n.pid for n in nodes]
        wall0 = time.monotonic()
        cpu0 = [cpu_seconds(f"/proc/{pid}/stat") for pid in pids]
        threads0 = [thread_times(pid) for pid in pids]
        rss = []
        while time.monotonic() - wall0 < duration:
            rss.append([rss_kib(pid) for pid in pids])
            time.sleep(1.0)
        cpu1 = [cpu_seconds(f"/proc/{pid}/stat") for pid in pids]
        threads1 = [thread_times(pid) for pid in pids]
        wall = time.monotonic() - wall0
        stop.set()
        time.sleep(0.2)
        for p in pubs:
            p.publish(Twist())  # stop, then compare at rest
        time.sleep(2.0)
        robots_out = []
        for i, ns in enumerate(names):
            odom = rospy.wait_for_message(f"/{ns}/odom", Odometry, timeout=10)
            truth = rospy.wait_for_message(f"/{ns}/sim/ground_truth", Odometry, timeout=10)
            o, g = odom.pose.pose, truth.pose.pose

            def yaw(q):
                return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            err = math.hypot(o.position.x - g.position.x, o.position.y - g.position.y)
            dyaw = math.degrees(abs(math.remainder(yaw(o.orientation) - yaw(g.orientation),
                                                   2 * math.pi)))
            chassis = next((t for t, (n, _) in threads1[i].items() if n == "ranger_sim"), None)
            chassis_cpu = (threads1[i][chassis][1] - threads0[i].get(chassis, ("", 0))[1]
                           if chassis else 0.0)
            robots_out.append({
                "ns": ns, "cpu_percent": round(100.0 * (cpu1[i] - cpu0[i]) / wall, 2),
                "driver_cpu_percent": round(100.0 * (cpu1[i] - cpu0[i] - chassis_cpu) / wall, 2),
                "rss_kib_median": int(statistics.median(r[i] for r in rss)),
                "position_error_mm": round(1000.0 * err, 1), "heading_error_deg": round(dyaw, 3),
                "ground_truth_from_origin_m": round(math.hypot(g.position.x, g.position.y), 3)})
    finally:
        stop.set()
        for n in nodes:
            n.send_signal(signal.SIGINT)
        for n in nodes:
            try:
                n.wait(timeout=20)
            except subprocess.TimeoutExpired:
                n.kill()
    total = sum(r["cpu_percent"] for r in robots_out)
    return {"robots": robots, "duration_s": round(wall, 1),
            "total_cpu_percent": round(total, 2),
            "per_robot_cpu_percent_mean": round(total / robots, 2),
            "per_robot_driver_cpu_percent_mean": round(
                statistics.mean(r["driver_cpu_percent"] for r in robots_out), 2),
            "total_rss_mib": round(sum(r["rss_kib_median"] for r in robots_out) / 1024.0, 1),
            "per_robot": robots_out}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=30.0, help="load phase, s")
    parser.add_argument("--samples", type=int, default=400, help="latency samples")
    parser.add_argument("--json", help="also write the figures to this file")
    parser.add_argument("--phases",
                        default="load,floor,latency,keepalive,keepalive_fifo,nodelet,fleet",
                        help="which measurements, comma-separated")
    parser.add_argument("--robots", type=int, default=10, help="fleet: how many robots")
    parser.add_argument("--node-arg", action="append", default=[],
                        help="extra node argument (both phases), e.g. _min_command_interval:=0.001")
    args = parser.parse_args()

    # A private rosmaster with a throwaway ROS_HOME.
    home = tempfile.mkdtemp(prefix="ranger-perf-roshome-")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    os.environ.update(ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOME=home,
                      ROS_LOG_DIR=os.path.join(home, "log"), ROS_HOSTNAME="localhost")
    master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        import rospy
        wait_for(lambda: subprocess.run(["rosnode", "list"], capture_output=True).returncode == 0)
        rospy.init_node("ranger_perf", anonymous=True, disable_signals=True)
        with open("/proc/cpuinfo") as f:
            cpu = next((line.split(":", 1)[1].strip() for line in f
                        if line.startswith("model name")), "unknown")
        figures = {"machine": {"cpu": cpu, "cores": os.cpu_count(), "kernel": platform.release()},
                   "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
                   "command": " ".join([os.path.relpath(sys.argv[0])] + sys.argv[1:])}
        phases = args.phases.split(",")
        measurements = {
            "load": ("load", lambda: measure_load(rospy, args.duration, args.node_arg)),
            "floor": ("roscpp_floor", lambda: measure_load(rospy, args.duration, [], floor=True)),
            "latency": ("latency_cmd_vel_to_0x111",
                        lambda: measure_latency(rospy, args.samples, args.node_arg)),
            "keepalive": ("keepalive_0x111",
                          lambda: measure_keepalive(rospy, args.duration, args.node_arg)),
            "keepalive_fifo": ("keepalive_0x111_fifo",
                               lambda: measure_keepalive(rospy, args.duration, args.node_arg,
                                                         fifo=True)),
            "nodelet": ("nodelet", lambda: measure_nodelet(rospy, args.duration, args.node_arg)),
            "fleet": ("fleet", lambda: measure_fleet(rospy, args.duration, args.robots,
                                                     args.node_arg)),
        }
        for phase in phases:
            if phase not in measurements:
                sys.exit(f"unknown phase {phase}: use {','.join(measurements)}")
        for phase in phases:
            key, measure = measurements[phase]
            try:
                figures[key] = measure()
            except Exception as e:  # a benchmark: report what failed, measure the rest
                figures[key] = {"error": f"{type(e).__name__}: {e}"}
            print(f"== {phase}: {json.dumps(figures[key])[:200]}", file=sys.stderr, flush=True)
        load, floor = figures.get("load", {}), figures.get("roscpp_floor", {})
        if load.get("driver_cpu_percent") is not None and "cpu_percent" in floor:
            load["driver_over_floor_percent"] = round(load["driver_cpu_percent"]
                                                      - floor["cpu_percent"], 2)
    finally:
        master.send_signal(signal.SIGINT)
        try:
            master.wait(timeout=10)
        except subprocess.TimeoutExpired:
            master.kill()
        shutil.rmtree(home, ignore_errors=True)

    print(json.dumps(figures, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)


if __name__ == "__main__":
    main()
