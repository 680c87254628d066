#!/usr/bin/python3
"""N namespaced virtual RANGERs in one ROS graph: CPU and memory per robot.

One roslaunch starts ranger_bringup/ranger_minimal.launch N times (sim:=true,
namespace:=robot1..robotN; one diagnostic_aggregator for the graph, as the launch file asks),
so each robot is ranger_base_node (with its in-process virtual chassis at the full feedback
rate, 50 Hz odometry and TF) plus robot_state_publisher. Once every robot reports CAN command
mode, each gets cmd_vel at 20 Hz (a slow circle) and, after a settling time, CPU time (from
/proc/<pid>/stat: the CPU-time figure, robust to a loaded machine) and RSS of every launched
process are sampled for --duration seconds; the odometry rate each robot achieved is counted
(does the machine keep up?). A benchmark: prints figures (and --json), asserts nothing.

  scripts/perf_fleet.py [--robots 10] [--duration 20] [--json FILE]

Needs a built and sourced workspace (source install/setup.bash).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "ranger_base",
                                "scripts"))
import measure_performance as mp  # noqa: E402  (rosmaster, node stop, /proc helpers)

SETTLE_S = 3.0


def launch_file(robots):
    includes = []
    for k in range(1, robots + 1):
        includes.append(f"""  <include file="$(find ranger_bringup)/launch/ranger_minimal.launch">
    <arg name="sim" value="true"/>
    <arg name="namespace" value="robot{k}"/>
    <arg name="diagnostics_aggregator" value="{'true' if k == 1 else 'false'}"/>
    <arg name="log_output" value="log"/>
  </include>""")
    return "<launch>\n" + "\n".join(includes) + "\n</launch>\n"


def descendants(pid):
    """pid's children, grandchildren, ... (from /proc/*/stat ppid)."""
    parent_of = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    parent_of[int(entry)] = int(f.read().rsplit(")", 1)[1].split()[1])
            except (FileNotFoundError, ProcessLookupError):
                pass
    found, frontier = [], [pid]
    while frontier:
        p = frontier.pop()
        children = [c for c, pp in parent_of.items() if pp == p]
        found += children
        frontier += children
    return found


def identify(pid):
    """(role, robot) of a launched process: role from __name:=, robot from ROS_NAMESPACE."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            args = f.read().decode(errors="replace").split("\0")
        with open(f"/proc/{pid}/environ", "rb") as f:
            env = dict(kv.split("=", 1) for kv in f.read().decode(errors="replace").split("\0")
                       if "=" in kv)
    except (FileNotFoundError, ProcessLookupError):
        return None, None
    name = next((a.split(":=", 1)[1] for a in args if a.startswith("__name:=")), None)
    if name is None:
        return None, None
    return name, env.get("ROS_NAMESPACE", "/").strip("/") or None


def wait_for_command_mode(rospy, robots, timeout):
    from ranger_msgs.msg import SystemState
    in_can = set()
    lock = threading.Lock()
    subs = []
    for k in range(1, robots + 1):
        def on_state(msg, k=k):
            if msg.link_up and msg.control_mode == SystemState.CONTROL_MODE_CAN:
                with lock:
                    in_can.add(k)
        subs.append(rospy.Subscriber(f"/robot{k}/system_state", SystemState, on_state))
    mp.wait_for(lambda: len(in_can) == robots, timeout=timeout, interval=0.2)
    for s in subs:
        s.unregister()
    return len(in_can)


def measure(rospy, launch, robots, duration):
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    t_launch = time.monotonic()
    reached = wait_for_command_mode(rospy, robots, timeout=180.0)
    all_up_s = time.monotonic() - t_launch

    pubs = [rospy.Publisher(f"/robot{k}/cmd_vel", Twist, queue_size=1)
            for k in range(1, robots + 1)]
    odom_count = [0] * robots

    def on_odom(_msg, i):
        odom_count[i] += 1
    odom_subs = [rospy.Subscriber(f"/robot{k}/odom", Odometry, on_odom, callback_args=k - 1,
                                  queue_size=10) for k in range(1, robots + 1)]
    stop = threading.Event()

    def teleop():
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = 0.4, 0.2
        while not stop.is_set():
            for p in pubs:
                p.publish(cmd)
            time.sleep(0.05)
    driver = threading.Thread(target=teleop, daemon=True)
    driver.start()
    time.sleep(SETTLE_S)

    processes = {}
    for pid in descendants(launch.pid):
        role, robot = identify(pid)
        if role:
            processes[pid] = (role, robot)

    def cpu_now():
        out = {}
        for pid in processes:
            try:
                out[pid] = mp.cpu_seconds(f"/proc/{pid}/stat")
            except (FileNotFoundError, ProcessLookupError):
                pass
        return out
    counts0 = list(odom_count)
    wall0, cpu0 = time.monotonic(), cpu_now()
    rss = {pid: [] for pid in processes}
    while time.monotonic() - wall0 < duration:
        for pid in processes:
            try:
                rss[pid].append(mp.rss_kib(pid))
            except (FileNotFoundError, ProcessLookupError):
                pass
        time.sleep(1.0)
    wall1, cpu1 = time.monotonic(), cpu_now()
    counts1 = list(odom_count)
    stop.set()
    driver.join()
    for s in odom_subs:
        s.unregister()

    wall = wall1 - wall0
    per_process = []
    for pid, (role, robot) in sorted(processes.items(), key=lambda kv: (str(kv[1][1]), kv[1][0])):
        if pid not in cpu0 or pid not in cpu1:
            continue
        per_process.append({"pid": pid, "role": role, "robot": robot,
                            "cpu_percent": round(100.0 * (cpu1[pid] - cpu0[pid]) / wall, 2),
                            "rss_kib": int(statistics.median(rss[pid])) if rss[pid] else None})

    def of_role(role, key):
        return [p[key] for p in per_process if p["role"] == role and p[key] is not None]
    node_cpu, node_rss = of_role("ranger_base_node", "cpu_percent"), of_role("ranger_base_node",
                                                                              "rss_kib")
    rsp_cpu, rsp_rss = of_role("robot_state_publisher", "cpu_percent"), of_role(
        "robot_state_publisher", "rss_kib")
    per_robot_total = {}
    for p in per_process:  # the robot's own processes (not the graph's one aggregator)
        if p["robot"] and p["role"] in ("ranger_base_node", "robot_state_publisher"):
            per_robot_total[p["robot"]] = per_robot_total.get(p["robot"], 0.0) + p["cpu_percent"]
    odom_hz = [(c1 - c0) / wall for c0, c1 in zip(counts0, counts1)]

    def summary(values, digits=2):
        if not values:
            return None
        return {"median": round(statistics.median(values), digits),
                "min": round(min(values), digits), "max": round(max(values), digits)}
    return {
        "robots": robots,
        "robots_in_command_mode": reached,
        "all_in_command_mode_after_s": round(all_up_s, 1),
        "duration_s": round(wall, 1),
        "node_cpu_percent": summary(node_cpu),
        "node_rss_kib": summary(node_rss, 0),
        "robot_state_publisher_cpu_percent": summary(rsp_cpu),
        "robot_state_publisher_rss_kib": summary(rsp_rss, 0),
        "per_robot_cpu_percent": summary(list(per_robot_total.values())),
        "graph_cpu_percent_total": round(sum(p["cpu_percent"] for p in per_process), 1),
        "graph_rss_kib_total": sum(p["rss_kib"] or 0 for p in per_process),
        "odom_hz": summary(odom_hz, 1),
        "processes": per_process,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, default=10)
    parser.add_argument("--duration", type=float, default=20.0, help="measurement window, s")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()

    env = mp.Environment()
    launch = None
    with tempfile.NamedTemporaryFile("w", suffix=".launch", prefix="ranger-fleet-",
                                     delete=False) as f:
        f.write(launch_file(args.robots))
        launch_path = f.name
    try:
        import rospy
        mp.wait_for(lambda: subprocess.run(["rosnode", "list"],
                                           capture_output=True).returncode == 0)
        rospy.init_node("ranger_perf_fleet", anonymous=True, disable_signals=True)
        launch = subprocess.Popen(["roslaunch", launch_path], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)
        figures = {"machine": mp.machine(),
                   "command": " ".join([os.path.relpath(sys.argv[0])] + sys.argv[1:]),
                   "launch": f"{args.robots} x ranger_minimal.launch sim:=true namespace:=robotN",
                   "fleet": measure(rospy, launch, args.robots, args.duration)}
    finally:
        if launch is not None:
            mp.stop_node(launch)
        env.close()
        os.unlink(launch_path)

    print(json.dumps(figures, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)
    return 0 if figures["fleet"]["robots_in_command_mode"] == args.robots else 1


if __name__ == "__main__":
    sys.exit(main())
