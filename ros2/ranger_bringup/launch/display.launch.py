"""rviz2 with the RANGER configuration (robot model, TF, odometry). Start the driver first
(ranger_minimal.launch.py).

    ros2 launch ranger_bringup display.launch.py
    ros2 launch ranger_bringup display.launch.py ns:=robot1
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = [
    ("ns", "", "the robot's namespace (its topics and TF frames)"),
    ("rviz_config", "", "an rviz2 configuration (default: ranger_description's ranger.rviz)"),
]


def setup(context):
    ns = LaunchConfiguration("ns").perform(context).strip("/")
    config = LaunchConfiguration("rviz_config").perform(context) or os.path.join(
        get_package_share_directory("ranger_description"), "rviz", "ranger.rviz")
    fixed = f"{ns}/odom" if ns else "odom"
    return [Node(package="rviz2", executable="rviz2", name="rviz2", namespace=ns,
                 arguments=["-d", config, "-f", fixed], output="screen")]


def generate_launch_description():
    return LaunchDescription(
        [DeclareLaunchArgument(name, default_value=default, description=doc)
         for name, default, doc in ARGUMENTS] + [OpaqueFunction(function=setup)])
