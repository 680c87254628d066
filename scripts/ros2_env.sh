# Sourced (bash): the environment the ROS 2 packages run in here, for one distribution
# ($RANGER_ROS2_DISTRO: jazzy or kilted, default kilted) — the venv of its ROS 2 wheels
# (scripts/setup_ros2.sh; $RANGER_ROS2_VENV, else .venv-ros2-DISTRO), the workspace
# scripts/test_ros2.sh builds for it (build/ros2_ws_DISTRO), the tf2_msgs generated for the
# tests, and discovery kept on this host with a domain id of its own.
#   source scripts/ros2_env.sh [DOMAIN_ID]   (default $RANGER_ROS2_DOMAIN_ID, else 86 Jazzy, 87 Kilted)
ranger_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ranger_distro=${RANGER_ROS2_DISTRO:-kilted}
ranger_venv=${RANGER_ROS2_VENV:-$ranger_root/.venv-ros2-$ranger_distro}
ranger_domain=87
[ "$ranger_distro" = jazzy ] && ranger_domain=86
# shellcheck disable=SC1091
source "$ranger_venv/bin/activate"
set +u
# shellcheck disable=SC1091
source "$ranger_root/build/ros2_ws_$ranger_distro/install/setup.bash"
ranger_tf2=$ranger_venv/tf2_msgs_prefix
export PYTHONPATH=$ranger_tf2/lib/python3.11/site-packages:${PYTHONPATH:-}
export LD_LIBRARY_PATH=$ranger_tf2/lib:${LD_LIBRARY_PATH:-}
export AMENT_PREFIX_PATH=$ranger_tf2:${AMENT_PREFIX_PATH:-}
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID=${1:-${RANGER_ROS2_DOMAIN_ID:-$ranger_domain}}
export ROS_LOG_DIR=$ranger_root/build/ros2_log_$ranger_distro
