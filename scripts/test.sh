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
# RANGER_STAGES="unit ros" runs a subset (default: all of the above, in that order).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
results=$root/build/test-results
stages=${RANGER_STAGES:-unit vcan ros ros_vcan workspaces sanitize fuzz ros2}
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

echo "== setup"
scripts/setup.sh test || { echo "setup failed: cannot install the system packages" >&2; exit 1; }
rm -rf "$results" && mkdir -p "$results"
echo "== build"
scripts/build.sh all || { echo "build failed" >&2; exit 1; }

for s in $stages; do
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

echo
echo "==================== summary ===================="
echo "stages passed: ${passed[*]:-none}"
echo "stages failed: ${failed[*]:-none}"
python3 scripts/junit_summary.py "$results"
[ ${#failed[@]} -eq 0 ]
