#!/usr/bin/env bash
# The `ros2` stage of scripts/test.sh: the Python binding and the ROS 2 packages (ros2/), in the
# venv of ROS 2 Kilted wheels that scripts/setup_ros2.sh makes.
#   1. builds the ROS 2 packages the way the README tells an owner to, in a workspace whose src/
#      holds this checkout: cd WS && colcon build --paths src/ranger_ros/ros2/*
#   2. checks ros2/ranger_msgs against the ROS 1 ranger_msgs (sync_interfaces.py --check)
#   3. runs the binding's tests (libranger_can/python/tests, `import ranger_can` from the
#      workspace) and the ROS 2 packages' tests (ros2/*/test), with discovery kept on this host
#      (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) and a domain id of the stage's own
#   4. `pip install ./libranger_can` into a fresh venv and the README's Python example with it
# Usage: scripts/test_ros2.sh [RESULTS_DIR]   (JUnit reports go there; default build/test-results)
# Environment: RANGER_ROS2_VENV (default .venv-ros2), RANGER_ROS2_DOMAIN_ID (default 87),
# RANGER_JOBS, RANGER_ROS2_SKIP_PIP=1 to leave out step 4.
set -uo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=build_flags.sh
source scripts/build_flags.sh
root=$(pwd)
results=${1:-$root/build/test-results}
mkdir -p "$results"
venv=$(scripts/setup_ros2.sh | tail -1) || { echo "test_ros2: setup failed" >&2; exit 1; }
ws=$root/build/ros2_ws
jobs=${RANGER_JOBS:-$(nproc)}
failed=0

(
  set -e
  mkdir -p "$ws/src"
  ln -sfn "$root" "$ws/src/ranger_ros"
  touch "$root/build/COLCON_IGNORE" "$root/build/CATKIN_IGNORE"
  # shellcheck disable=SC1091
  source "$venv/bin/activate"
  export AMENT_PREFIX_PATH=$venv CMAKE_PREFIX_PATH=$venv
  cd "$ws"
  colcon --log-base log build --paths src/ranger_ros/ros2/* \
    --event-handlers console_cohesion- summary+ --parallel-workers "$jobs" \
    --cmake-args -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$ranger_relwithdebinfo_flags" \
    -DBUILD_TESTING=OFF
) || { echo "test_ros2: the colcon build failed" >&2; exit 1; }

/usr/bin/python3 ros2/ranger_msgs/sync_interfaces.py --check || failed=1

(
  # shellcheck disable=SC1091
  RANGER_ROS2_VENV=$venv source scripts/ros2_env.sh "${RANGER_ROS2_DOMAIN_ID:-87}"
  rc=0
  python -m pytest -p no:cacheprovider -q libranger_can/python/tests \
    --junitxml="$results/ros2_binding.xml" || rc=1
  for t in ros2/*/test; do
    pkg=$(basename "$(dirname "$t")")
    (cd "$t" && python -m pytest -p no:cacheprovider -q . \
      --junitxml="$results/ros2_$pkg.xml") || rc=1
  done
  exit $rc
) || failed=1

if [ "${RANGER_ROS2_SKIP_PIP:-0}" != 1 ]; then
  (
    set -e
    fresh=$root/build/pip_venv
    rm -rf "$fresh"
    /usr/bin/python3 -m venv "$fresh"
    # Built without optimisation (scikit-build-core's SKBUILD_CMAKE_BUILD_TYPE; the package's own
    # default is Release): this step proves the install and the README's example, and the
    # optimised library is the one every other stage tests; about half the compile time.
    SKBUILD_CMAKE_BUILD_TYPE=${RANGER_PIP_BUILD_TYPE:-Debug} \
      "$fresh/bin/pip" install -q --disable-pip-version-check ./libranger_can pytest
    cd /tmp  # not the source tree: the installed package is what is imported
    RANGER_PIP_PYTHON=$fresh/bin/python "$fresh/bin/python" -m pytest -p no:cacheprovider -q \
      "$root/libranger_can/python/tests/test_binding.py" -k "readme or parameters" \
      --junitxml="$results/ros2_pip_install.xml"
  ) || { echo "test_ros2: pip install ./libranger_can failed" >&2; failed=1; }
fi
exit $failed
