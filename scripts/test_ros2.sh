#!/usr/bin/env bash
# The `ros2` stage of scripts/test.sh: the Python binding and the ROS 2 packages (ros2/), on each
# ROS 2 distribution tested here (Jazzy, Kilted), each in the venv of its PyPI wheels that
# scripts/setup_ros2.sh makes. For each distribution:
#   1. builds the ROS 2 packages the way the README tells an owner to, in a workspace of the
#      distribution's own (build/ros2_ws_DISTRO) whose src/ holds this checkout:
#      cd WS && colcon build --paths src/ranger_ros/ros2/*
#   2. runs the binding's tests (libranger_can/python/tests, `import ranger_can` from the
#      workspace) and the ROS 2 packages' tests (ros2/*/test), with discovery kept on this host
#      (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) and a domain id of the distribution's own;
#      JUnit reports ros2_DISTRO_binding.xml, ros2_DISTRO_PACKAGE.xml
# and once: checks ros2/ranger_msgs against the ROS 1 ranger_msgs (sync_interfaces.py --check);
# `pip install ./libranger_can` into a fresh venv and the README's Python example with it.
# Usage: scripts/test_ros2.sh [RESULTS_DIR]   (JUnit reports go there; default build/test-results)
#        scripts/test_ros2.sh --setup-only   (only each selected distribution's venv: what
#                                             scripts/test.sh makes beside its first build)
# Environment: RANGER_ROS2_DISTRO=jazzy|kilted (one distribution; default both);
# RANGER_ROS2_VENV_JAZZY, RANGER_ROS2_VENV_KILTED (a distribution's venv; default
# .venv-ros2-DISTRO), RANGER_ROS2_VENV (the venv, when one distribution is selected);
# RANGER_ROS2_DOMAIN_ID (the first distribution's, the next one's one more; default 86 for
# Jazzy, 87 for Kilted), RANGER_JOBS,
# RANGER_ROS2_SKIP_PIP=1 to leave out the pip install; RANGER_ROS2_PARALLEL=0 runs the
# distributions' tests one after the other (default: side by side, after the builds in turn).
set -uo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=build_flags.sh
source scripts/build_flags.sh
root=$(pwd)
setup_only=0
[ "${1:-}" = --setup-only ] && { setup_only=1; shift; }
results=${1:-$root/build/test-results}
mkdir -p "$results"
jobs=${RANGER_JOBS:-$(nproc)}
failed=0
read -r -a distros <<<"${RANGER_ROS2_DISTRO:-jazzy kilted}"
declare -A domain_of=([jazzy]=86 [kilted]=87)

# A distribution's venv, made or completed (scripts/setup_ros2.sh); its path in $venv.
setup_distro() {
  local distro=$1 venv_var="RANGER_ROS2_VENV_${1^^}"
  if [ -z "${!venv_var:-}" ] && [ ${#distros[@]} -gt 1 ] && [ -n "${RANGER_ROS2_VENV:-}" ]; then
    echo "test_ros2: RANGER_ROS2_VENV names one venv for ${distros[*]}: set RANGER_ROS2_DISTRO," \
      "or $venv_var" >&2
    return 1
  fi
  venv=$(RANGER_ROS2_DISTRO=$distro RANGER_ROS2_VENV=${!venv_var:-${RANGER_ROS2_VENV:-}} \
    scripts/setup_ros2.sh | tail -1) || { echo "test_ros2: $distro: setup failed" >&2; return 1; }
}

if [ "$setup_only" = 1 ]; then
  for distro in "${distros[@]}"; do setup_distro "$distro" || failed=1; done
  exit $failed
fi

# One distribution's colcon build in its workspace (its venv in $venv). Returns non-zero when it
# failed.
build_distro() {  # distro
  local distro=$1 ws started=$SECONDS
  setup_distro "$distro" || return 1
  ws=$root/build/ros2_ws_$distro
  echo "test_ros2: $distro: venv $venv, workspace $ws"
  (
    set -e
    mkdir -p "$ws/src"
    ln -sfn "$root" "$ws/src/ranger_ros"
    touch "$root/build/COLCON_IGNORE" "$root/build/CATKIN_IGNORE"
    # shellcheck disable=SC1091
    source "$venv/bin/activate"
    export AMENT_PREFIX_PATH=$venv CMAKE_PREFIX_PATH=$venv
    cd "$ws"
    # Without make's load limit (colcon's default -l<cores>): beside the other lanes it would
    # build one file at a time.
    MAKEFLAGS=${MAKEFLAGS:--j$jobs} colcon --log-base log build --paths src/ranger_ros/ros2/* \
      --event-handlers console_cohesion- summary+ --parallel-workers "$jobs" \
      --cmake-args -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$ranger_relwithdebinfo_flags" \
      -DBUILD_TESTING=OFF
  ) || { echo "test_ros2: $distro: the colcon build failed" >&2; return 1; }
  echo "test_ros2: $distro built ($((SECONDS - started)) s)"
}

# One distribution's tests, with its domain id. Returns non-zero when any failed.
test_distro() {  # distro domain_id
  local distro=$1 domain=$2 venv started=$SECONDS
  setup_distro "$distro" >/dev/null || return 1
  (
    # shellcheck disable=SC1091
    RANGER_ROS2_DISTRO=$distro RANGER_ROS2_VENV=$venv \
      source scripts/ros2_env.sh "$domain"
    rc=0
    python -m pytest -p no:cacheprovider -q libranger_can/python/tests \
      --junitxml="$results/ros2_${distro}_binding.xml" || rc=1
    for t in ros2/*/test; do
      pkg=$(basename "$(dirname "$t")")
      (cd "$t" && python -m pytest -p no:cacheprovider -q . \
        --junitxml="$results/ros2_${distro}_$pkg.xml") || rc=1
    done
    exit $rc
  ) || { echo "test_ros2: $distro: tests failed" >&2; return 1; }
  echo "test_ros2: $distro passed (tests $((SECONDS - started)) s)"
}

/usr/bin/python3 ros2/ranger_msgs/sync_interfaces.py --check || failed=1
# The builds one after the other (the second distribution's compilations of the library are the
# compiler cache's hits of the first's: the same flags at the same depth); then the tests side by
# side (RANGER_ROS2_PARALLEL=0: one after the other): each distribution has its own venv,
# workspace and domain id, and their suites mostly wait on nodes and DDS. The first ones' tests
# run in the background, their output in build/ros2_DISTRO.log, printed whole when they are done.
parallel=${RANGER_ROS2_PARALLEL:-1}
built=()
for distro in "${distros[@]}"; do
  case $distro in
    jazzy | kilted) ;;
    *) echo "test_ros2: RANGER_ROS2_DISTRO=$distro: jazzy or kilted" >&2; failed=1; continue ;;
  esac
  if build_distro "$distro"; then built+=("$distro"); else failed=1; fi
done
background=()
for i in "${!built[@]}"; do
  distro=${built[$i]}
  # RANGER_ROS2_DOMAIN_ID: the first distribution's; the next ones count up from it.
  domain=${domain_of[$distro]}
  [ -z "${RANGER_ROS2_DOMAIN_ID:-}" ] || domain=$((RANGER_ROS2_DOMAIN_ID + i))
  if [ "$parallel" = 1 ] && [ "$i" -lt $((${#built[@]} - 1)) ]; then
    test_distro "$distro" "$domain" >"$root/build/ros2_$distro.log" 2>&1 </dev/null &
    background+=("$distro:$!")
  else
    test_distro "$distro" "$domain" || failed=1
  fi
done
for entry in "${background[@]}"; do
  distro=${entry%%:*}
  wait "${entry#*:}" || failed=1
  echo "---- test_ros2: $distro's tests (run beside the others; build/ros2_$distro.log):"
  cat "$root/build/ros2_$distro.log"
done

if [ "${RANGER_ROS2_SKIP_PIP:-0}" != 1 ]; then
  (
    set -e
    fresh=$root/build/pip_venv
    rm -rf "$fresh"
    /usr/bin/python3 -m venv "$fresh"
    # Built without optimisation (scikit-build-core's SKBUILD_CMAKE_BUILD_TYPE; the package's own
    # default is Release): this step proves the install and the README's example, and the
    # optimised library is the one every other stage tests; about half the compile time.
    # The build directory at a fixed path of the checkout's (emptied first): the compiler cache
    # (scripts/ccache_env.sh) knows its files by their paths, and pip's own is new every time.
    rm -rf "$root/build/pip_build"
    SKBUILD_CMAKE_BUILD_TYPE=${RANGER_PIP_BUILD_TYPE:-Debug} SKBUILD_BUILD_DIR=$root/build/pip_build \
      "$fresh/bin/pip" install -q --disable-pip-version-check ./libranger_can pytest
    cd /tmp  # not the source tree: the installed package is what is imported
    RANGER_PIP_PYTHON=$fresh/bin/python "$fresh/bin/python" -m pytest -p no:cacheprovider -q \
      "$root/libranger_can/python/tests/test_binding.py" -k "readme or parameters" \
      --junitxml="$results/ros2_pip_install.xml"
  ) || { echo "test_ros2: pip install ./libranger_can failed" >&2; failed=1; }
fi
exit $failed
