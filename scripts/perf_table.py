#!/usr/bin/python3
"""Usage: scripts/perf_table.py RAW. Prints the tables of docs/PERFORMANCE.md (scripts/perf.sh
writes the header) from RAW = build/perf/raw (NAME.cmd: a step's command, NAME.out: its output);
every row names its target, where one exists, and the command that produced it."""

import json
import os
import re
import statistics
import sys

raw, out = sys.argv[1], []


def read(name):
    path = os.path.join(raw, name)
    return open(path).read().strip() if os.path.exists(path) else ""


def medians(step):
    """run name -> Google Benchmark's median aggregate, with 'ns': the CPU time in ns."""
    runs = {b["run_name"]: dict(b, ns=b["cpu_time"] * {"ns": 1, "us": 1e3}[b["time_unit"]])
            for b in json.loads(read(f"{step}.out"))["benchmarks"]
            if b.get("aggregate_name") == "median"}
    if not runs:
        raise ValueError(f"no medians in {step}.out")
    return runs


def row(figure, value, step, target="", met=None):
    goal = f"{target}: {'met' if met else '**missed**'}" if target else ""
    cmd = read(step + ".cmd")
    out.append(f"| {figure} | {value} | {goal} | {f'`{cmd}`' if cmd else 'not run'} |")


def section(*steps):
    """A table: title and text from the first step's docstring; a step that did not run or
    printed nothing usable gets a row saying so."""
    title, text = steps[0].__doc__.split("\n", 1)
    out.extend(["", f"## {title}", "", " ".join(text.split()), "",
                "| Figure | Value | Target | Command |", "|---|---|---|---|"])
    for step in steps:
        try:
            step()
        except (ValueError, KeyError, TypeError, AttributeError):
            name = step.__name__
            row(f"({name})", "not measured: " + (f"failed, see {raw}/{name}.log"
                                                 if read(name + ".cmd") else "skipped"), name)


def codec():
    """Codec
    Google Benchmark, median of 5 repetitions, CPU time; the feedback cycle: the 13 frames sent
    every 20 ms. Instructions: callgrind, collecting in `ranger::decode` only, 1.3 M frames."""
    b = medians("codec")
    cycle = b["BM_DecodeFeedbackCycle"]["ns"]
    row("Feedback cycle decoded (13 frames)", f"{cycle:.1f} ns", "codec", "< 1 µs", cycle < 1000)
    for what in ("Decode", "Encode"):
        ns = [v["ns"] for k, v in b.items() if re.fullmatch(rf"BM_{what}/\d+", k)]
        row(f"{what}, one frame (median over {len(ns)} IDs)",
            f"{statistics.median(ns):.1f} ns ({min(ns):.1f} .. {max(ns):.1f})", "codec")


def callgrind():
    text = read("callgrind.out")
    ir = int(re.search(r"Collected\s*:\s*([\d,]+)", text).group(1).replace(",", ""))
    cycles, frames = re.search(r"decoded (\d+) cycles x (\d+) frames", text).groups()
    row("Decode, instructions per frame", f"{ir / int(cycles) / int(frames):.1f}" if ir else
        "none collected: has `ranger::decode`'s signature changed?", "callgrind")


def control():
    """Control
    The driver's work per 20 ms cycle. Google Benchmark, median of 5 repetitions, CPU time."""
    names = {"BM_ControllerFeedbackCycleAndTick": "Controller: feedback cycle + command + tick",
             "BM_OdometryFeedbackCycle": "Odometry: one cycle", "BM_FitBodyTwist": "Body twist "
             "fitted to 4 wheels", **{f"BM_SolveKinematics/{i}": f"Kinematics solve, {mode}"
                                     for i, mode in enumerate(("Ackermann", "oblique", "spin"))}}
    for name, b in medians("control").items():
        row(names.get(name, f"`{name}`"), f"{b['ns']:.1f} ns", "control")


def bus():
    """Bus (in-process loopback)
    Google Benchmark, median of 3 repetitions. Throughput (wall clock): at most 128 frames in
    flight. Latency (wall clock): send -> receive, one frame in flight."""
    b = {name.split("/")[0]: v for name, v in medians("bus").items()}
    row("Send + receive, one thread", f"{b['BM_LoopbackSendThenReceive']['ns']:.1f} ns", "bus")
    row("Throughput, reader thread",
        f"{b['BM_LoopbackThroughputWithReaderThread']['frames_per_s']:,.0f} frames/s", "bus")
    for p in ("p50", "p99"):
        row(f"Latency {p}", f"{b['BM_LoopbackLatency'][p + '_us']:.1f} µs", "bus")


def node():
    """ROS node
    ranger_base_node, `port_name:=sim` (the virtual chassis, a thread of the node, sends the full
    feedback), `odom`, `/tf`, `joint_states` at 50 Hz to subscribers, `cmd_vel` at 20 Hz; CPU in
    % of one core. Latency: `cmd_vel` published -> the 0x111's send stamp (`cmd_vel_out`); it
    includes up to `min_command_interval` (5 ms by default, see ranger_base/README.md)."""
    doc = json.loads(read("node.json"))
    load, lat = doc["load"], doc["latency_cmd_vel_to_0x111"]
    cpu = load["driver_cpu_percent"]
    row("Driver CPU (node minus chassis thread)", "chassis thread not found" if cpu is None else
        f"{cpu} % of one core", "node", "≤ 1 %", cpu is not None and cpu <= 1.0)
    floor = doc["roscpp_floor"]
    row("roscpp floor: the same topics and rates, no driver (`roscpp_floor`)",
        f"{floor['cpu_percent']} % (" + ", ".join(
            f"{t['name']} {t['tid']}: {t['cpu_percent']}" for t in floor["threads"]
            if t["cpu_percent"]) + ")", "node")
    if "driver_over_floor_percent" in load:
        row("Driver CPU above the roscpp floor", f"{load['driver_over_floor_percent']} %", "node")
    row("Virtual chassis thread (name tid)", f"{load['chassis_cpu_percent']} % "
        f"({load['chassis_thread']})", "node")
    row("Node process (driver + chassis)", f"{load['node_cpu_percent']} % (feedback "
        f"{load['feedback_frames_per_s']} frames/s)", "node")
    row("Per thread, % (name tid)", ", ".join(f"{t['name']} {t['tid']}: {t['cpu_percent']}"
                                             for t in load["threads"] if t["cpu_percent"]), "node")
    rss = load["rss_kib_median"] * 1.024e-3
    row("RSS", f"{rss:.1f} MB (median; max {load['rss_kib_max'] * 1.024e-3:.1f})", "node",
        "≤ 15 MB", rss <= 15.0)
    for p, limit in (("p50", 0.5), ("p90", None), ("p99", 2.0)):
        row(f"cmd_vel -> 0x111 latency {p}", f"{lat[p + '_ms']} ms" + (
            f" (max {lat['max_ms']}, {lat['samples']} samples)" if p == "p99" else ""), "node",
            f"≤ {limit:g} ms" if limit else "", limit and lat[p + "_ms"] <= limit)
    row("Received by the subscribers", ", ".join(
        f"{t} {r} Hz" for t, r in load["subscribers_messages_per_s"].items()), "node")


def node_ros2(distro):
    """A section's step: the ROS 2 node on `distro` (its step node_ros2_DISTRO)."""
    step = f"node_ros2_{distro}"

    def measured():
        doc = json.loads(read(f"{step}.json"))
        load, lat, floor = doc["load"], doc["latency_cmd_vel_to_0x111"], doc["rclpy_floor"]
        ros1 = json.loads(read("node.json"))["load"] if read("node.json") else {}
        cpu, ros1_cpu = load["driver_cpu_percent"], ros1.get("driver_cpu_percent")
        ratio = cpu / ros1_cpu if cpu is not None and ros1_cpu else None
        row("Driver CPU (node minus chassis thread)", "chassis thread not found" if cpu is None
            else f"{cpu} % of one core" + (f" ({ratio:.2f}x the ROS 1 node's {ros1_cpu} %)"
                                           if ratio else ""), step, "≤ 1.5x the ROS 1 node's",
            ratio is not None and ratio <= 1.5)
        row("rclpy floor: the same topics and rates, no driver", f"{floor['cpu_percent']} %",
            step)
        if cpu is not None:
            above = round(cpu - floor["cpu_percent"], 2)
            row("Driver CPU above the rclpy floor", f"{above} %" + (
                f" (the ROS 1 node above roscpp's: {ros1['driver_over_floor_percent']} %)"
                if "driver_over_floor_percent" in ros1 else ""), step)
        row("Per thread, % (name)", ", ".join(f"{t['name']}: {t['cpu_percent']}"
                                             for t in load["threads"] if t["cpu_percent"]), step)
        rss = load["rss_kib_median"] * 1.024e-3
        row("RSS", f"{rss:.1f} MB (median)", step, "≤ 60 MB", rss <= 60.0)
        for p, limit in (("p50", None), ("p90", None), ("p99", 1.0)):
            row(f"cmd_vel -> 0x111 latency {p}", f"{lat[p + '_ms']} ms" + (
                f" (max {lat['max_ms']}, {lat['samples']} samples)" if p == "p99" else ""),
                step, f"≤ {limit:g} ms" if limit else "", limit and lat[p + "_ms"] <= limit)
    measured.__name__ = step
    measured.__doc__ = f"""ROS 2 node on {distro.capitalize()}
    ros2/ranger_base's ranger_base_node (rclpy over the ranger_can binding; the fast path of
    ranger_base/rclpy_fast.py, the default) on ROS 2 {distro.capitalize()} (its venv of PyPI
    wheels, scripts/setup_ros2.sh), in the same run, the same load: `port_name:=sim`,
    subscribers on `odom`, `/tf`, `joint_states` (raw: bytes, no Python message, as the ROS 1
    measurement's `rospy.AnyMsg`), `cmd_vel` at 20 Hz; latency as above, from the twist's bytes
    handed to the publisher (serialised beforehand) to the 0x111's send stamp
    (ros2/ranger_base/ranger_base/measure_performance.py). The node takes `cmd_vel`'s bytes and
    reads them in C++ (`ranger_can.read_twist`). Where the resident memory goes (Jazzy, one
    process, VmRSS after each step, measured 2026-11-28): Python 9 MB; `import rclpy` 24 MB;
    the first node 35 MB (numpy, which the parameter services' messages import, 16 MB, and
    Fast DDS's participant, its heap and threads, the rest); ranger_can and ranger_base 4 MB;
    the driver, its threads and the node's 20 publishers and 7 services the rest. The goal of
    60 MB is below what rclpy and Fast DDS take before the node does anything (70 MB): not met
    by a change in this node. Where the CPU goes: the rclpy floor (rclpy and Fast DDS sending
    the same messages, no driver) is itself about the ROS 1 node's whole driver CPU; cProfile of
    the publication thread (ranger_publish, the largest; 25 s on Jazzy, wall-clock):
    `publish_raw` (rclpy into Fast DDS) 1.04 s for 3174 messages, the node's own Python (states,
    diagnostics, the audience, the cmd_vel type check, the encoder) under 0.2 s, the rest
    waiting in `Driver.wait_motion` with the GIL released: what is above the goal is rclpy's and
    Fast DDS's per-message cost, not the node's Python."""
    return measured


def keepalive():
    """Publication off the CAN schedule
    The 0x111 keep-alive's period while the node publishes to a subscriber on every topic it
    advertises, two of them slow (0.2 s per message, on `odom` and `/tf`): one `cmd_vel`, then
    every 0x111 is a scheduled one; deviation = |interval between consecutive `cmd_vel_out`
    stamps (taken right after each send) - 20 ms|; with the driver thread at the default
    priority, and under SCHED_FIFO 50 (`chrt`), as a robot computer that runs other work would
    run it. Publication runs on a thread of the node's own, so this does not depend on what is
    published; what remains is how soon the kernel runs the driver thread on a loaded machine."""
    doc = json.loads(read("node.json"))
    for key, how in (("keepalive_0x111", "default priority"),
                     ("keepalive_0x111_fifo", "driver thread SCHED_FIFO 50")):
        k = doc[key]
        if "error" in k:
            raise ValueError(k["error"])
        for p in ("p50", "p99"):
            v = k[f"deviation_{p}_ms"]
            row(f"0x111 period deviation from 20 ms, {p} ({how})", f"{v} ms" + (
                f" (max {k['deviation_max_ms']}, {k['intervals']} intervals, mean period "
                f"{k['period_ms_mean']} ms, {k['topics_subscribed']} topics subscribed)"
                if p == "p99" else ""), "node", "≤ 1 ms" if p == "p99" else "",
                v <= 1.0 if p == "p99" else None)


def nodelet():
    """Nodelet
    The driver as the nodelet `ranger_base/RangerNodelet` in a manager of its own, with the
    subscriber nodelet `ranger_base/PerfSubscriber` on `odom`, `/tf` and `joint_states` in the
    same manager (shared pointers: no serialisation, no socket); the virtual chassis's full
    feedback, odometry at 50 Hz, `cmd_vel` at 20 Hz from another process."""
    n = json.loads(read("node.json"))["nodelet"]
    if "error" in n:
        raise ValueError(n["error"])
    cpu = n["driver_cpu_percent"]
    # The driver's own threads (the bus and the keep-alive; publication): what it costs, apart
    # from the manager's roscpp threads, which also run the subscriber nodelet's callbacks.
    own = [t for t in n["threads"] if t["name"] in ("ranger_driver", "ranger_publish")]
    own_cpu = round(sum(t["cpu_percent"] for t in own), 2) if own else None
    row("Driver CPU, its own threads (ranger_driver + ranger_publish)",
        f"{own_cpu} % of one core", "node", "≤ 0.6 %", own_cpu is not None and own_cpu <= 0.6)
    row("Driver CPU with the manager's share (manager minus chassis thread; roscpp and the "
        "subscriber nodelet included)", f"{cpu} % of one core", "node")
    row("Manager process (driver + chassis + subscriber nodelet)",
        f"{n['manager_cpu_percent']} % (chassis thread {n['chassis_cpu_percent']} %)", "node")
    row("Per thread, % (name tid)", ", ".join(f"{t['name']} {t['tid']}: {t['cpu_percent']}"
                                             for t in n["threads"] if t["cpu_percent"]), "node")
    row("Received by the subscriber nodelet", ", ".join(
        f"{t} {r} Hz" for t, r in n["subscriber_nodelet_messages_per_s"].items()), "node")


def fleet():
    """Fleet
    Ten `ranger_base_node` processes at once, each with its own in-process virtual chassis
    (`port_name:=sim`, protocol identified), each driven in a circle of its own by `cmd_vel` at
    10 Hz, on this machine; no subscriber. Then each is stopped and its `odom` compared with its
    chassis's `sim/ground_truth`."""
    f = json.loads(read("node.json"))["fleet"]
    if "error" in f:
        raise ValueError(f["error"])
    row(f"{f['robots']} robots: total CPU", f"{f['total_cpu_percent']} % of one core "
        f"(machine: {os.cpu_count()} cores)", "node")
    row("Per robot: CPU (mean)", f"{f['per_robot_cpu_percent_mean']} % (driver without its "
        f"virtual chassis {f['per_robot_driver_cpu_percent_mean']} %)", "node")
    row("Memory: total RSS", f"{f['total_rss_mib']} MiB (per robot "
        f"{f['total_rss_mib'] / f['robots']:.1f} MiB)", "node")
    worst = max(f["per_robot"], key=lambda r: r["position_error_mm"])
    row("Odometry vs ground truth, worst robot", f"{worst['position_error_mm']} mm, "
        f"{worst['heading_error_deg']} deg ({worst['ns']}, "
        f"{worst['ground_truth_from_origin_m']} m from its start)", "node")
    row("Per robot: CPU %, RSS MiB, position error mm", "; ".join(
        f"{r['ns']} {r['cpu_percent']}, {r['rss_kib_median'] / 1024:.1f}, "
        f"{r['position_error_mm']}" for r in f["per_robot"]), "node")


def odometry():
    """Odometry error against ground truth
    The end-to-end suite on the in-process bus, per motion mode (lock-step, simulated clock:
    deterministic)."""
    lines = re.findall(r"^\[odometry\] bus=\S+ mode=(\S+) distance=([\d.]+) m turns=([\d.]+) "
                       r"position_error=([\d.]+) m .*? \(([\d.]+) deg/turn\)",
                       read("odometry.out"), re.M)
    if not lines:
        raise ValueError("no [odometry] lines")
    for mode, *figures in lines:
        distance, turns, error, per_turn = map(float, figures)
        where = f"over {distance:.2f} m, {turns:.2f} turns"
        if distance > 0.5:
            pct = 100 * error / distance
            row(f"{mode.capitalize()}: position error", f"{pct:.3g} % of distance "
                f"({1000 * error:.1f} mm {where})", "odometry", "≤ 1 %", pct <= 1.0)
        if turns > 0.1:
            row(f"{mode.capitalize()}: heading error", f"{per_turn:.4f} deg/turn ({where})",
                "odometry", "≤ 1 deg/turn", per_turn <= 1.0)


section(codec, callgrind)
section(control)
section(bus)
section(node)
section(node_ros2("jazzy"))
section(node_ros2("kilted"))
section(keepalive)
section(nodelet)
section(fleet)
section(odometry)
# The vendor comparison runs apart (a VM, ~10 minutes): its section is carried over as it is.
previous = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs",
                        "PERFORMANCE.md")
if os.path.exists(previous):
    text = open(previous).read()
    m = re.search(r"^## Against the vendor's driver\n.*?(?=^## |\Z)", text, re.M | re.S)
    if m:
        out.extend(["", m.group(0).rstrip()])
print("\n".join(out))
