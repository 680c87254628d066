#!/usr/bin/env bash
# The repository as ROS 1 users get it: cloned as it is into the src/ of a fresh workspace and
# built with the standard tools; the driver run from catkin_make's devel space; the plain CMake
# build (tests included) configured and built with the oldest CMake we declare; catkin_lint.
#
#   scripts/test_workspaces.sh [STEP...]     (default: lint catkin_make catkin_build colcon
#                                             cmake316)
#
#   lint                  catkin_lint -W1 over the repository: no error, no warning; the catkin
#                         tools find each package once (not again in build/ or install/)
#   catkin_make           `catkin_make` in a fresh build/workspaces/ws, then the driver from its
#                         devel space: `source devel/setup.bash; roslaunch ranger_bringup
#                         ranger_minimal.launch sim:=true` until it reaches CAN command mode
#   catkin_make_isolated  `catkin_make_isolated` in a fresh build/workspaces/ws
#   catkin_build          `catkin build` (catkin_tools) in a fresh build/workspaces/ws
#   colcon                `colcon build` in a fresh build/workspaces/ws
#                         (each build's output: build/workspaces/<step>.log)
#   prepare               only CMake 3.16's venv (below), nothing built
#   cmake316              CMake 3.16 (pip, in a venv cached under build/cmake-3.16): the top-level
#                         build configured (library, tool, unit tests, system suites) and the tool
#                         and two test executables built and run, in the plain build's type and
#                         flags (RelWithDebInfo: its compilations are the compiler cache's hits of
#                         build/lib); RANGER_CMAKE316_FULL=1 builds and runs everything
#
# Every build must print no CMake warning (nor "Manually-specified variables were not used").
# The workspaces are fresh copies of the tracked files (with their working-tree contents).
# The ROS builds are the commands of the README as they are, in the build type RANGER_WORKSPACE_BUILD_TYPE
# (default Debug), given to them the way an owner can, through CMake's CMAKE_BUILD_TYPE environment
# variable: what these steps prove is that the packages configure, build, install and run in each
# kind of workspace, which the build type does not change, and a file compiles without
# optimisation in about a third of the time (catkin_make: 172 s against 291 s, the driver's run
# included; the optimised builds are scripts/build.sh's, tested by every other stage). RANGER_WORKSPACE_BUILD_TYPE="" leaves the packages' own default (RelWithDebInfo).
# Environment: RANGER_JOBS (default nproc); ROS_MASTER_URI is not used: the driver's run gets a
# free port of its own.
set -uo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=build_flags.sh
source scripts/build_flags.sh
root=$(pwd)
work=$root/build/workspaces
jobs=${RANGER_JOBS:-$(nproc)}
steps=${*:-lint catkin_make catkin_build colcon cmake316}
build_type=${RANGER_WORKSPACE_BUILD_TYPE-Debug}
if [ -n "$build_type" ]; then export CMAKE_BUILD_TYPE=$build_type; else unset CMAKE_BUILD_TYPE; fi
# ccache (where installed; RANGER_WORKSPACE_CCACHE=0 turns it off) through CMake's
# CMAKE_CXX_COMPILER_LAUNCHER environment variable: the test run's one cache (scripts/ccache_env.sh,
# which scripts/test.sh sources, or sourced here when run alone). Each tool builds in a fresh
# workspace at the same path, so the later tools find the library's objects in it.
if [ "${RANGER_WORKSPACE_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null; then
  if [ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]; then
    # shellcheck source=ccache_env.sh
    source scripts/ccache_env.sh
  fi
else
  unset CMAKE_CXX_COMPILER_LAUNCHER CMAKE_C_COMPILER_LAUNCHER
fi
export PATH=/usr/bin:$PATH  # the ROS tools need Debian's python3, not a pyenv one
if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
mkdir -p "$work" && touch "$root/build/COLCON_IGNORE" "$root/build/CATKIN_IGNORE"
failed=()

# A fresh workspace $ws with the repository in $ws/src/ranger_ros. Every tool gets a fresh one at
# the same path, so that with ccache (below) the library's files, compiled alike by each tool, are
# compiled once.
ws=$work/ws
fresh_workspace() {
  rm -rf "$ws" && mkdir -p "$ws/src/ranger_ros"
  git ls-files -z | tar --null -T - --ignore-failed-read -c 2>/dev/null \
    | tar -x -C "$ws/src/ranger_ros"
}

# Runs a build command with its output in LOG; fails on a failed build or a CMake warning.
checked_build() {  # log command...
  local log=$1
  shift
  local start=$SECONDS
  if ! "$@" >"$log" 2>&1; then
    tail -40 "$log"
    echo "FAILED: $* (log: $log)"
    return 1
  fi
  if grep -nE "CMake (Deprecation )?Warning|Manually-specified variables were not used" "$log"; then
    echo "FAILED: $* printed CMake warnings (log: $log)"
    return 1
  fi
  echo "ok: $* ($((SECONDS - start)) s)"
}

# catkin_lint, and the packages as the catkin tools find them in this checkout, build/ and
# install/ included: each once (catkin_pkg refuses a name found twice), with CATKIN_IGNORE as the
# only marker (older catkin_pkg, e.g. Noetic's, knows no COLCON_IGNORE).
step_lint() {
  catkin_lint -W1 --strict . 2>&1 | grep -v "rosdep"
  [ "${PIPESTATUS[0]}" -eq 0 ] || return 1
  python3 -c 'from catkin_pkg.packages import find_packages
names = sorted(p.name for p in find_packages(".", ignore_markers={"CATKIN_IGNORE"}).values())
print("catkin finds:", " ".join(names))
assert len(names) == 5, names'
}

# The driver from a sourced workspace: ranger_minimal.launch sim:=true on a master of its own,
# until /system_state reports CAN command mode with the protocol identified.
run_driver() {  # setup.bash
  (
    set +u
    source "$1"
    set -u
    port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0))
print(s.getsockname()[1])')
    export ROS_MASTER_URI=http://localhost:$port ROS_HOSTNAME=localhost
    export ROS_HOME=$work/ros_home
    log=$work/driver.log
    roslaunch -p "$port" ranger_bringup ranger_minimal.launch sim:=true >"$log" 2>&1 &
    launch=$!
    python3 - <<'EOF'
import sys
import time

import rospy
from ranger_msgs.msg import SystemState

rospy.init_node("workspace_check", anonymous=True, disable_signals=True)
end = time.monotonic() + 90
while time.monotonic() < end:
    try:
        m = rospy.wait_for_message("/system_state", SystemState, timeout=5)
    except rospy.ROSException:
        continue
    if m.control_mode == 1 and m.identification == "decided":
        print("driver: CAN command mode, protocol identified")
        sys.exit(0)
print("driver: no CAN command mode within 90 s")
sys.exit(1)
EOF
    rc=$?
    kill -INT "$launch" 2>/dev/null
    wait "$launch"
    [ $rc -eq 0 ] || tail -40 "$log"
    exit $rc
  )
}

# CMake 3.16.8 (Ubuntu 20.04's, the oldest we declare) from PyPI, in a venv cached under build/;
# its cmake and ctest alone in build/cmake-3.16/tools (the venv's python3 must not shadow the
# system one the ROS tools need).
cmake316=$root/build/cmake-3.16
cmake316_tools() {
  if [ ! -x "$cmake316/bin/cmake" ]; then
    /usr/bin/python3 -m venv "$cmake316" && "$cmake316/bin/pip" install -q cmake==3.16.8 || return 1
  fi
  mkdir -p "$cmake316/tools"
  ln -sf ../bin/cmake "$cmake316/tools/cmake" && ln -sf ../bin/ctest "$cmake316/tools/ctest"
}
# CMake < 3.17 ignores the CMAKE_CXX_COMPILER_LAUNCHER environment variable (e.g. ccache).
launcher_args=()
[ -n "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ] &&
  launcher_args=(-DCMAKE_CXX_COMPILER_LAUNCHER="$CMAKE_CXX_COMPILER_LAUNCHER")

# The ROS tools run the system's CMake: Debian's catkin finds GoogleTest through the targets of
# CMake >= 3.20 (Noetic's catkin on Ubuntu 20.04 does not), so catkin with CMake 3.16 is a
# combination no user has.
step_catkin_make() {
  fresh_workspace
  (cd "$ws" && checked_build "$work/catkin_make.log" catkin_make -j"$jobs") || return 1
  run_driver "$ws/devel/setup.bash"
}

step_catkin_make_isolated() {
  fresh_workspace
  (cd "$ws" && checked_build "$work/catkin_make_isolated.log" catkin_make_isolated -j"$jobs")
}

step_catkin_build() {
  fresh_workspace
  (cd "$ws" && catkin init >/dev/null &&
    checked_build "$work/catkin_build.log" catkin build --no-status --no-notify -j"$jobs" -p 1)
}

step_colcon() {
  fresh_workspace
  # colcon runs make with -j<cores> -l<cores> unless MAKEFLAGS is set: the load limit would make
  # it build one file at a time while CI's background lane (scripts/test.sh) is busy.
  (cd "$ws" && MAKEFLAGS=-j$jobs checked_build "$work/colcon.log" colcon build \
    --event-handlers console_direct+ --executor sequential)
}

# Not a build: only makes CMake 3.16's venv (scripts/test.sh runs it beside its first build).
step_prepare() { cmake316_tools; }

step_cmake316() {
  local build=$root/build/cmake316 tools=$cmake316/tools
  cmake316_tools || return 1
  "$tools/cmake" --version | head -1
  rm -rf "$build"
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  # The plain build's type and flags (scripts/build.sh's build/lib, at the same depth under the
  # checkout): with the compiler cache, what CMake 3.16 compiles was compiled there, so its
  # compilations are hits and the step costs its configure and links.
  checked_build "$build.configure.log" "$tools/cmake" -S . -B "$build" "${generator[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$ranger_relwithdebinfo_flags" \
    "${launcher_args[@]}" || return 1
  if [ "${RANGER_CMAKE316_FULL:-0}" = 1 ]; then
    checked_build "$build.build.log" "$tools/cmake" --build "$build" -j "$jobs" || return 1
    (cd "$build" && "$tools/ctest" -LE vcan -j "$jobs" --output-on-failure)
  else
    # A unit test of the library (GTest::Main, the test support library) and a system suite
    # (tests/): linked and discovered as CMake 3.16 does it.
    checked_build "$build.build.log" "$tools/cmake" --build "$build" -j "$jobs" \
      --target ranger_can_tool test_codec test_bus_loopback || return 1
    (cd "$build" && "$tools/ctest" -R '^(Codec|LoopbackNetwork|Loopback/)' -j "$jobs" \
      --output-on-failure)
  fi
}

for s in $steps; do
  if [ "$(type -t "step_$s")" != function ]; then
    echo "test_workspaces: unknown step '$s'" >&2
    failed+=("$s")
    continue
  fi
  echo "---- workspace step: $s"
  start=$SECONDS
  if "step_$s"; then
    echo "---- $s: ok ($((SECONDS - start)) s)"
  else
    echo "---- $s: FAILED ($((SECONDS - start)) s)"
    failed+=("$s")
  fi
done
[ ${#failed[@]} -eq 0 ] || { echo "workspace steps failed: ${failed[*]}"; exit 1; }
