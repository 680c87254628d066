#!/usr/bin/env bash
# Makes the ROS 2 environment of the `ros2` test stage, idempotently: a venv made with the
# system's Python (/usr/bin/python3) holding one ROS 2 distribution (Jazzy or Kilted) from PyPI
# wheels, colcon, and what the Python binding builds with (pybind11, scikit-build-core) and is
# tested with (pytest).
#
#   RANGER_ROS2_DISTRO=jazzy|kilted scripts/setup_ros2.sh [VENV]
#     distribution: default kilted; venv: default $RANGER_ROS2_VENV, else .venv-ros2-DISTRO in
#     the checkout (each distribution a venv of its own)
#
# Two things the wheels lack are mended here, in the venv only (the packages in ros2/ build with
# the standard ament, rosidl and rclpy APIs of any distribution and know nothing of this):
#  * the wheels' exported CMake files (*__rosidl_generator_pyExport*.cmake) name the wheel
#    builder's /opt/python/... include directories: they are pointed at the system's Python
#    headers (python3-dev) and the venv's numpy headers, so rosidl_generate_interfaces works;
#  * tf2_msgs has no wheel: its one message is generated into a prefix of its own
#    ($VENV/tf2_msgs_prefix), which only the tests put on their paths.
# Prints the venv's path on its last line. Needs the packages of `scripts/setup.sh lib` and
# python3-dev.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
distro=${RANGER_ROS2_DISTRO:-kilted}
venv=${1:-${RANGER_ROS2_VENV:-$root/.venv-ros2-$distro}}
python=/usr/bin/python3
# What both distributions have under the same names, then each one's own: Kilted gathers the
# CMake support of ament_cmake_ros in ament-cmake-ros-core; Jazzy has no such package and needs
# ament_cmake_ros and what it finds (gmock, gtest, pytest, python_cmake_module) by name.
common=(rclpy rmw-fastrtps-cpp std-msgs geometry-msgs nav-msgs sensor-msgs diagnostic-msgs std-srvs
  rosidl-default-generators rosidl-core-generators ament-cmake)
case $distro in
  kilted) own=(ament-cmake-ros-core ament-package builtin-interfaces) ;;
  jazzy) own=(ament-cmake-ros ament-cmake-gmock ament-cmake-gtest ament-cmake-pytest
    python-cmake-module ament-package builtin-interfaces) ;;
  *) echo "setup_ros2: RANGER_ROS2_DISTRO=$distro: jazzy or kilted" >&2; exit 2 ;;
esac
packages=()
for p in "${common[@]}" "${own[@]}"; do packages+=("ros-$distro-$p"); done
packages+=(catkin_pkg colcon-common-extensions pybind11 scikit-build-core pytest)
# Bump when the list above or the mending below changes: an older venv is then completed.
stamp_text="ranger ros2 venv 1: ${packages[*]}"

if ! dpkg-query -W -f='${Status}' python3-dev 2>/dev/null | grep -q "install ok installed"; then
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
    python3-dev python3-venv >/dev/null
fi

if [ -f "$venv/.ranger-setup" ] && [ "$(cat "$venv/.ranger-setup")" = "$stamp_text" ]; then
  echo "setup_ros2: the venv is complete"
  echo "$venv"
  exit 0
fi

echo "setup_ros2: making the ROS 2 venv in $venv"
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
# The wheels install ROS 2 package manifests (share/*/package.xml): no ROS 1 tool may find them.
touch "$venv/COLCON_IGNORE" "$venv/CATKIN_IGNORE" "$venv/AMENT_IGNORE"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "${packages[@]}"

# ---- the wheels' CMake exports: the builder's include paths -> this machine's ----------------
py_include=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
np_include=$("$venv/bin/python" -c 'import numpy; print(numpy.get_include())')
mended=0
while IFS= read -r -d '' f; do
  if grep -q '/opt/python/' "$f"; then
    sed -i -E \
      -e "s#/opt/python/[^/;\"]+/include/python3\.[0-9]+#${py_include}#g" \
      -e "s#/opt/python/[^;\"]+/site-packages/numpy/_core/include#${np_include}#g" \
      -e "s#/opt/python/[^;\"]+/site-packages/numpy/core/include#${np_include}#g" "$f"
    mended=$((mended + 1))
  fi
done < <(find "$venv" -name '*__rosidl_generator_pyExport*.cmake' -print0)
if grep -rl --include='*__rosidl_generator_pyExport*.cmake' '/opt/python/' "$venv" >/dev/null; then
  echo "setup_ros2: a CMake export still names /opt/python/ after mending:" >&2
  grep -rl --include='*__rosidl_generator_pyExport*.cmake' '/opt/python/' "$venv" >&2
  exit 1
fi
echo "setup_ros2: $mended CMake export files pointed at $py_include and $np_include"

# ---- tf2_msgs for the tests (no wheel exists): its one message, generated --------------------
tf2_src=$venv/tf2_msgs_src
tf2_prefix=$venv/tf2_msgs_prefix
rm -rf "$tf2_src" "$venv/tf2_msgs_build" "$tf2_prefix"
mkdir -p "$tf2_src/msg"
cat >"$tf2_src/msg/TFMessage.msg" <<'EOF'
geometry_msgs/TransformStamped[] transforms
EOF
cat >"$tf2_src/package.xml" <<'EOF'
<?xml version="1.0"?>
<package format="3">
  <name>tf2_msgs</name>
  <version>0.0.0</version>
  <description>TFMessage only, generated for ranger_ros's ROS 2 tests (no wheel exists)</description>
  <maintainer email="maintainers@ranger-ros.invalid">ranger_ros maintainers</maintainer>
  <license>BSD-3-Clause</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
  <depend>geometry_msgs</depend>
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
EOF
cat >"$tf2_src/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.16)
project(tf2_msgs)
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
find_package(geometry_msgs REQUIRED)
rosidl_generate_interfaces(${PROJECT_NAME} msg/TFMessage.msg DEPENDENCIES geometry_msgs)
ament_export_dependencies(rosidl_default_runtime)
ament_package()
EOF
(
  # shellcheck disable=SC1091
  source "$venv/bin/activate"
  export AMENT_PREFIX_PATH=$venv CMAKE_PREFIX_PATH=$venv
  generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake -S "$tf2_src" -B "$venv/tf2_msgs_build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$tf2_prefix" -DPython3_EXECUTABLE="$venv/bin/python" \
    -DBUILD_TESTING=OFF >"$venv/tf2_msgs_build.log" 2>&1 &&
    cmake --build "$venv/tf2_msgs_build" --target install -j "${RANGER_JOBS:-$(nproc)}" \
      >>"$venv/tf2_msgs_build.log" 2>&1
) || { echo "setup_ros2: generating tf2_msgs failed:" >&2; tail -30 "$venv/tf2_msgs_build.log" >&2; exit 1; }
rm -rf "$venv/tf2_msgs_build" "$tf2_src"
echo "setup_ros2: tf2_msgs generated into $tf2_prefix"

echo "$stamp_text" >"$venv/.ranger-setup"
echo "$venv"
