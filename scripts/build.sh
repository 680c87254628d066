#!/usr/bin/env bash
# Builds everything: libranger_can with its tool, unit tests and system suites (plain CMake, in
# build/lib), then the ROS packages with colcon (build/ws, install/).
# Usage: scripts/build.sh [lib|ros|all]    (default all; in the ROS workspace the library's own
# tests are off: they are built in build/lib)
# Environment: RANGER_BUILD_TYPE (default RelWithDebInfo), RANGER_JOBS (default nproc).
# RelWithDebInfo here is -O2 with line tables only (-g1; scripts/build_flags.sh says why and
# RANGER_RELWITHDEBINFO_FLAGS replaces them). For a debugger session: RANGER_BUILD_TYPE=Debug.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=build_flags.sh
source scripts/build_flags.sh
what=${1:-all}
build_type=${RANGER_BUILD_TYPE:-RelWithDebInfo}
jobs=${RANGER_JOBS:-$(nproc)}
relwithdebinfo=-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$ranger_relwithdebinfo_flags
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)

# Keep colcon and the catkin tools (catkin_make, catkin build) from finding the packages a second
# time in the build trees.
mkdir -p build && touch build/COLCON_IGNORE build/CATKIN_IGNORE
case "$what" in lib | ros | all) ;; *) echo "build.sh: unknown target '$what'" >&2; exit 2 ;; esac

if [ "$what" != ros ]; then
  echo "== build: libranger_can + tests (build/lib)"
  [ -f build/lib/CMakeCache.txt ] || cmake -S . -B build/lib "${generator[@]}" \
    -DCMAKE_BUILD_TYPE="$build_type" "$relwithdebinfo" >/dev/null
  cmake --build build/lib -j "$jobs"
fi
[ "$what" = lib ] && exit 0

echo "== build: ROS packages (colcon -> install/)"
# The ROS build must use the system Python (python3 on PATH may be a pyenv without ROS modules).
export PATH=/usr/bin:$PATH
if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
# colcon runs make with -j<cores> -l<cores> unless MAKEFLAGS is set: under load (scripts/test.sh's
# background lane) the load limit would build one file at a time.
MAKEFLAGS=${MAKEFLAGS:--j$jobs} colcon --log-base build/log build --base-paths . \
  --build-base build/ws --install-base install \
  --event-handlers console_cohesion- summary+ \
  --parallel-workers "$jobs" \
  --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE="$build_type" "$relwithdebinfo"
# The install space holds the packages' manifests too: a catkin tool run in a workspace around
# this checkout must not find them there (colcon leaves COLCON_IGNORE in it itself).
touch install/CATKIN_IGNORE
