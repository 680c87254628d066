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
#   sanitize  four stages (scripts/test_sanitizers.sh): asan (ASan+UBSan build of the library
#             and its tests), tsan (TSan build of the suites labelled `threads`), asan_ros (ASan
#             build of the ROS node and its tests), tsan_ros (the same with TSan)
#   fuzz      every libFuzzer target for a bounded time (RANGER_FUZZ_SECONDS, default 60)
#   ros2      the Python binding and the ROS 2 packages (scripts/test_ros2.sh): the venv of ROS 2
#             wheels (scripts/setup_ros2.sh), the colcon build of ros2/ as the README has it, the
#             binding's and the ROS 2 node's tests on this host only, pip install ./libranger_can
#
# RANGER_STAGES="unit ros" runs a subset (default: all of the above, in the order
# unit vcan ros_vcan ros ros2 workspaces sanitize fuzz).
#
# Lanes. unit, the VM stages, ros and ros2 mostly wait on nodes, clocks, the VM and DDS;
# workspaces, sanitize and fuzz mostly compile. Right after the first build, workspaces, sanitize
# and fuzz form a queue (asan_ros, asan, tsan_ros, workspaces, fuzz, tsan: the longest first)
# that a background lane works through at a lower CPU and I/O priority (nice 10: about a tenth
# of the CPU against a busy stage, never starved; ionice best-effort 7), beside the unit and VM
# stages and then beside ros; once no VM stage is left, ros2 runs in a lane of its own beside ros (ROS
# 1's master and ROS 2's DDS domain do not meet). Whichever lane, the foreground included, is done
# with its own stages takes the next queued stage (whoever runs a queued stage runs it at nice
# 10), so that both cores work to the end. The vcan and ros_vcan stages share one boot of the VM.
# The lanes' output is printed at the end, each stage's as a whole, and they count as any other
# stage. RANGER_LANES=2 keeps ros2 in the foreground after ros; RANGER_LANES=1 runs every stage in
# the foreground, in turn.
#
# Every build goes through one compiler cache kept between runs (scripts/ccache_env.sh); the
# Python environments of the later stages (ROS 2 wheels, CMake 3.16, cantools) are made beside
# the first build. The summary at the end gives each stage's wall time, the total, the cache's
# hit rate and the count of test cases.
#
# The builds are RelWithDebInfo with line tables only (scripts/build.sh); the workspaces stage
# builds without optimisation (scripts/test_workspaces.sh); ASan+UBSan at -O0, TSan at -O1
# (scripts/test_sanitizers.sh).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
results=$root/build/test-results
stages=${RANGER_STAGES:-unit vcan ros_vcan ros ros2 workspaces sanitize fuzz}
failed=()
passed=()
declare -A stage_time=()   # stage -> "SECONDS s" (with ", background" for the lane's)
timing_order=()            # the order the stages ended in, for the summary
run_start=$SECONDS

note_time() {  # name seconds [where]
  stage_time[$1]="$2 s${3:+, $3}"
  timing_order+=("$1")
}

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
  note_time "$name" $((SECONDS - start))
}

stage_unit() {
  ctest --test-dir build/lib -LE vcan --output-on-failure -j "$(nproc)" \
    --output-junit "$results/unit.xml"
}
# vcan and ros_vcan share one boot of the VM (scripts/run_vcan_tests.sh --and): when both are
# selected, the vcan stage runs ros_vcan's suite after its own, and ros_vcan reports what it found
# (each tree's status and time in build/lib/vcan-status/).
stage_vcan() {
  if wants ros_vcan && [ "${ros_vcan_done:-0}" = 0 ]; then
    vcan_vm_shared=1
    (ros_env && scripts/run_vcan_tests.sh build/lib "$results/vcan.xml" \
      --and build/ws/ranger_base "$results/ros_vcan.xml")
    tree_status 0
  else
    scripts/run_vcan_tests.sh build/lib "$results/vcan.xml"
  fi
}
tree_status() {  # index: the status of that tree of the shared VM run (1 when it did not run)
  local rc=1 seconds
  read -r rc seconds 2>/dev/null <"build/lib/vcan-status/$1"
  return "$rc"
}
ros_env() {  # the environment every ROS stage runs in (system Python first, our workspace)
  export PATH=/usr/bin:$PATH
  if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
  set +u; source install/setup.bash; set -u
  export ROS_HOME=${ROS_HOME:-$root/build/ros_home} ROS_HOSTNAME=localhost
  export ROS_MASTER_URI=${ROS_MASTER_URI:-http://localhost:11311}
}
stage_ros_vcan() {
  ros_vcan_done=1
  (ros_env && scripts/run_vcan_tests.sh build/ws/ranger_base "$results/ros_vcan.xml")
}
# ros_vcan after the vcan stage ran its suite in the same VM boot: that run's verdict.
ros_vcan_in_vcan_vm() {
  local rc=1 seconds=?
  read -r rc seconds 2>/dev/null <build/lib/vcan-status/1
  echo "ros_vcan: run in the vcan stage's VM boot: status $rc in $seconds s (output above, in stage vcan)"
  [ "$rc" = 0 ]
}
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
# sanitize is four stages, so that lanes can share them: asan, tsan, asan_ros, tsan_ros.
stage_asan() { scripts/test_sanitizers.sh address; }
stage_tsan() { scripts/test_sanitizers.sh thread; }
stage_asan_ros() { scripts/test_sanitizers.sh ros; }
stage_tsan_ros() { scripts/test_sanitizers.sh ros_thread; }
stage_fuzz() { scripts/fuzz.sh "${RANGER_FUZZ_SECONDS:-60}"; }
stage_ros2() { scripts/test_ros2.sh "$results"; }

# ---- the lanes ----
# The stages that mostly compile (asan_ros, asan, tsan_ros, workspaces, fuzz, tsan: the longest
# first) form a queue from the start of the run: a background lane at nice 10 works through it,
# and every other lane joins it when its own stages are done, the foreground too (each queued
# stage is claimed once: mkdir is atomic). ros2 runs in a lane of its own beside ros, once the VM stages
# are done. A stage run in a lane or from the queue writes its output to
# build/lane/<stage>.log, printed whole at the end; it counts as any other stage.
queued=()    # the compile queue, in order (RANGER_LANES >= 2)
own_lane=()  # stages in a background lane of their own (RANGER_LANES >= 3)
case ${RANGER_LANES:-3} in
  1) ;;
  2) queued=(asan_ros asan tsan_ros workspaces fuzz tsan) ;;
  *) queued=(asan_ros asan tsan_ros workspaces fuzz tsan) own_lane=(ros2) ;;
esac
selected_queue=()  # the queued stages of this run
logged_stages=()   # every stage whose output is in build/lane/, in the order printed
lane_pids=()
lanes_started=0
lane_dir=$root/build/lane
in_list() {  # word words...
  local w=$1 x
  shift
  for x in "$@"; do [ "$x" = "$w" ] && return 0; done
  return 1
}
vm_left() {  # stages...: is vcan or ros_vcan among them?
  local s
  for s in "$@"; do
    case $s in vcan | ros_vcan) return 0 ;; esac
  done
  return 1
}
run_to_log() {  # runner stage: the stage into lane/<stage>.log; "rc seconds runner" into .status
  local start=$SECONDS rc
  if "stage_$2" >"$lane_dir/$2.log" 2>&1; then rc=0; else rc=$?; fi
  echo "$rc $((SECONDS - start)) $1" >"$lane_dir/$2.status"
}
# Claims and runs, in order, each queued stage nobody has claimed yet, at a lower CPU and I/O
# priority whoever runs it (nice 10: about a tenth of the CPU against a busy stage that waits on
# clocks, never starved; ionice best-effort 7).
work_queue() {  # runner
  (
    renice -n 10 -p "$BASHPID" >/dev/null
    ionice -c 2 -n 7 -p "$BASHPID" 2>/dev/null
    for s in "${selected_queue[@]}"; do
      mkdir "$lane_dir/claim.$s" 2>/dev/null || continue
      run_to_log "$1" "$s"
    done
  )
}
start_lane() {  # name stages...: in the background: its stages in turn, then the queue
  local name=$1
  shift
  echo "== background lane $name: ${*:+$* then }the compile queue (logs: build/lane/)"
  set -m  # a process group of its own, which the trap below can stop whole
  (
    for s in "$@"; do run_to_log "$name" "$s"; done
    work_queue "$name"
  ) </dev/null &
  lane_pids+=($!)
  set +m
}
start_queue() {  # stages...: the run's stages; the compile lane starts with the queued ones
  local s
  for s in "${queued[@]}"; do  # in the queue's order
    if in_list "$s" "$@" && [ "$(type -t "stage_$s")" = function ]; then selected_queue+=("$s"); fi
  done
  logged_stages+=("${selected_queue[@]}")
  [ ${#selected_queue[@]} -eq 0 ] || start_lane compile
}
start_lanes() {  # stages...: the rest of the run; starts the lanes of their own with their part
  local s own=()
  lanes_started=1
  for s in "${own_lane[@]}"; do
    if in_list "$s" "$@" && [ "$(type -t "stage_$s")" = function ]; then own+=("$s"); fi
  done
  logged_stages=("${own[@]}" "${logged_stages[@]}")
  [ ${#own[@]} -eq 0 ] || start_lane ros2 "${own[@]}"
}
in_a_lane() {  # stage: is it run by a lane (or the queue) rather than in the foreground here?
  in_list "$1" "${logged_stages[@]}"
}
stop_lanes() {
  local pid
  for pid in "${lane_pids[@]}"; do kill -TERM -- "-$pid" 2>/dev/null; done
  [ -z "${prepare_pid:-}" ] || kill -TERM "$prepare_pid" 2>/dev/null
}
trap stop_lanes EXIT
trap 'stop_lanes; exit 130' INT TERM
finish_lanes() {  # the foreground joins the queue, waits for the lanes, prints and counts
  local start=$SECONDS s rc seconds runner pid
  [ ${#logged_stages[@]} -gt 0 ] || return 0
  if [ ${#selected_queue[@]} -gt 0 ]; then
    echo
    echo "== the foreground joins the compile queue"
    work_queue foreground
  fi
  echo "== waiting for the background lanes"
  for pid in "${lane_pids[@]}"; do wait "$pid"; done
  lane_pids=()
  echo "== background lanes done (waited $((SECONDS - start)) s)"
  for s in "${logged_stages[@]}"; do
    rc=1 seconds= runner=
    read -r rc seconds runner 2>/dev/null <"$lane_dir/$s.status"
    echo
    echo "==================== stage: $s (lane ${runner:-none}) ===================="
    cat "$lane_dir/$s.log" 2>/dev/null
    if [ "$rc" = 0 ]; then
      passed+=("$s")
      echo "== stage $s: ok ($seconds s, lane $runner)"
    else
      failed+=("$s")
      echo "== stage $s: FAILED (${seconds:-not run} s, lane ${runner:-none})"
    fi
    note_time "$s" "${seconds:-?}" "lane ${runner:-none}"
  done
}

# ---- what only downloads, beside the first build ----
# The Python environments the later stages install from PyPI (the ROS 2 wheels, CMake 3.16 for the
# workspaces stage, cantools for the DBC check) are made while the first build compiles; the
# stages find them complete. Their output: build/lane/prepare.log, printed when it fails.
wants() {  # stage: is it among the selected stages?
  local s
  for s in $stages; do [ "$s" = "$1" ] && return 0; done
  return 1
}
prepare_pid=
start_prepare() {
  (
    rc=0
    if wants ros2; then scripts/test_ros2.sh --setup-only || rc=1; fi
    if wants workspaces; then scripts/test_workspaces.sh prepare || rc=1; fi
    if wants unit; then
      /usr/bin/python3 tests/dbc/check_dbc.py --venv "$root/build/lib/dbc-venv" --venv-only || rc=1
    fi
    exit $rc
  ) </dev/null >"$lane_dir/prepare.log" 2>&1 &
  prepare_pid=$!
}
finish_prepare() {
  [ -n "$prepare_pid" ] || return 0
  local start=$SECONDS
  if wait "$prepare_pid"; then
    echo "== downloads done (waited $((SECONDS - start)) s after the build)"
  else
    echo "== preparing the stages' Python environments failed (the stages try again):"
    tail -30 "$lane_dir/prepare.log"
  fi
  prepare_pid=
}

echo "== setup"
setup_start=$SECONDS
scripts/setup.sh test || { echo "setup failed: cannot install the system packages" >&2; exit 1; }
note_time setup $((SECONDS - setup_start))
# shellcheck source=ccache_env.sh
source scripts/ccache_env.sh
rm -rf "$results" "$lane_dir" && mkdir -p "$results" "$lane_dir"
start_prepare
echo "== build"
build_start=$SECONDS
scripts/build.sh all || { echo "build failed" >&2; exit 1; }
note_time build $((SECONDS - build_start))
finish_prepare

read -r -a stage_list <<<"${stages//sanitize/asan tsan asan_ros tsan_ros}"
# The compile queue starts at once, beside the unit and VM stages (the VM takes about half a core
# while its suites run: 169 of 346 s measured; the queue runs at nice 10, so the VM's threads
# come first whenever they want a core).
start_queue "${stage_list[@]}"
for i in "${!stage_list[@]}"; do
  s=${stage_list[$i]}
  if [ "$(type -t "stage_$s")" != function ]; then
    echo "unknown stage '$s'" >&2
    failed+=("$s")
    continue
  fi
  if [ "$lanes_started" = 0 ] && ! vm_left "${stage_list[@]:$i}"; then
    # From here on no VM stage is left: ros2's lane takes its part of the rest.
    start_lanes "${stage_list[@]:$i}"
  fi
  in_a_lane "$s" && continue
  if [ "$s" = ros_vcan ] && [ "${vcan_vm_shared:-0}" = 1 ]; then
    run_stage ros_vcan ros_vcan_in_vcan_vm
    continue
  fi
  run_stage "$s" "stage_$s"
done
finish_lanes

echo
echo "==================== test reports ($results) ===================="
python3 scripts/junit_summary.py "$results" --files
echo "==================== summary ===================="
echo "stages passed: ${passed[*]:-none}"
echo "stages failed: ${failed[*]:-none}"
echo "wall time per stage (a lane's beside the foreground's):"
for s in "${timing_order[@]}"; do printf '  %-11s %s\n' "$s" "${stage_time[$s]}"; done
printf '  %-11s %s s\n' total $((SECONDS - run_start))
echo "wall-clock bounds and what the tests measured against them, under this run's load:"
python3 scripts/junit_summary.py "$results" --measured
ranger_ccache_summary
python3 scripts/junit_summary.py "$results" --total
[ ${#failed[@]} -eq 0 ]
