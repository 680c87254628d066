"""The RANGER driver on ROS 2: ranger_base_node and robot_state_publisher with the model's URDF.

    ros2 launch ranger_bringup ranger_minimal.launch.py                   robot on can0
    ros2 launch ranger_bringup ranger_minimal.launch.py sim:=true         in-process virtual chassis
    ros2 launch ranger_bringup ranger_minimal.launch.py sim_variant:=agx_v2   a variant (sim:VARIANT)
    ros2 launch ranger_bringup ranger_minimal.launch.py model:=ranger_mini_v2 protocol:=agx_v2
    ros2 launch ranger_bringup ranger_minimal.launch.py ns:=robot1        under /robot1, TF frames
                                                                           prefixed robot1/
    ros2 launch ranger_bringup ranger_minimal.launch.py cmd_vel_stamped:=true   cmd_vel as
                                                                           TwistStamped
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = [
    ("port_name", "can0", "CAN interface of the chassis; replaced by sim when sim is true"),
    ("sim", "false", "true: the node's in-process virtual chassis instead of a CAN interface"),
    ("sim_variant", "", "a virtual chassis variant (implies sim): port_name sim:VARIANT"),
    ("model", "ranger", "ranger, ranger_mini_v1, ranger_mini_v2 or ranger_mini_v3"),
    ("protocol", "auto", "auto (identified from the chassis), manual or agx_v2 (forced)"),
    ("commissioning_file", "", "a file from ranger_can commission: its settings, forced"),
    ("ns", "", "the robot's namespace, e.g. robot1"),
    ("publish_odom_tf", "true", "publish the odom -> base_footprint transform"),
    ("robot_state_publisher", "true", "publish the URDF's TF from joint_states"),
    ("cmd_vel_stamped", "auto", "cmd_vel as TwistStamped (true), Twist (false) or the type of its "
     "publishers (auto)"),
]


def urdf_of(model):
    path = os.path.join(get_package_share_directory("ranger_description"), "urdf", "models",
                        f"{model}.urdf")
    with open(path, encoding="utf-8") as f:
        return f.read()


def setup(context):
    arg = {name: LaunchConfiguration(name).perform(context) for name, _, _ in ARGUMENTS}
    ns = arg["ns"].strip("/")
    prefix = f"{ns}/" if ns else ""
    port = (f"sim:{arg['sim_variant']}" if arg["sim_variant"] else
            "sim" if arg["sim"].lower() == "true" else arg["port_name"])
    params = {"port_name": port, "model": arg["model"], "protocol": arg["protocol"],
              "odom_frame": prefix + "odom", "base_frame": prefix + "base_footprint",
              "frame_prefix": prefix,
              "publish_odom_tf": arg["publish_odom_tf"].lower() == "true",
              "cmd_vel_stamped": arg["cmd_vel_stamped"].lower()}
    if arg["commissioning_file"]:
        params["commissioning_file"] = arg["commissioning_file"]
    actions = [Node(package="ranger_base", executable="ranger_base_node",
                    name="ranger_base_node", namespace=ns, output="screen",
                    parameters=[params])]
    if arg["robot_state_publisher"].lower() == "true":
        actions.append(Node(package="robot_state_publisher", executable="robot_state_publisher",
                            name="robot_state_publisher", namespace=ns, output="screen",
                            parameters=[{"robot_description": urdf_of(arg["model"]),
                                         "frame_prefix": prefix, "publish_frequency": 50.0}]))
    return actions


def generate_launch_description():
    return LaunchDescription(
        [DeclareLaunchArgument(name, default_value=default, description=doc)
         for name, default, doc in ARGUMENTS] + [OpaqueFunction(function=setup)])
