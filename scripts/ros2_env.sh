# Sourced (bash): the environment the ROS 2 packages run in here — the venv of ROS 2 wheels
# (scripts/setup_ros2.sh), the workspace scripts/test_ros2.sh builds (build/ros2_ws), the
# tf2_msgs generated for the tests, and discovery kept on this host with a domain id of its own.
#   source scripts/ros2_env.sh [DOMAIN_ID]          (default $RANGER_ROS2_DOMAIN_ID, else 87)
ranger_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ranger_venv=${RANGER_ROS2_VENV:-$ranger_root/.venv-ros2}
# shellcheck disable=SC1091
source "$ranger_venv/bin/activate"
set +u
# shellcheck disable=SC1091
source "$ranger_root/build/ros2_ws/install/setup.bash"
ranger_tf2=$ranger_venv/tf2_msgs_prefix
export PYTHONPATH=$ranger_tf2/lib/python3.11/site-packages:${PYTHONPATH:-}
export LD_LIBRARY_PATH=$ranger_tf2/lib:${LD_LIBRARY_PATH:-}
export AMENT_PREFIX_PATH=$ranger_tf2:${AMENT_PREFIX_PATH:-}
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID=${1:-${RANGER_ROS2_DOMAIN_ID:-87}}
export ROS_LOG_DIR=$ranger_root/build/ros2_log
