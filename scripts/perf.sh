#!/usr/bin/env bash
# The performance table: builds what it needs, measures every figure, and writes
# docs/PERFORMANCE.md (the project's one performance document) and docs/perf/results.json, each
# figure compared with the previous run's (read from docs/perf/results.json before it is
# overwritten) so that regressions show.
#
#   scripts/perf.sh [--no-build] [--no-vm] [--no-ros]
#
#   --no-build  use the existing build/perf and install/ trees as they are
#   --no-vm     skip the vcan figures where they would need the qemu VM (kernel without vcan)
#   --no-ros    skip the ROS figures (node, launch time, fleet)
#
# What it runs (each step's exact command, start/end load average and status are recorded in
# build/perf/raw/steps.jsonl and end up in the document):
#   1. codec    libranger_can/bench/bench_codec (Google Benchmark, median of 5 repetitions) and
#               callgrind instructions per decoded frame (bench_codec --callgrind-cycles)
#   2. control  bench_control: controller cycle, odometry cycle, kinematics
#   3. bus      bench_bus (in-process loopback); tests/bus/bench_bus_vcan on vcan0, natively if
#               the kernel has vcan, else inside the throwaway VM (tests/vm/run_in_vm.sh) together
#               with the same benchmark on the loopback bus in that VM, for scale
#   4. node     ranger_base/scripts/measure_performance.py: CPU, RSS, cmd_vel -> 0x111 latency
#   5. odometry tests/e2e/test_e2e_loopback's [odometry] lines (lock-step, simulated clock)
#   6. launch   scripts/perf_launch_time.py: process start -> CAN command mode
#   7. fleet    scripts/perf_fleet.py: 10 namespaced virtual RANGERs in one ROS graph
#
# Builds: the library benchmarks in build/perf, a Release build of its own (-O3 -DNDEBUG, the
# build type pinned here so the figures never depend on how someone configured build/lib, e.g.
# Debug or a sanitizer); the ROS node with scripts/build.sh ros (install/, RelWithDebInfo: the
# node as users build it). On a 2-core machine the measurements take 3-5 minutes; builds come
# on top (a few minutes each when sources changed, seconds when not).
# Environment: RANGER_JOBS (build jobs, default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD

build=1 vm=1 ros=1
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --no-vm) vm=0 ;;
    --no-ros) ros=0 ;;
    -h | --help) sed -n '2,30p' "$0"; exit 0 ;;
    *) echo "perf.sh: unknown option '$arg' (see --help)" >&2; exit 2 ;;
  esac
done

perf_dir=build/perf
raw=$perf_dir/raw
jobs=${RANGER_JOBS:-2}
benches=(bench_codec bench_control bench_bus bench_bus_vcan test_e2e_loopback)

# ---- build ---------------------------------------------------------------------------------
if [ "$build" = 1 ]; then
  echo "== perf: build $perf_dir (Release): ${benches[*]}"
  mkdir -p build && touch build/COLCON_IGNORE
  generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  [ -f $perf_dir/CMakeCache.txt ] ||
    cmake -S . -B $perf_dir "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build $perf_dir -j "$jobs" --target "${benches[@]}"
  if [ "$ros" = 1 ]; then
    echo "== perf: build the ROS workspace (scripts/build.sh ros)"
    RANGER_JOBS=$jobs scripts/build.sh ros
  fi
fi
bin_codec=$perf_dir/libranger_can/bench_codec
bin_control=$perf_dir/libranger_can/bench_control
bin_bus=$perf_dir/libranger_can/bench_bus
bin_vcan=$perf_dir/tests/bus/bench_bus_vcan
bin_e2e=$perf_dir/tests/e2e/test_e2e_loopback
for b in $bin_codec $bin_control $bin_bus $bin_vcan $bin_e2e; do
  [ -x "$b" ] || { echo "perf.sh: $b is missing: run without --no-build" >&2; exit 1; }
done

rm -rf "$raw"
mkdir -p "$raw"
failures=0

# step NAME OUTPUT COMMAND: runs COMMAND (a shell string, recorded exactly as given) with its
# stdout in $raw/OUTPUT and stderr in $raw/NAME.log; records timing, load and exit status.
step() {
  local name=$1 output=$2 command=$3 load0 load1 t0 t1 status
  echo "== perf: $name: $command"
  load0=$(cut -d' ' -f1-3 /proc/loadavg)
  t0=$(date +%s.%N)
  set +e
  bash -c "$command" >"$raw/$output" 2>"$raw/$name.log"
  status=$?
  set -e
  t1=$(date +%s.%N)
  load1=$(cut -d' ' -f1-3 /proc/loadavg)
  if [ "$status" != 0 ]; then
    failures=$((failures + 1))
    echo "   FAILED ($status), see $raw/$name.log" >&2
  fi
  /usr/bin/python3 - "$raw/steps.jsonl" "$name" "$output" "$command" "$t0" "$t1" \
    "$load0" "$load1" "$status" <<'PY'
import json, sys
path, name, output, command, t0, t1, load0, load1, status = sys.argv[1:]
with open(path, "a") as f:
    f.write(json.dumps({"step": name, "output": output, "command": command,
                        "started": float(t0), "seconds": round(float(t1) - float(t0), 1),
                        "load_before": [float(x) for x in load0.split()],
                        "load_after": [float(x) for x in load1.split()],
                        "status": int(status)}) + "\n")
PY
}

gbench="--benchmark_repetitions=5 --benchmark_report_aggregates_only=true --benchmark_format=json"

# ---- 1. codec ------------------------------------------------------------------------------
step codec codec.json "$bin_codec --benchmark_min_time=0.03 $gbench"
step callgrind callgrind.log "valgrind --tool=callgrind --callgrind-out-file=$raw/callgrind.out \
'--toggle-collect=ranger::decode(ranger::CanFrame const&)' $bin_codec \
--callgrind-cycles=100000 2>&1"

# ---- 2. control ----------------------------------------------------------------------------
step control control.json "$bin_control --benchmark_min_time=0.05 $gbench"

# ---- 3. bus --------------------------------------------------------------------------------
step bus bus.json "$bin_bus --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
--benchmark_format=json"
if ip -details link show vcan0 2>/dev/null | grep -qw vcan; then
  echo native >"$raw/vcan.where"
  step vcan vcan.out "$bin_vcan --interface vcan0"
elif { modprobe vcan && ip link add dev vcan0 type vcan && ip link set vcan0 up; } 2>/dev/null; then
  echo native >"$raw/vcan.where"
  step vcan vcan.out "$bin_vcan --interface vcan0"
  ip link del vcan0 2>/dev/null || true
elif [ "$vm" = 1 ]; then
  # Under qemu TCG every figure measures the emulator as much as the code: the loopback run in
  # the same VM gives the scale. Fewer frames than natively, to keep the VM run near a minute.
  echo vm >"$raw/vcan.where"
  step vcan vcan.out "tests/vm/run_in_vm.sh --timeout 600 '$bin_vcan --interface vcan0 \
--frames 20000 --samples 5000; s=\$?; $bin_vcan --loopback --frames 20000 --samples 5000 && \
exit \$s' 2>&1"
else
  echo skipped >"$raw/vcan.where"
fi

# ---- 5. odometry (before the ROS steps: it is short and deterministic) ---------------------
step odometry odometry.out "$bin_e2e --gtest_filter='*OdometryMatchesGroundTruth*'"

# ---- 4, 6, 7. the ROS node -----------------------------------------------------------------
if [ "$ros" = 1 ]; then
  [ -f install/setup.bash ] || { echo "perf.sh: install/setup.bash missing: build first" >&2; exit 1; }
  ros_env="export PATH=/usr/bin:\$PATH; source install/setup.bash;"
  # Each script prints progress on stderr and its JSON (also written with --json) on stdout.
  step node node.stdout "$ros_env /usr/bin/python3 ranger_base/scripts/measure_performance.py \
--duration 20 --samples 400 --json $raw/node.json"
  step launch launch.stdout "$ros_env /usr/bin/python3 scripts/perf_launch_time.py --runs 5 \
--roslaunch-runs 3 --json $raw/launch.json"
  step fleet fleet.stdout "$ros_env /usr/bin/python3 scripts/perf_fleet.py --robots 10 \
--duration 20 --json $raw/fleet.json"
fi

# ---- the document --------------------------------------------------------------------------
echo "== perf: writing docs/PERFORMANCE.md and docs/perf/results.json"
/usr/bin/python3 scripts/perf_report.py --raw "$raw" --build-dir "$perf_dir" \
  --results docs/perf/results.json --markdown docs/PERFORMANCE.md \
  --command "scripts/perf.sh${*:+ $*}" --repo "$repo"
if [ "$failures" -gt 0 ]; then
  echo "perf.sh: $failures step(s) failed: their rows say so; logs in $raw/" >&2
  exit 1
fi
