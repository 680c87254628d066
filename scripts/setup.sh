#!/usr/bin/env bash
# Installs the system packages the project needs, idempotently (nothing is fetched when all are
# present). Usage: scripts/setup.sh [lib|ros|test]
#   lib   compiler, CMake, GoogleTest, Google Benchmark: enough for libranger_can and its tool
#   ros   lib + ROS 1 (distribution packages on Debian 12 / Ubuntu 22.04+, Noetic on Ubuntu 20.04)
#   test  ros + what the full test suite needs: can-utils, qemu + a kernel with vcan (for hosts
#         without CAN support), Xvfb for the rviz test, clang for fuzzing, valgrind, the other
#         ROS 1 build tools (catkin_tools, catkin_lint) for the workspace builds
set -euo pipefail
profile=${1:-test}

lib_pkgs=(build-essential cmake ninja-build pkg-config git libgtest-dev libbenchmark-dev
  python3 python3-venv)
# ROS 1 as Debian 12 / Ubuntu 22.04+ package it (installed under /usr).
ros_pkgs=(ros-base-dev libroscpp-dev librostest-dev python3-rostest python3-roslaunch
  python3-rosnode python3-rostopic ros-message-generation python3-genmsg libstd-msgs-dev
  libstd-srvs-dev python3-std-srvs
  libgeometry-msgs-dev libsensor-msgs-dev libnav-msgs-dev libtf2-ros-dev libtf2-geometry-msgs-dev
  libdiagnostic-updater-dev libdiagnostic-aggregator-dev libdiagnostic-aggregator-tools
  ros-robot-state-publisher rviz liburdfdom-tools libeigen3-dev catkin rosbash
  libnodeletlib-dev libnodelet-dev libnodeletlib-tools python3-nodelet pluginlib-dev
  libtf2-msgs-dev libtopic-tools-dev
  colcon python3-colcon-ros python3-colcon-cmake python3-colcon-bash python3-colcon-output
  python3-colcon-parallel-executor python3-colcon-package-selection
  python3-colcon-package-information python3-colcon-test-result python3-colcon-library-path
  python3-matplotlib python3-numpy
  python3-yaml python3-pytest python3-geometry-msgs python3-nav-msgs python3-sensor-msgs
  python3-diagnostic-msgs python3-tf2-msgs)
# ROS Noetic from packages.ros.org (Ubuntu 20.04), for users who already have /opt/ros/noetic.
noetic_pkgs=(ros-noetic-ros-base ros-noetic-rostest ros-noetic-tf2-ros ros-noetic-tf2-geometry-msgs
  ros-noetic-nav-msgs ros-noetic-sensor-msgs ros-noetic-std-srvs ros-noetic-diagnostic-updater
  ros-noetic-diagnostic-aggregator ros-noetic-robot-state-publisher ros-noetic-rviz
  ros-noetic-nodelet ros-noetic-pluginlib ros-noetic-topic-tools
  liburdfdom-tools libeigen3-dev python3-colcon-common-extensions python3-matplotlib)
test_pkgs=(can-utils iproute2 kmod qemu-system-x86 linux-image-amd64 busybox-static cpio gzip
  xvfb xauth imagemagick clang libclang-rt-14-dev valgrind clang-format ccache)
# The workspace builds (scripts/test_workspaces.sh): catkin build and catkin_lint (catkin_make
# and catkin_make_isolated come with catkin; CMake 3.16 from PyPI into a venv).
if [ -d /opt/ros/noetic ]; then
  test_pkgs+=(python3-catkin-tools python3-catkin-lint)
else
  test_pkgs+=(catkin-tools catkin-lint)
fi

pkgs=("${lib_pkgs[@]}")
case "$profile" in
  lib) ;;
  ros | test)
    if [ -d /opt/ros/noetic ]; then pkgs+=("${noetic_pkgs[@]}"); else pkgs+=("${ros_pkgs[@]}"); fi
    [ "$profile" = test ] && pkgs+=("${test_pkgs[@]}")
    ;;
  *) echo "setup.sh: unknown profile '$profile' (expected lib, ros or test)" >&2; exit 2 ;;
esac

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#pkgs[@]} packages for profile '$profile' are installed"
  exit 0
fi

sudo=()
[ "$(id -u)" -eq 0 ] || sudo=(sudo)
echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
  "${missing[@]}" >/dev/null
echo "setup: done"
