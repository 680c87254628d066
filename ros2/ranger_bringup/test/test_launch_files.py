"""The ROS 2 launch files, checked without `launch` (no registry has it here): each file is
loaded with stand-ins for launch and launch_ros that record what it declares, every argument
combination the README shows is run through its setup function, and then every executable,
parameter and file it names must exist: our executables in the workspace, every parameter given
to ranger_base_node declared by the node, every file on disk. robot_state_publisher and rviz2
come from the owner's distribution: named, not looked for."""

import glob
import importlib.util
import os
import re
import sys
import types

import pytest
from ament_index_python.packages import get_package_prefix, get_package_share_directory

from ranger_base import parameters

HERE = os.path.dirname(os.path.abspath(__file__))
LAUNCH_DIR = os.path.join(HERE, os.pardir, "launch")
REPO = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DISTRIBUTION = {("robot_state_publisher", "robot_state_publisher"), ("rviz2", "rviz2")}
ROBOT_STATE_PUBLISHER_PARAMETERS = {"robot_description", "frame_prefix", "publish_frequency"}


class Recorded:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class LaunchConfiguration(Recorded):
    def perform(self, context):
        return context.launch_configurations[self.args[0]]


def stand_ins():
    launch = types.ModuleType("launch")
    launch.LaunchDescription = lambda entities: list(entities)
    actions = types.ModuleType("launch.actions")
    actions.DeclareLaunchArgument = type("DeclareLaunchArgument", (Recorded,), {})
    actions.OpaqueFunction = type("OpaqueFunction", (Recorded,), {})
    substitutions = types.ModuleType("launch.substitutions")
    substitutions.LaunchConfiguration = LaunchConfiguration
    launch.actions, launch.substitutions = actions, substitutions
    launch_ros = types.ModuleType("launch_ros")
    ros_actions = types.ModuleType("launch_ros.actions")
    ros_actions.Node = type("Node", (Recorded,), {})
    launch_ros.actions = ros_actions
    return {"launch": launch, "launch.actions": actions, "launch.substitutions": substitutions,
            "launch_ros": launch_ros, "launch_ros.actions": ros_actions}


def load(path, monkeypatch):
    for name, module in stand_ins().items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location(os.path.basename(path).replace(".", "_"), path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.generate_launch_description()


def run(entities, **given):
    declared = {e.kwargs["name"] if "name" in e.kwargs else e.args[0]: e.kwargs["default_value"]
                for e in entities if type(e).__name__ == "DeclareLaunchArgument"}
    unknown = set(given) - set(declared)
    assert not unknown, f"arguments not declared: {unknown}"
    context = types.SimpleNamespace(launch_configurations={**declared, **given})
    nodes = []
    for e in entities:
        if type(e).__name__ == "OpaqueFunction":
            nodes += e.kwargs["function"](context)
    return nodes


def check_node(node):
    package, executable = node.kwargs["package"], node.kwargs["executable"]
    params = {}
    for p in node.kwargs.get("parameters", []):
        params.update(p)
    if (package, executable) in DISTRIBUTION:
        if package == "robot_state_publisher":
            assert set(params) <= ROBOT_STATE_PUBLISHER_PARAMETERS
            assert "<robot" in params["robot_description"]
        return
    path = os.path.join(get_package_prefix(package), "lib", package, executable)
    assert os.access(path, os.X_OK), f"{package}/{executable}: no executable {path}"
    if executable == "ranger_base_node":
        declared = {parameters.ros2_name(n) for n in parameters.declared_names()}
        assert set(params) <= declared, set(params) - declared


LAUNCH_FILES = sorted(glob.glob(os.path.join(LAUNCH_DIR, "*.launch.py")))


def readme_arguments():
    """Every `ros2 launch ranger_bringup FILE args` of the README and the launch files' own
    docstrings, as (file, {arg: value})."""
    texts = [open(os.path.join(REPO, "README.md"), encoding="utf-8").read()]
    texts += [open(p, encoding="utf-8").read() for p in LAUNCH_FILES]
    out = []
    for text in texts:
        for m in re.finditer(r"ros2 launch ranger_bringup (\S+\.launch\.py)((?: \w+:=\S+)*)", text):
            out.append((m.group(1), dict(a.split(":=") for a in m.group(2).split())))
    return out


def test_there_are_launch_files():
    names = {os.path.basename(p) for p in LAUNCH_FILES}
    assert {"ranger_minimal.launch.py", "display.launch.py",
            "ranger_teleop_keyboard.launch.py"} <= names
    assert readme_arguments()


@pytest.mark.parametrize("file,given", readme_arguments())
def test_every_documented_launch_names_what_exists(file, given, monkeypatch):
    entities = load(os.path.join(LAUNCH_DIR, file), monkeypatch)
    nodes = run(entities, **given)
    assert nodes
    for node in nodes:
        check_node(node)
        if node.kwargs.get("package") == "rviz2":
            config = node.kwargs["arguments"][1]
            assert os.path.exists(config), config


def test_the_minimal_launch_maps_its_arguments(monkeypatch):
    entities = load(os.path.join(LAUNCH_DIR, "ranger_minimal.launch.py"), monkeypatch)
    driver, rsp = run(entities, sim_variant="agx_v2", ns="robot1", model="ranger_mini_v2")
    params = driver.kwargs["parameters"][0]
    assert params["port_name"] == "sim:agx_v2" and params["model"] == "ranger_mini_v2"
    assert params["odom_frame"] == "robot1/odom" and params["base_frame"] == "robot1/base_footprint"
    assert driver.kwargs["namespace"] == "robot1" == rsp.kwargs["namespace"]
    assert rsp.kwargs["parameters"][0]["frame_prefix"] == "robot1/"
    assert 'robot name="ranger"' in rsp.kwargs["parameters"][0]["robot_description"]
    assert params["cmd_vel_stamped"] == "auto"  # the node's default
    driver, _ = run(entities, cmd_vel_stamped="true")
    assert driver.kwargs["parameters"][0]["cmd_vel_stamped"] == "true"


def test_every_model_has_its_urdf():
    from ranger_can import model_names
    share = get_package_share_directory("ranger_description")
    for model in model_names():
        assert os.path.exists(os.path.join(share, "urdf", "models", f"{model}.urdf")), model
