"""Keyboard teleop in this terminal, publishing cmd_vel (in the robot's namespace).

    ros2 launch ranger_bringup ranger_teleop_keyboard.launch.py
    ros2 launch ranger_bringup ranger_teleop_keyboard.launch.py ns:=robot1 speed:=0.3
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = [
    ("ns", "", "the robot's namespace"),
    ("speed", "0.3", "m/s"),
    ("spin_speed", "0.5", "rad/s"),
]


def setup(context):
    arg = {name: LaunchConfiguration(name).perform(context) for name, _, _ in ARGUMENTS}
    return [Node(package="ranger_bringup", executable="ranger_teleop_keyboard",
                 name="ranger_teleop_keyboard", namespace=arg["ns"].strip("/"),
                 output="screen", emulate_tty=True,
                 parameters=[{"speed": float(arg["speed"]),
                              "spin_speed": float(arg["spin_speed"])}])]


def generate_launch_description():
    return LaunchDescription(
        [DeclareLaunchArgument(name, default_value=default, description=doc)
         for name, default, doc in ARGUMENTS] + [OpaqueFunction(function=setup)])
