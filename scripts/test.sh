#!/usr/bin/env bash
# The project's one test command (README, CI): installs what is missing, builds, and runs every
# suite. Stages run in order; a failing stage does not stop the later ones, and the exit status
# is non-zero when any stage failed. The last line counts every test case from the JUnit reports.
#
#   unit      libranger_can unit tests and the in-process system suites (CTest, label != vcan)
#   dbc       (part of unit) the DBC file cross-checked against the C++ codec with cantools
#   vcan      suites on real SocketCAN vcan0: natively where the kernel has vcan, else in a qemu VM
#   ros       the ROS packages' tests (rostest + gtest, launch-file checks) via colcon test
#   ros_vcan  the node against `ranger_can sim vcan0` over real SocketCAN (native or in the VM):
#             stop on SIGINT / rosnode kill, the chassis's own stop after SIGKILL
#   workspaces  the repository in the src/ of fresh ROS 1 workspaces (scripts/test_workspaces.sh):
#             catkin_make (and the driver run from its devel space), catkin build, colcon; the
#             plain build with CMake 3.16; catkin_lint -W1
#   sanitize  ASan+UBSan and TSan builds of the library and its tests, ASan build of the ROS node
#   fuzz      every libFuzzer target for a bounded time (RANGER_FUZZ_SECONDS, default 60)
#   ros2      the Python binding and the ROS 2 packages (scripts/test_ros2.sh): the venv of ROS 2
#             wheels (scripts/setup_ros2.sh), the colcon build of ros2/ as the README has it, the
#             binding's and the ROS 2 node's tests on this host only, pip install ./libranger_can
#
# RANGER_STAGES="unit ros" runs a subset (default: all of the above, in the order
# unit vcan ros_vcan ros workspaces sanitize fuzz ros2).
#
# Building ahead: sanitize, fuzz and ros2 spend most of their time compiling, while ros mostly waits
# on nodes and clocks. Once no stage that runs the qemu VM (vcan, ros_vcan) is left, the builds of
# those three stages start in the background at the lowest CPU and I/O priority (nice 19, ionice
# idle), so that they take only what the running stage leaves; the first of the three waits for
# them, then finds its builds done (log: build/build-ahead.log). RANGER_BUILD_AHEAD=0 builds each
# in its own stage instead.
#
# The builds are RelWithDebInfo with line tables only (scripts/build.sh); the workspaces stage
# builds without optimisation (scripts/test_workspaces.sh); ASan+UBSan at -O0, TSan at -O1
# (scripts/test_sanitizers.sh).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
results=$root/build/test-results
stages=${RANGER_STAGES:-unit vcan ros_vcan ros workspaces sanitize fuzz ros2}
failed=()
passed=()

run_stage() {  # name command...
  local name=$1
  shift
  echo
  echo "==================== stage: $name ===================="
  local start=$SECONDS
  if "$@"; then
    passed+=("$name")
    echo "== stage $name: ok ($((SECONDS - start)) s)"
  else
    failed+=("$name")
    echo "== stage $name: FAILED ($((SECONDS - start)) s)"
  fi
}

stage_unit() {
  ctest --test-dir build/lib -LE vcan --output-on-failure -j "$(nproc)" \
    --output-junit "$results/unit.xml"
}
stage_vcan() { scripts/run_vcan_tests.sh build/lib "$results/vcan.xml"; }
ros_env() {  # the environment every ROS stage runs in (system Python first, our workspace)
  export PATH=/usr/bin:$PATH
  if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
  set +u; source install/setup.bash; set -u
  export ROS_HOME=${ROS_HOME:-$root/build/ros_home} ROS_HOSTNAME=localhost
  export ROS_MASTER_URI=${ROS_MASTER_URI:-http://localhost:11311}
}
stage_ros_vcan() { (ros_env && scripts/run_vcan_tests.sh build/ws/ranger_base "$results/ros_vcan.xml"); }
stage_ros() {
  (
    ros_env
    colcon --log-base build/log test --base-paths . --build-base build/ws --install-base install \
      --event-handlers console_direct+ --executor sequential --return-code-on-test-failure
    local rc=$?
    colcon test-result --test-result-base build/ws --verbose
    rm -rf "$results/ros" && mkdir -p "$results/ros"
    find build/ws -path '*test_results*' -name '*.xml' -exec cp {} "$results/ros/" \;
    exit $rc
  )
}
stage_workspaces() { scripts/test_workspaces.sh; }
stage_sanitize() { scripts/test_sanitizers.sh; }
stage_fuzz() { scripts/fuzz.sh "${RANGER_FUZZ_SECONDS:-60}"; }
stage_ros2() { scripts/test_ros2.sh "$results"; }

# ---- building ahead ----
ahead_pid=
ahead_log=$root/build/build-ahead.log
build_ahead() {  # the builds of the stages among sanitize, fuzz, ros2 that are to run
  local wanted=() s
  for s in $stages; do
    case $s in sanitize | fuzz | ros2) wanted+=("$s") ;; esac
  done
  [ ${#wanted[@]} -gt 0 ] && [ "${RANGER_BUILD_AHEAD:-1}" != 0 ] || return 0
  echo "== building ahead in the background (nice 19): ${wanted[*]} (log: build/build-ahead.log)"
  set -m  # a process group of its own, which the trap below can stop whole
  (
    renice -n 19 -p "$BASHPID" >/dev/null
    ionice -c 3 -p "$BASHPID" 2>/dev/null
    export RANGER_BUILD_ONLY=1
    for s in "${wanted[@]}"; do
      start=$SECONDS
      case $s in
        sanitize) scripts/test_sanitizers.sh ;;
        fuzz) scripts/fuzz.sh ;;
        ros2) scripts/test_ros2.sh "$results" ;;
      esac
      echo "== build ahead: $s: exit status $? ($((SECONDS - start)) s)"
    done
  ) </dev/null >"$ahead_log" 2>&1 &
  ahead_pid=$!
  set +m
}
stop_ahead() { [ -z "$ahead_pid" ] || kill -TERM -- "-$ahead_pid" 2>/dev/null; }
trap stop_ahead EXIT
trap 'stop_ahead; exit 130' INT TERM
wait_ahead() {
  [ -n "$ahead_pid" ] || return 0
  local start=$SECONDS
  echo "== waiting for the builds ahead"
  wait "$ahead_pid"
  ahead_pid=
  echo "== builds ahead done (waited $((SECONDS - start)) s):"
  grep -E "^== build ahead:" "$ahead_log"
  # A build that failed ahead is built again by its stage, which then shows the error.
}
# The background builds start before the first stage after which no VM stage is left.
vm_left() {  # stages...: is vcan or ros_vcan among them?
  local s
  for s in "$@"; do
    case $s in vcan | ros_vcan) return 0 ;; esac
  done
  return 1
}

echo "== setup"
scripts/setup.sh test || { echo "setup failed: cannot install the system packages" >&2; exit 1; }
rm -rf "$results" "$ahead_log" && mkdir -p "$results"
echo "== build"
scripts/build.sh all || { echo "build failed" >&2; exit 1; }

read -r -a stage_list <<<"$stages"
for i in "${!stage_list[@]}"; do
  s=${stage_list[$i]}
  if [ -z "$ahead_pid" ] && [ ! -f "$ahead_log" ] && ! vm_left "${stage_list[@]:$i}"; then
    build_ahead
  fi
  case $s in sanitize | fuzz | ros2) wait_ahead ;; esac
  if [ "$(type -t "stage_$s")" != function ]; then
    echo "unknown stage '$s'" >&2
    failed+=("$s")
    continue
  fi
  case $s in
    sanitize) [ -x scripts/test_sanitizers.sh ] || { echo "(no sanitizer script yet)"; continue; } ;;
    fuzz) [ -x scripts/fuzz.sh ] || { echo "(no fuzz script yet)"; continue; } ;;
  esac
  run_stage "$s" "stage_$s"
done

wait_ahead

echo
echo "==================== summary ===================="
echo "stages passed: ${passed[*]:-none}"
echo "stages failed: ${failed[*]:-none}"
python3 scripts/junit_summary.py "$results"
[ ${#failed[@]} -eq 0 ]
