#!/usr/bin/python3
"""Turns the raw outputs of scripts/perf.sh into docs/perf/results.json and docs/PERFORMANCE.md,
comparing every figure with the previous results.json (read before it is overwritten).

  scripts/perf_report.py --raw build/perf/raw --build-dir build/perf \
      --results docs/perf/results.json --markdown docs/PERFORMANCE.md --command "scripts/perf.sh"

Standard library only. Called by scripts/perf.sh; not meant to be run by hand except to
re-render from an existing raw directory.
"""

import argparse
import datetime
import json
import os
import platform
import re
import statistics
import subprocess

SCHEMA = 1

# What a figure's change means, by kind of measurement: how much change is noise, and how far
# to trust the figure on a shared, loaded machine.
KINDS = {
    "instr": (1.0, "instructions counted by callgrind: exact and repeatable, the figure to trust "
                   "for regressions"),
    "sim": (1.0, "simulated clock (lock-step, ManualClock): deterministic"),
    "cpu": (15.0, "CPU time consumed (benchmark cpu_time or /proc utime+stime): trustworthy, "
                  "little affected by other load"),
    "mem": (10.0, "resident memory (VmRSS): stable"),
    "wall": (30.0, "wall clock: includes waiting for a CPU on a loaded machine; noisy, compare "
                   "only runs at similar load"),
    "vm": (100.0, "wall clock inside the qemu TCG VM: measures the emulator as much as the code; "
                  "indicative only"),
    "count": (0.0, "a count: any change matters"),
}

SECTIONS = [
    ("codec", "1. Codec", "Decode/encode cost per frame and per 20 ms feedback cycle (13 frames: "
     "0x211, 0x221, 0x251-0x258, 0x271, 0x281, 0x291). Target: a full cycle decoded in < 1 us. "
     "Google Benchmark, median of 5 repetitions, cpu_time; instructions by callgrind with "
     "collection toggled on ranger::decode only (100,000 cycles = 1.3 M frames)."),
    ("control", "2. Control", "The driver's work per 20 ms cycle, from bench_control (median of "
     "5 repetitions, cpu_time)."),
    ("bus", "3. Bus", "Throughput (at most 128 frames in flight, none lost) and send -> receive "
     "latency (one frame in flight, reader blocked in receive()). In-process loopback natively; "
     "vcan as stated in the row."),
    ("node", "4. ROS node", "ranger_base_node with port_name:=sim (the in-process virtual chassis "
     "sends the full feedback, ~790 frames/s, through the node's CAN thread, controller and "
     "odometry), 50 Hz odometry + TF, cmd_vel at 20 Hz. CPU and RSS of the node process, which "
     "also hosts the virtual chassis. Latency: cmd_vel published -> the node's stamp of the "
     "resulting 0x111 (cmd_vel_out), one host clock. Targets: <= 1 % of one core, p99 <= 2 ms."),
    ("odometry", "5. Odometry error vs ground truth", "The driver's odometry (wheels source) "
     "against the virtual chassis's integrated ground truth, per motion mode, from the "
     "end-to-end suite on the in-process bus (lock-step, simulated clock: deterministic). "
     "Budget: <= 1 % of distance, <= 1 deg of heading per full turn."),
    ("launch", "6. Launch to CAN command mode", "From just before the process starts to the "
     "header stamp of the first system_state reporting link up and CAN control mode "
     "(state_publish_rate 100 Hz for 10 ms resolution), port_name sim; median of the runs."),
    ("fleet", "7. Ten virtual RANGERs in one ROS graph", "One roslaunch of ranger_minimal.launch "
     "sim:=true namespace:=robot1..robot10 (each robot: ranger_base_node with its in-process "
     "virtual chassis at full feedback rate, robot_state_publisher; one diagnostic_aggregator), "
     "cmd_vel at 20 Hz to each, 20 s window. CPU % is of one core (the machine has all its "
     "cores x 100 %)."),
]


# ---- inputs ----------------------------------------------------------------------------------

def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def read_text(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


def run(cmd, cwd=None):
    try:
        return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True,
                              check=False).stdout.strip()
    except OSError:
        return ""


def machine_info(build_dir, repo):
    cpu = "unknown"
    for line in (read_text("/proc/cpuinfo") or "").splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    distro = "unknown"
    for line in (read_text("/etc/os-release") or "").splitlines():
        if line.startswith("PRETTY_NAME="):
            distro = line.split("=", 1)[1].strip().strip('"')
    mem_kib = 0
    for line in (read_text("/proc/meminfo") or "").splitlines():
        if line.startswith("MemTotal:"):
            mem_kib = int(line.split()[1])
    compiler = ""
    cache = read_text(os.path.join(build_dir, "CMakeCache.txt")) or ""
    m = re.search(r"^CMAKE_CXX_COMPILER:\w+=(.+)$", cache, re.M)
    if m:
        compiler = run([m.group(1), "--version"]).splitlines()[0:1]
        compiler = compiler[0] if compiler else ""
    build_type = re.search(r"^CMAKE_BUILD_TYPE:\w+=(.*)$", cache, re.M)
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "kernel": platform.release(),
        "distro": distro,
        "memory_gib": round(mem_kib / 1048576, 1),
        "compiler": compiler,
        "library_build": f"{build_dir} ({build_type.group(1) if build_type else '?'})",
        "node_build": "install/ via scripts/build.sh ros (RelWithDebInfo unless RANGER_BUILD_TYPE)",
        "git": run(["git", "rev-parse", "--short", "HEAD"], cwd=repo)
        + (" + uncommitted changes" if run(["git", "status", "--porcelain"], cwd=repo) else ""),
    }


def machine_line(m):
    return f"{m['cpu']}, {m['cores']} cores, Linux {m['kernel']}, {m['distro']}"


def gbench_medians(doc):
    """run_name -> the 'median' aggregate of a Google Benchmark JSON document."""
    out = {}
    for b in (doc or {}).get("benchmarks", []):
        if b.get("aggregate_name") == "median":
            out[b["run_name"]] = b
    return out


def ns(b, key="cpu_time"):
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
    return b[key] * scale


# ---- rows ------------------------------------------------------------------------------------

class Rows:
    def __init__(self, steps):
        self.steps = steps
        self.rows = []
        self.details = {}

    def add(self, section, key, figure, value, unit, kind, step, better="lower", detail=""):
        self.rows.append({"section": section, "key": key, "figure": figure,
                          "value": value, "unit": unit, "kind": kind, "better": better,
                          "detail": detail, "step": step})

    def failed(self, section, key, figure, step, why):
        self.rows.append({"section": section, "key": key, "figure": figure, "value": None,
                          "unit": "", "kind": "", "better": "lower", "detail": why,
                          "step": step})

    def step_ok(self, name):
        s = self.steps.get(name)
        return s is not None and s["status"] == 0


def codec_rows(r, raw):
    doc = gbench_medians(read_json(os.path.join(raw, "codec.json")))
    if not doc:
        r.failed("codec", "codec.decode_cycle_ns", "Feedback cycle decoded (13 frames)", "codec",
                 "bench_codec produced no results")
    else:
        cycle = doc.get("BM_DecodeFeedbackCycle")
        if cycle:
            r.add("codec", "codec.decode_cycle_ns", "Feedback cycle decoded (13 frames)",
                  round(ns(cycle), 1), "ns", "cpu", "codec",
                  detail=f"wall {ns(cycle, 'real_time'):.1f} ns; target < 1000 ns")
            r.add("codec", "codec.decode_ns_per_frame_cycle", "Decode, per frame of the cycle",
                  round(ns(cycle) / 13, 2), "ns", "cpu", "codec",
                  detail=f"wall {ns(cycle, 'real_time') / 13:.2f} ns")
        per_id = {}
        for name, b in doc.items():
            m = re.match(r"BM_(Decode|Encode)/(\d+)$", name)
            if m:
                per_id.setdefault(int(m.group(2)), {"name": b.get("label", "")})[
                    m.group(1).lower()] = round(ns(b), 2)
        r.details["codec_per_id_ns"] = {f"0x{i:03X}": v for i, v in sorted(per_id.items())}
        for what in ("decode", "encode"):
            values = [(v[what], v["name"]) for v in per_id.values() if what in v]
            if not values:
                continue
            lo, hi = min(values), max(values)
            r.add("codec", f"codec.{what}_ns_per_frame_median_id",
                  f"{what.capitalize()}, per frame (median over {len(values)} IDs)",
                  round(statistics.median(v for v, _ in values), 2), "ns", "cpu", "codec",
                  detail=f"{lo[0]:.1f} ({lo[1]}) .. {hi[0]:.1f} ({hi[1]})")
        for name, label in (("BM_DecodeBadDlc", "bad DLC"), ("BM_DecodeUnknownId", "unknown ID")):
            if name in doc:
                r.details.setdefault("codec_error_paths_ns", {})[label] = round(ns(doc[name]), 1)
    log = read_text(os.path.join(raw, "callgrind.log")) or ""
    m = re.search(r"Collected\s*:\s*([\d,]+)", log)
    cycles = re.search(r"decoded (\d+) cycles x (\d+) frames", log)
    if m and cycles and r.step_ok("callgrind"):
        ir = int(m.group(1).replace(",", ""))
        frames = int(cycles.group(1)) * int(cycles.group(2))
        r.add("codec", "codec.callgrind_ir_per_frame", "Decode, instructions per frame "
              "(callgrind)", round(ir / frames, 2), "Ir", "instr", "callgrind",
              detail=f"{ir:,} Ir / {frames:,} frames, inclusive of decode's callees")
    else:
        r.failed("codec", "codec.callgrind_ir_per_frame", "Decode, instructions per frame "
                 "(callgrind)", "callgrind", "no callgrind total (is valgrind installed?)")


def control_rows(r, raw):
    doc = gbench_medians(read_json(os.path.join(raw, "control.json")))
    names = [
        ("BM_ControllerFeedbackCycleAndTick", "control.controller_cycle_ns",
         "Controller: feedback cycle (13 frames) + command + tick"),
        ("BM_OdometryFeedbackCycle", "control.odometry_cycle_ns",
         "Odometry: one cycle (0x221, 0x271, 0x281, 0x291)"),
        ("BM_SolveKinematics/0", "control.kinematics_ackermann_ns", "Kinematics solve, Ackermann"),
        ("BM_SolveKinematics/1", "control.kinematics_oblique_ns", "Kinematics solve, oblique"),
        ("BM_SolveKinematics/2", "control.kinematics_spin_ns", "Kinematics solve, spin"),
        ("BM_FitBodyTwist", "control.fit_body_twist_ns", "Body twist fitted to 4 wheels"),
    ]
    for run_name, key, figure in names:
        b = doc.get(run_name)
        if b:
            r.add("control", key, figure, round(ns(b), 1), "ns", "cpu", "control",
                  detail=f"wall {ns(b, 'real_time'):.1f} ns")
        else:
            r.failed("control", key, figure, "control", "not in bench_control's output")


VCAN_LINE = re.compile(r"^(\S+) throughput: .*?(\d+) received, (\d+) rx dropped, (\d+) tx dropped, "
                       r"[\d.]+ s -> (\d+) frames/s")
LAT_LINE = re.compile(r"^(\S+) latency .*?(\d+) samples, p50 ([\d.]+) us, p99 ([\d.]+) us, "
                      r"max ([\d.]+) us")


def bus_rows(r, raw):
    doc = gbench_medians(read_json(os.path.join(raw, "bus.json")))
    b = doc.get("BM_LoopbackSendThenReceive")
    if b:
        r.add("bus", "bus.loopback.send_receive_ns", "Loopback: send + receive, one thread",
              round(ns(b), 1), "ns", "cpu", "bus", detail=f"wall {ns(b, 'real_time'):.1f} ns")
    t = next((v for k, v in doc.items() if k.startswith("BM_LoopbackThroughput")), None)
    if t:
        r.add("bus", "bus.loopback.throughput_fps", "Loopback: throughput, reader thread",
              round(t["frames_per_s"]), "frames/s", "wall", "bus", better="higher",
              detail=f"100,000 frames, dropped {t.get('dropped', 0):.0f}; median of 3")
    lat = next((v for k, v in doc.items() if k.startswith("BM_LoopbackLatency")), None)
    if lat:
        for p in ("p50", "p99"):
            r.add("bus", f"bus.loopback.latency_{p}_us", f"Loopback: latency {p}",
                  round(lat[f"{p}_us"], 1), "us", "wall", "bus",
                  detail=f"20,000 samples, max {lat['max_us']:.0f} us; median of 3 runs")
    if not doc:
        r.failed("bus", "bus.loopback.throughput_fps", "Loopback", "bus", "bench_bus failed")

    where = (read_text(os.path.join(raw, "vcan.where")) or "skipped").strip()
    if where == "skipped":
        r.failed("bus", "bus.vcan.throughput_fps", "vcan0", "vcan",
                 "skipped: the kernel has no vcan and --no-vm was given")
        return
    out = read_text(os.path.join(raw, "vcan.out")) or ""
    place = "in the qemu VM" if where == "vm" else "native"
    kind = "vm" if where == "vm" else "wall"

    def key_label(bus):  # bench_bus_vcan names the bus "loopback" or by its interface
        if bus == "loopback":
            return f"bus.loopback_{where}", f"Loopback ({place})"
        return f"bus.vcan_{where}", f"{bus} ({place})"
    found = False
    for line in out.splitlines():
        m = VCAN_LINE.match(line)
        if m:
            key, label = key_label(m.group(1))
            r.add("bus", f"{key}.throughput_fps", f"{label}: throughput", int(m.group(5)),
                  "frames/s", kind, "vcan", better="higher",
                  detail=f"{m.group(2)} received, {m.group(3)} rx + {m.group(4)} tx dropped")
            found = found or m.group(1) != "loopback"
        m = LAT_LINE.match(line)
        if m:
            key, label = key_label(m.group(1))
            for p, g in (("p50", 3), ("p99", 4)):
                r.add("bus", f"{key}.latency_{p}_us", f"{label}: latency {p}",
                      float(m.group(g)), "us", kind, "vcan",
                      detail=f"{m.group(2)} samples, max {float(m.group(5)):.0f} us")
    if not found:
        r.failed("bus", f"bus.vcan_{where}.throughput_fps", "vcan0", "vcan",
                 "no figures: see build/perf/raw/vcan.log")


def node_rows(r, raw):
    doc = read_json(os.path.join(raw, "node.json"))
    if not doc:
        if "node" in r.steps:
            r.failed("node", "node.cpu_percent", "Node CPU", "node",
                     "measure_performance.py produced no figures")
        return
    load, lat = doc.get("load", {}), doc.get("latency_cmd_vel_to_0x111", {})
    fps = load.get("feedback_frames_per_s")
    threads = load.get("threads_cpu_percent", {})
    top = ", ".join(f"{k.split(' (')[0]} {v}" for k, v in list(threads.items())[:3])
    r.add("node", "node.cpu_percent", "Node CPU (driver + in-process chassis)",
          load.get("node_cpu_percent_of_one_core"), "% of a core", "cpu", "node",
          detail=f"feedback {fps} frames/s; busiest threads %: {top}")
    if "driver_cpu_percent_of_one_core" in load:
        r.add("node", "node.driver_cpu_percent", "Node CPU without the chassis thread",
              load["driver_cpu_percent_of_one_core"], "% of a core", "cpu", "node",
              detail="target <= 1 %")
    if load.get("rss_kib_median") is not None:
        r.add("node", "node.rss_mib", "Node RSS", round(load["rss_kib_median"] / 1024, 1),
              "MiB", "mem", "node", detail=f"max {load.get('rss_kib_max', 0) / 1024:.1f} MiB")
    for p in ("p50", "p99"):
        if lat.get(f"{p}_ms") is not None:
            r.add("node", f"node.latency_{p}_ms", f"cmd_vel -> 0x111 latency {p}",
                  lat[f"{p}_ms"], "ms", "wall", "node",
                  detail=f"{lat.get('samples')} samples, max {lat.get('max_ms')} ms"
                  + ("; target <= 2 ms" if p == "p99" else ""))


ODOM_LINE = re.compile(r"^\[odometry\] bus=(\S+) mode=(\S+) distance=([\d.]+) m turns=([\d.]+) "
                       r"position_error=([\d.]+) m \(([\d.]+) % of distance\) yaw_error=([\d.]+) "
                       r"deg \(([\d.]+) deg/turn\)")


def odometry_rows(r, raw):
    out = read_text(os.path.join(raw, "odometry.out")) or ""
    seen = 0
    for line in out.splitlines():
        m = ODOM_LINE.match(line)
        if not m:
            continue
        seen += 1
        bus, mode = m.group(1), m.group(2)
        distance, turns = float(m.group(3)), float(m.group(4))
        pos_m = float(m.group(5))
        # From the metres (printed to 0.1 mm) rather than the printed percentage (3 decimals).
        pos_pct = float(f"{100.0 * pos_m / distance:.3g}") if distance > 0 else 0.0
        yaw_deg, yaw_per_turn = float(m.group(7)), float(m.group(8))
        r.details.setdefault("odometry", {})[mode] = {
            "bus": bus, "distance_m": distance, "turns": turns, "position_error_m": pos_m,
            "position_error_pct": pos_pct, "yaw_error_deg": yaw_deg,
            "yaw_error_deg_per_turn": yaw_per_turn}
        where = f"{distance:.2f} m, {turns:.2f} turns"
        if distance > 0.5:
            r.add("odometry", f"odometry.{mode}.position_error_pct",
                  f"{mode.capitalize()}: position error", pos_pct, "% of distance", "sim",
                  "odometry", detail=f"{pos_m * 1000:.1f} mm over {where}")
        if turns > 0.1:
            r.add("odometry", f"odometry.{mode}.yaw_error_deg_per_turn",
                  f"{mode.capitalize()}: heading error", yaw_per_turn, "deg/turn", "sim",
                  "odometry", detail=f"{yaw_deg:.4f} deg over {where}")
        if distance <= 0.5 and turns <= 0.1:
            r.add("odometry", f"odometry.{mode}.position_error_m",
                  f"{mode.capitalize()}: position error", pos_m, "m", "sim", "odometry",
                  detail=where)
    if not seen:
        r.failed("odometry", "odometry.ackermann.position_error_pct", "Odometry", "odometry",
                 "no [odometry] lines from test_e2e_loopback")
    elif not r.step_ok("odometry"):
        r.details["odometry_note"] = "test_e2e_loopback failed: see build/perf/raw/odometry.log"


def launch_rows(r, raw):
    doc = read_json(os.path.join(raw, "launch.json"))
    if not doc:
        if "launch" in r.steps:
            r.failed("launch", "launch.node_s", "Launch to command mode", "launch",
                     "perf_launch_time.py produced no figures")
        return
    for way, key, figure in (("node", "launch.node_s", "ranger_base_node _port_name:=sim"),
                             ("roslaunch", "launch.roslaunch_s",
                              "roslaunch ranger_minimal.launch sim:=true")):
        s = doc.get(way, {})
        if s.get("median_s") is None:
            r.failed("launch", key, figure, "launch", f"{s.get('reached', 0)} of "
                     f"{s.get('runs', '?')} runs reached command mode")
            continue
        r.add("launch", key, figure, s["median_s"], "s", "wall", "launch",
              detail=f"median of {s['reached']}/{s['runs']} runs, {s['min_s']} .. {s['max_s']} s")


def fleet_rows(r, raw):
    doc = read_json(os.path.join(raw, "fleet.json"))
    if not doc:
        if "fleet" in r.steps:
            r.failed("fleet", "fleet.node_cpu_percent", "Fleet", "fleet",
                     "perf_fleet.py produced no figures")
        return
    f = doc["fleet"]
    n = f["robots"]
    r.details["fleet_processes"] = f.get("processes", [])

    def span(s, fmt="{:.1f}"):
        return f"min {fmt.format(s['min'])}, max {fmt.format(s['max'])}" if s else ""
    r.add("fleet", "fleet.robots_in_command_mode", "Robots that reached CAN command mode",
          f["robots_in_command_mode"], f"of {n}", "count", "fleet", better="higher",
          detail=f"all of them within {f['all_in_command_mode_after_s']} s of the launch")
    if f.get("per_robot_cpu_percent"):
        r.add("fleet", "fleet.per_robot_cpu_percent", "CPU per robot (node + "
              "robot_state_publisher)", f["per_robot_cpu_percent"]["median"], "% of a core",
              "cpu", "fleet", detail=span(f["per_robot_cpu_percent"]))
    if f.get("node_cpu_percent"):
        r.add("fleet", "fleet.node_cpu_percent", "CPU per ranger_base_node",
              f["node_cpu_percent"]["median"], "% of a core", "cpu", "fleet",
              detail=span(f["node_cpu_percent"]))
    r.add("fleet", "fleet.graph_cpu_percent", f"CPU of the whole graph ({n} robots + "
          "aggregator)", f["graph_cpu_percent_total"], "% of a core", "cpu", "fleet",
          detail=f"the machine has {os.cpu_count() * 100} %")
    if f.get("node_rss_kib"):
        rsp = (f.get("robot_state_publisher_rss_kib") or {}).get("median", 0)
        r.add("fleet", "fleet.node_rss_mib", "RSS per ranger_base_node",
              round(f["node_rss_kib"]["median"] / 1024, 1), "MiB", "mem", "fleet",
              detail=f"with robot_state_publisher: {(f['node_rss_kib']['median'] + rsp) / 1024:.1f}"
              " MiB per robot")
    if f.get("odom_hz"):
        r.add("fleet", "fleet.odom_hz_slowest", "Odometry rate of the slowest robot",
              f["odom_hz"]["min"], "Hz", "wall", "fleet", better="higher",
              detail=f"configured 50 Hz; median {f['odom_hz']['median']} Hz")


# ---- comparison and output -------------------------------------------------------------------

def compare(rows, previous, machine):
    prev_rows = {row["key"]: row for row in (previous or {}).get("rows", [])}
    prev_run = (previous or {}).get("run", {})
    same_machine = machine_line(prev_run.get("machine", machine)) == machine_line(machine)
    for row in rows:
        p = prev_rows.get(row["key"])
        row["previous"] = None
        row["change_pct"] = None
        row["verdict"] = ""
        if not p or p.get("value") is None:
            continue
        row["previous"] = {"value": p["value"], "date": p.get("date", prev_run.get("date")),
                           "same_machine": same_machine}
        if row["value"] is None:
            row["verdict"] = "failed"
            continue
        if p["value"] == 0:
            row["change_pct"] = 0.0 if row["value"] == 0 else None
        else:
            row["change_pct"] = round(100.0 * (row["value"] - p["value"]) / abs(p["value"]), 1)
        if row["change_pct"] is None:
            continue
        noise = KINDS.get(row["kind"], (0.0, ""))[0]
        change = row["change_pct"] if row["better"] == "lower" else -row["change_pct"]
        worse, better = change > noise, change < -noise
        row["verdict"] = "worse" if worse else "better" if better else ""


def fmt(v):
    if v is None:
        return "—"
    if isinstance(v, int):
        return f"{v:,}"
    a = abs(v)
    if a >= 1000:
        return f"{v:,.0f}"
    if a >= 100:
        return f"{v:.1f}"
    if a >= 1 or a == 0:
        return f"{v:.2f}"
    return f"{v:.4f}".rstrip("0")


def markdown(result):
    run = result["run"]
    m = run["machine"]
    out = []
    w = out.append
    w("# Performance\n")
    w("Generated by `scripts/perf.sh` (do not edit by hand: run it again). Every figure is "
      "compared with the previous run's, read from `docs/perf/results.json` before it was "
      "overwritten; the JSON holds the same rows, each with its machine, date, command and load "
      "average.\n")
    w("## This run\n")
    w("| | |\n|---|---|")
    w(f"| Date | {run['date']} (measuring took {run['duration_s']:.0f} s, builds excluded) |")
    w(f"| Command | `{run['command']}` |")
    w(f"| Machine | {machine_line(m)}, {m['memory_gib']} GiB RAM |")
    w(f"| Compiler | {m['compiler']} |")
    w(f"| Builds | library benchmarks: {m['library_build']}; ROS node: {m['node_build']} |")
    w(f"| Source | {m['git']} |")
    w(f"| Load average (1/5/15 min) | {' / '.join(fmt(x) for x in run['load_at_start'])} at the "
      f"start, {' / '.join(fmt(x) for x in run['load_at_end'])} at the end |")
    prev = result.get("previous_run")
    if prev:
        same = "same machine" if machine_line(prev["machine"]) == machine_line(m) else \
            f"**another machine**: {machine_line(prev['machine'])}"
        w(f"| Previous run | {prev['date']}, {same}, load {fmt(prev['load_at_start'][0])} |")
    else:
        w("| Previous run | none (first run: no comparison) |")
    if prev:
        worse = [r["figure"] for r in result["rows"] if r.get("verdict") == "worse"]
        better = [r["figure"] for r in result["rows"] if r.get("verdict") == "better"]
        failed = [r["figure"] for r in result["rows"] if r["value"] is None]
        w(f"| Beyond the noise band | {len(worse)} worse" + (f" ({'; '.join(worse)})" if worse
                                                             else "")
          + f", {len(better)} better" + (f" ({'; '.join(better)})" if better else "")
          + (f"; **failed**: {'; '.join(failed)}" if failed else "") + " |")
    w("")
    w("**How far to trust a figure.** The machine is shared and was loaded while these figures "
      "were taken (see the load average above and per section; the load counts runnable tasks, "
      f"{m['cores']} cores). **Instruction counts (instr) and CPU time (cpu) are the "
      "trustworthy columns**: they count work done, not time spent waiting for a CPU. Wall-clock "
      "figures (wall: throughput, latency, launch time) include that wait and move with the load; "
      "compare them only between runs at similar load. Simulated-clock figures (sim) are "
      "deterministic. A change beyond the noise band of its kind is marked **worse** or better:\n")
    for kind, (noise, text) in KINDS.items():
        w(f"- `{kind}` (noise band {noise:g} %): {text}")
    w("")
    commands = []
    for section, title, text in SECTIONS:
        rows = [r for r in result["rows"] if r["section"] == section]
        if not rows:
            continue
        w(f"## {title}\n")
        w(text + "\n")
        steps = []
        for r in rows:
            if r["step"] not in steps:
                steps.append(r["step"])
        loads = []
        for s in steps:
            info = result["steps"].get(s)
            if info:
                loads.append(f"{s} at load {fmt(info['load_before'][0])}")
        if loads:
            w(f"Measured {run['date']} on {machine_line(m)}; " + ", ".join(loads) + ".\n")
        w("| Figure | Value | Kind | Previous | Change | Detail | Cmd |")
        w("|---|---:|---|---:|---:|---|---|")
        for r in rows:
            info = result["steps"].get(r["step"])
            if info and info["command"] not in commands:
                commands.append(info["command"])
            number = commands.index(info["command"]) + 1 if info else 0
            ref = f"[C{number}](#c{number})" if info else ""
            value = f"{fmt(r['value'])} {r['unit']}" if r["value"] is not None else "**failed**"
            p = r.get("previous")
            prev = "—" if not p else fmt(p["value"]) + (
                "" if p["same_machine"] else " (other machine)")
            if r.get("change_pct") is None:
                change = "—"
            else:
                change = f"{r['change_pct']:+.1f} %"
                if r["verdict"] == "worse":
                    change = f"**{change} worse**"
                elif r["verdict"] == "better":
                    change += " better"
            w(f"| {r['figure']} | {value} | {r['kind']} | {prev} | {change} | {r['detail']} | "
              f"{ref} |")
        w("")
        if section == "codec" and result["details"].get("codec_per_id_ns"):
            w("<details><summary>Per frame ID (cpu ns, median of 5)</summary>\n")
            w("| ID | Frame | Decode ns | Encode ns |\n|---|---|---:|---:|")
            for i, v in result["details"]["codec_per_id_ns"].items():
                w(f"| {i} | {v.get('name', '')} | {fmt(v.get('decode'))} | "
                  f"{fmt(v.get('encode'))} |")
            err = result["details"].get("codec_error_paths_ns", {})
            if err:
                w("\nError paths (they build a message string): " + ", ".join(
                    f"{k} {fmt(v)} ns" for k, v in err.items()) + ".")
            w("\n</details>\n")
    w("## Commands\n")
    w("Run from the repository root by `scripts/perf.sh` (ROS steps in a shell that sourced "
      "`install/setup.bash`), in this order:\n")
    for i, c in enumerate(commands, 1):
        step = next((s for s in result["steps"].values() if s["command"] == c), None)
        status = "" if not step or step["status"] == 0 else f" — **exit status {step['status']}**"
        secs = f" ({step['seconds']:.0f} s)" if step else ""
        w(f"- <a id=\"c{i}\"></a>**C{i}**{secs}{status}: `{c}`")
    w("")
    notes = []
    where = result["details"].get("vcan_where")
    if where == "vm":
        notes.append("This kernel has no vcan: the vcan figures come from the throwaway qemu VM "
                     "(tests/vm/run_in_vm.sh, TCG emulation, no KVM), so they measure the "
                     "emulator as much as SocketCAN; the loopback bus measured in the same VM "
                     "gives the scale. On a machine with vcan the script measures it natively.")
    notes.append("Node CPU (section 4) includes the in-process virtual chassis thread, which a "
                 "real robot does not run; on can0 the driver's own share is smaller.")
    notes.append("Odometry errors come from the lock-step in-process rig; the same scenarios "
                 "over vcan (tests/e2e/test_e2e_vcan, real clock) print their own [odometry] "
                 "lines in the vcan test run.")
    w("## Notes\n")
    for n in notes:
        w(f"- {n}")
    w("")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--raw", required=True)
    ap.add_argument("--build-dir", required=True)
    ap.add_argument("--results", required=True)
    ap.add_argument("--previous", help="the run to compare with (default: --results as it is "
                    "before being overwritten); for re-rendering a raw directory")
    ap.add_argument("--markdown", required=True)
    ap.add_argument("--command", default="scripts/perf.sh")
    ap.add_argument("--repo", default=".")
    args = ap.parse_args()

    steps = {}
    for line in (read_text(os.path.join(args.raw, "steps.jsonl")) or "").splitlines():
        if line.strip():
            s = json.loads(line)
            steps[s["step"]] = s
    previous = read_json(args.previous or args.results)  # before it is overwritten
    machine = machine_info(args.build_dir, args.repo)
    started = min((s["started"] for s in steps.values()), default=0)
    ended = max((s["started"] + s["seconds"] for s in steps.values()), default=0)
    first = min(steps.values(), key=lambda s: s["started"]) if steps else None
    last = max(steps.values(), key=lambda s: s["started"]) if steps else None
    date = datetime.datetime.fromtimestamp(started or 0, datetime.timezone.utc)

    r = Rows(steps)
    codec_rows(r, args.raw)
    control_rows(r, args.raw)
    bus_rows(r, args.raw)
    node_rows(r, args.raw)
    odometry_rows(r, args.raw)
    launch_rows(r, args.raw)
    fleet_rows(r, args.raw)
    r.details["vcan_where"] = (read_text(os.path.join(args.raw, "vcan.where")) or "").strip()

    run = {
        "date": date.strftime("%Y-%m-%d %H:%M UTC"),
        "command": args.command,
        "duration_s": round(ended - started, 1),
        "machine": machine,
        "load_at_start": first["load_before"] if first else [],
        "load_at_end": last["load_after"] if last else [],
    }
    for row in r.rows:  # every row states its machine, date, command and load
        s = steps.get(row["step"], {})
        row["machine"] = machine_line(machine)
        row["date"] = run["date"]
        row["command"] = s.get("command", "")
        row["load"] = s.get("load_before", [])
    compare(r.rows, previous, machine)
    result = {"schema": SCHEMA, "run": run, "rows": r.rows, "steps": steps,
              "details": r.details}
    if previous and previous.get("run"):
        result["previous_run"] = {k: previous["run"].get(k) for k in
                                  ("date", "command", "machine", "load_at_start")}

    os.makedirs(os.path.dirname(os.path.abspath(args.results)), exist_ok=True)
    with open(args.results + ".tmp", "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")
    os.replace(args.results + ".tmp", args.results)
    with open(args.markdown + ".tmp", "w") as f:
        f.write(markdown(result))
    os.replace(args.markdown + ".tmp", args.markdown)

    width = max(len(row["figure"]) for row in r.rows) if r.rows else 10
    for row in r.rows:
        change = "" if row.get("change_pct") is None else f"  ({row['change_pct']:+.1f} % " \
            f"{row['verdict'] or 'within noise'})"
        print(f"{row['figure']:<{width}}  {fmt(row['value']):>10} {row['unit']}{change}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
