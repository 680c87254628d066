#!/usr/bin/env bash
# Measures the performance figures and rewrites docs/PERFORMANCE.md with them (machine, date,
# commit, and for every row the command that produced it). Previous figures: git log -p
# docs/PERFORMANCE.md.
#
#   scripts/perf.sh [--no-build] [--no-ros]
#
#   --no-build  use build/perf and install/ as they are
#   --no-ros    skip the node measurement (its rows say so)
#
# Runs bench_codec (+ callgrind instructions per decoded frame), bench_control, bench_bus
# (in-process loopback), the e2e odometry figures (lock-step, simulated clock) and
# ranger_base/scripts/measure_performance.py (and the ROS 2 node's, ros2/ranger_base, on Jazzy
# and Kilted, where scripts/test_ros2.sh has built their workspaces). Builds the benchmarks in build/perf, a Release
# build of its own (figures never depend on how build/lib is configured), and the node with
# scripts/build.sh ros. About 5 minutes of measuring; RANGER_JOBS sets the build jobs (2).
# RANGER_PERF_NOTE: a line for the header (e.g. what else ran on the machine meanwhile).
set -euo pipefail
cd "$(dirname "$0")/.."

build=1 ros=1
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --no-ros) ros=0 ;;
    -h | --help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "perf.sh: unknown option '$arg' (see --help)" >&2; exit 2 ;;
  esac
done

out=build/perf
raw=$out/raw
jobs=${RANGER_JOBS:-2}
if [ "$build" = 1 ]; then
  mkdir -p build && touch build/COLCON_IGNORE
  [ -f $out/CMakeCache.txt ] || cmake -S . -B $out $(command -v ninja >/dev/null && echo -G Ninja) \
    -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build $out -j "$jobs" --target bench_codec bench_control bench_bus test_e2e_loopback
  [ "$ros" = 0 ] || RANGER_JOBS=$jobs scripts/build.sh ros
fi
rm -rf $raw && mkdir -p $raw
cut -d' ' -f1-3 /proc/loadavg >$raw/loadavg
failures=0

# run NAME COMMAND: the command (a shell string) in $raw/NAME.cmd, its stdout in $raw/NAME.out,
# its stderr in $raw/NAME.log.
run() {
  echo "== perf: $1: $2"
  echo "$2" >"$raw/$1.cmd"
  bash -c "$2" >"$raw/$1.out" 2>"$raw/$1.log" ||
    { failures=$((failures + 1)); echo "   FAILED, see $raw/$1.log" >&2; }
}

gbench="--benchmark_report_aggregates_only=true --benchmark_format=json"
lib=$out/libranger_can
run codec "$lib/bench_codec --benchmark_min_time=0.03 --benchmark_repetitions=5 $gbench"
run callgrind "valgrind --tool=callgrind --callgrind-out-file=/dev/null \
'--toggle-collect=ranger::decode(ranger::CanFrame const&)' $lib/bench_codec \
--callgrind-cycles=100000 2>&1"
run control "$lib/bench_control --benchmark_min_time=0.05 --benchmark_repetitions=5 $gbench"
run bus "$lib/bench_bus --benchmark_repetitions=3 $gbench"
run odometry "$out/tests/e2e/test_e2e_loopback --gtest_filter='*OdometryMatchesGroundTruth*'"
if [ "$ros" = 1 ]; then
  run node "export PATH=/usr/bin:\$PATH; source install/setup.bash; /usr/bin/python3 \
ranger_base/scripts/measure_performance.py --duration 20 --samples 400 --json $raw/node.json"
  # The ROS 2 node in the same run, on each distribution whose workspace scripts/test_ros2.sh
  # built (RANGER_ROS2_DISTRO: those named; default jazzy and kilted), each with a domain id of
  # its own (RANGER_PERF_ROS2_DOMAIN_BASE, default 88: Jazzy 88, Kilted 89).
  domain=${RANGER_PERF_ROS2_DOMAIN_BASE:-88}
  for distro in ${RANGER_ROS2_DISTRO:-jazzy kilted}; do
    if [ -f "build/ros2_ws_$distro/install/setup.bash" ]; then
      run "node_ros2_$distro" "RANGER_ROS2_DISTRO=$distro source scripts/ros2_env.sh $domain; \
python -m ranger_base.measure_performance --duration 20 --samples 400 \
--json $raw/node_ros2_$distro.json"
    fi
    domain=$((domain + 1))
  done
fi

{
  echo "# Performance"
  echo
  echo "Written by \`scripts/perf.sh\`; earlier figures: \`git log -p docs/PERFORMANCE.md\`. CPU" \
    "time and instructions count work done; wall-clock figures move with the machine's load."
  echo
  echo "| | |"
  echo "|---|---|"
  echo "| Date | $(date -u '+%Y-%m-%d %H:%M UTC') |"
  echo "| Command | \`scripts/perf.sh${*:+ $*}\` |"
  echo "| Machine | $(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -1), $(nproc) cores," \
    "Linux $(uname -r) |"
  echo "| Commit | $(git rev-parse --short HEAD)$(git status --porcelain | grep -q . &&
    echo ' + uncommitted changes') |"
  echo "| Load average (1, 5, 15 min) | $(cat $raw/loadavg) at the start," \
    "$(cut -d' ' -f1-3 /proc/loadavg) at the end |"
  echo "| Builds | benchmarks: $out (Release); node: install/ (\`scripts/build.sh ros\`) |"
  [ -z "${RANGER_PERF_NOTE:-}" ] || echo "| Note | $RANGER_PERF_NOTE |"
  /usr/bin/python3 scripts/perf_table.py $raw
} >$raw/PERFORMANCE.md
mv $raw/PERFORMANCE.md docs/PERFORMANCE.md
echo "== perf: wrote docs/PERFORMANCE.md"
[ "$failures" = 0 ] || { echo "perf.sh: $failures step(s) failed: logs in $raw/" >&2; exit 1; }
