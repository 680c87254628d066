#!/usr/bin/python3
"""Time from launch to CAN command mode, against the in-process virtual chassis (port_name sim).

Each run starts the node on a private rosmaster and waits for the first `system_state` message
with link_up and control_mode == CAN; the figure is that message's header stamp (the node's own
clock reading when it published it) minus the wall-clock time just before the process was
started. Two ways in:
  node       ranger_base_node started directly (_port_name:=sim)
  roslaunch  roslaunch ranger_bringup ranger_minimal.launch sim:=true (what a user types: adds
             roslaunch's own start-up, URDF generation and robot_state_publisher)
system_state is asked for at 100 Hz (state_publish_rate, its maximum; default 10 Hz) so the
figure resolves 10 ms. A benchmark: prints figures (and --json), asserts nothing.

  scripts/perf_launch_time.py [--runs 5] [--roslaunch-runs 3] [--json FILE]

Needs a built and sourced workspace (source install/setup.bash).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "ranger_base",
                                "scripts"))
import measure_performance as mp  # noqa: E402  (rosmaster, node start/stop, /proc helpers)

TIMEOUT_S = 60.0


def time_to_command_mode(rospy, ns, start_process):
    """Seconds from just before `start_process()` to the stamp of the first CAN-mode state."""
    from ranger_msgs.msg import SystemState
    reached = threading.Event()
    stamp = {}

    def on_state(msg):
        in_can = msg.link_up and msg.control_mode == SystemState.CONTROL_MODE_CAN
        if in_can and not reached.is_set():
            stamp["t"] = msg.header.stamp.to_sec()
            reached.set()
    sub = rospy.Subscriber(f"/{ns}/system_state", SystemState, on_state, queue_size=100,
                           tcp_nodelay=True)
    t0 = time.time()
    process = start_process()
    try:
        if not reached.wait(TIMEOUT_S):
            return None, process
        return stamp["t"] - t0, process
    finally:
        sub.unregister()


def start_node(ns):
    return mp.start_node("ranger_base_node", f"__ns:=/{ns}", "_state_publish_rate:=100")


def start_roslaunch(ns):
    # state_publish_rate is set through the parameter server before the launch reads it: the
    # launch file has no argument for it, and a private parameter set in advance survives.
    subprocess.run(["rosparam", "set", f"/{ns}/ranger_base_node/state_publish_rate", "100"],
                   check=True, stdout=subprocess.DEVNULL)
    return subprocess.Popen(["roslaunch", "ranger_bringup", "ranger_minimal.launch", "sim:=true",
                             f"namespace:={ns}", "diagnostics_aggregator:=false",
                             "log_output:=log"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def series(rospy, label, runs, starter):
    values = []
    for k in range(runs):
        ns = f"perf_{label}_{k}"
        seconds, process = time_to_command_mode(rospy, ns, lambda: starter(ns))
        mp.stop_node(process)
        if seconds is None:
            print(f"{label} run {k}: no CAN command mode within {TIMEOUT_S:.0f} s", file=sys.stderr)
        else:
            values.append(seconds)
            print(f"{label} run {k}: {seconds:.3f} s", file=sys.stderr)
    return {
        "runs": runs,
        "reached": len(values),
        "seconds": [round(v, 3) for v in values],
        "median_s": round(statistics.median(values), 3) if values else None,
        "min_s": round(min(values), 3) if values else None,
        "max_s": round(max(values), 3) if values else None,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="node started directly")
    parser.add_argument("--roslaunch-runs", type=int, default=3, help="through ranger_minimal")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()

    env = mp.Environment()
    try:
        import rospy
        mp.wait_for(lambda: subprocess.run(["rosnode", "list"],
                                           capture_output=True).returncode == 0)
        rospy.init_node("ranger_perf_launch", anonymous=True, disable_signals=True)
        figures = {"machine": mp.machine(),
                   "command": " ".join([os.path.relpath(sys.argv[0])] + sys.argv[1:]),
                   "node": series(rospy, "node", args.runs, start_node),
                   "roslaunch": series(rospy, "roslaunch", args.roslaunch_runs, start_roslaunch)}
    finally:
        env.close()

    print(json.dumps(figures, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)
    return 0 if figures["node"]["reached"] == args.runs else 1


if __name__ == "__main__":
    sys.exit(main())
