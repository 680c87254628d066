#!/usr/bin/env bash
# The RANGER driver demo, from a fresh checkout: installs what is missing (scripts/setup.sh),
# builds (scripts/build.sh), starts the driver against its in-process virtual chassis, drives a
# scripted route through all three motion modes (Ackermann arcs, crab, spin), then writes a plot
# of the driver's odometry against the virtual chassis's ground truth and prints a summary.
#
# Usage: scripts/demo.sh [--rviz | --headless] [--no-setup] [--no-build] [--output DIR]
#   --rviz       open rviz while driving (default when $DISPLAY is set)
#   --headless   never open rviz (default without $DISPLAY)
#   --no-setup   skip scripts/setup.sh;  --no-build  skip scripts/build.sh
#   --output     where the plot, summary and logs go (default demo_output/)
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

rviz=auto setup=1 build=1 out="$repo/demo_output"
while [ $# -gt 0 ]; do
  case "$1" in
    --rviz) rviz=1 ;;
    --headless) rviz=0 ;;
    --no-setup) setup=0 ;;
    --no-build) build=0 ;;
    --output) out=${2:?--output needs a directory}; shift ;;
    -h | --help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done
[ "$rviz" = auto ] && { [ -n "${DISPLAY:-}" ] && rviz=1 || rviz=0; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

step() { printf '\n== %s\n' "$*"; }
start=$SECONDS

if [ "$setup" = 1 ] && [ -x scripts/setup.sh ]; then
  step "setup: system packages (scripts/setup.sh ros)"
  scripts/setup.sh ros
fi
if [ "$build" = 1 ] && [ -x scripts/build.sh ]; then
  step "build: ROS packages (scripts/build.sh ros)"
  scripts/build.sh ros
fi
install_dir=${RANGER_INSTALL:-$repo/install}
setup_file=$install_dir/setup.bash
[ -f "$setup_file" ] || setup_file=$install_dir/setup.sh  # without colcon's bash extension
if [ ! -f "$setup_file" ]; then
  echo "demo.sh: no setup.bash or setup.sh in $install_dir: build first (scripts/build.sh)" >&2
  exit 1
fi

# The ROS tools need Debian's Python (a pyenv python3 on PATH lacks the ROS modules), a writable
# ROS_HOME, and a master of our own so that the demo never disturbs a running roscore.
export PATH=/usr/bin:$PATH
set +u
# shellcheck disable=SC1090
source "$setup_file"
set -u
export ROS_HOME="$out/ros_home" ROS_HOSTNAME=${ROS_HOSTNAME:-localhost}
unset ROS_IP
port=$(/usr/bin/python3 -c \
  'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
step "driver: roslaunch ranger_bringup ranger_sim.launch (virtual chassis in-process)"
roslaunch -p "$port" ranger_bringup ranger_sim.launch log_output:=log >"$out/roslaunch.log" 2>&1 &
launch_pid=$!
rviz_pid=
node_pids() {  # the processes of the nodes registered at our master, and the master's own
  /usr/bin/python3 - <<'PY' 2>/dev/null || true
import xmlrpc.client
import rosgraph
import rosnode
master = rosgraph.Master("/demo_sh")
print(master.getPid())
for name in rosnode.get_node_names():
    try:
        print(xmlrpc.client.ServerProxy(master.lookupNode(name)).getPid("/demo_sh")[2])
    except Exception:
        pass
PY
}
stop_launch() {  # SIGINT as Ctrl-C would: the driver stops the chassis on its way out
  local pid=$1
  kill -0 "$pid" 2>/dev/null || return 0
  kill -INT "$pid" 2>/dev/null || true
  for _ in $(seq 75); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}
cleanup() {
  # roslaunch starts each node in a session of its own and, stopped while still starting,
  # may leave some behind: note them first, and end whatever outlives the launches.
  local nodes p
  nodes=$(node_pids)
  if [ -n "$rviz_pid" ]; then stop_launch "$rviz_pid"; fi
  stop_launch "$launch_pid"
  for p in $nodes; do
    if kill -0 "$p" 2>/dev/null; then kill -INT "$p" 2>/dev/null || true; fi
  done
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# The ROS master comes up with roslaunch; the route's node must not start before it.
for _ in $(seq 100); do
  rosparam get /run_id >/dev/null 2>&1 && break
  kill -0 "$launch_pid" 2>/dev/null || { cat "$out/roslaunch.log" >&2; exit 1; }
  sleep 0.2
done

if [ "$rviz" = 1 ]; then
  step "rviz: roslaunch ranger_bringup display.launch"
  roslaunch ranger_bringup display.launch required:=true >"$out/rviz.log" 2>&1 &
  rviz_pid=$!
fi

step "route: Ackermann arcs, crab, spin (ranger_bringup/scripts/demo_route)"
demo_route=$(catkin_find --first-only --libexec ranger_bringup demo_route) || {
  echo "demo.sh: ranger_bringup's demo_route is not installed in $install_dir" >&2
  exit 1
}
status=0
"$demo_route" --output-dir "$out" || status=$?
if [ "$status" -ne 0 ]; then
  echo "demo.sh: the route did not complete; the driver's logs: $out/roslaunch.log," \
    "$ROS_HOME/log" >&2
  tail -n 20 "$out/roslaunch.log" >&2 || true
  exit "$status"
fi
if [ -n "$rviz_pid" ]; then
  echo "rviz is open: close it (or press Ctrl-C) to finish."
  wait "$rviz_pid" || true
fi
step "done in $((SECONDS - start)) s: plot $out/odometry_vs_ground_truth.png," \
  "summary $out/summary.txt"
