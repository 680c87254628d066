"""The launch files, resolved by roslaunch itself (--nodes, --dump-params; nothing is started):
which nodes each starts, under which names, with which parameters, for each combination of the
arguments users pass. roslaunch-check (CMakeLists.txt) covers parse errors and missing packages.

The source launch files are tested (their package directories come first on ROS_PACKAGE_PATH);
ranger_base must be findable (source the workspace's setup.bash), as for roslaunch-check."""

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
import yaml

sys.path.insert(0, os.path.dirname(__file__))
from rostest_support import PACKAGE_DIR  # noqa: E402

REPO = os.path.dirname(PACKAGE_DIR)
DESCRIPTION_DIR = os.path.join(REPO, "ranger_description")
LAUNCH_DIR = os.path.join(PACKAGE_DIR, "launch")
GEOMETRY = os.path.join(DESCRIPTION_DIR, "config", "geometry.yaml")
ENV = dict(os.environ, ROS_HOME=os.environ.get("ROS_HOME", "/tmp/ranger-test-roshome"),
           ROS_PACKAGE_PATH=os.pathsep.join(
               [PACKAGE_DIR, DESCRIPTION_DIR] + [p for p in os.environ.get(
                   "ROS_PACKAGE_PATH", "").split(os.pathsep) if p]))


def roslaunch(option, launch, *args):
    """`roslaunch OPTION FILE ARGS...`; option may be a list (e.g. ["--args", "/rviz"])."""
    options = option if isinstance(option, list) else [option]
    result = subprocess.run(["roslaunch", *options, os.path.join(LAUNCH_DIR, launch), *args],
                            capture_output=True, text=True, env=ENV, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def nodes(launch, *args):
    return sorted(roslaunch("--nodes", launch, *args).split())


def params(launch, *args):
    return yaml.safe_load(roslaunch("--dump-params", launch, *args))


def all_launch_files():
    return sorted(f for f in os.listdir(LAUNCH_DIR) if f.endswith(".launch"))


def test_every_launch_file_is_covered():
    assert all_launch_files() == ["display.launch", "ranger_diagnostics.launch",
                                  "ranger_minimal.launch", "ranger_sim.launch",
                                  "ranger_sim_two.launch", "ranger_teleop_keyboard.launch"]


ROBOT_LAUNCH_FILES = ["display.launch", "ranger_minimal.launch", "ranger_sim.launch",
                      "ranger_teleop_keyboard.launch"]


@pytest.mark.parametrize("launch", all_launch_files())
@pytest.mark.parametrize("ns", [[], ["namespace:=r1"]])
def test_every_launch_file_resolves(launch, ns):
    if ns and launch == "ranger_sim_two.launch":
        # Its robots have namespaces of their own (robot1, robot2): an argument it does not
        # declare is refused, not ignored.
        assert "unknown argument namespace:=r1" in refused(launch, *ns)
        return
    assert nodes(launch, *ns)


@pytest.mark.parametrize("launch", ROBOT_LAUNCH_FILES)
def test_ns_and_namespace_are_one_argument(launch):
    """README and users say ns:=robot1; a silently ignored ns:= would start a second robot in the
    root namespace, whose node replaces (kills) the first robot's driver."""
    expected = nodes(launch, "namespace:=robot1")
    assert all(n.startswith("/robot1/") or n == "/diagnostic_aggregator" for n in expected)
    assert any(n.startswith("/robot1/") for n in expected)
    assert nodes(launch, "ns:=robot1") == expected
    assert nodes(launch, "ns:=/robot1/") == expected  # slashes are the namespace's, not a name
    assert nodes(launch, "ns:=robot1", "namespace:=robot1") == expected
    assert params(launch, "ns:=robot1") == params(launch, "namespace:=robot1")


@pytest.mark.parametrize("launch", ROBOT_LAUNCH_FILES)
def test_ns_and_namespace_that_disagree_are_refused(launch):
    result = subprocess.run(["roslaunch", "--nodes", os.path.join(LAUNCH_DIR, launch),
                             "ns:=robot1", "namespace:=robot2"],
                            capture_output=True, text=True, env=ENV, timeout=120)
    assert result.returncode != 0
    assert ("ns:=robot1 and namespace:=robot2 name two different namespaces"
            in result.stdout + result.stderr)


def test_minimal_on_can0_by_default():
    assert nodes("ranger_minimal.launch") == ["/diagnostic_aggregator", "/ranger_base_node",
                                              "/robot_state_publisher"]
    p = params("ranger_minimal.launch")
    assert p["/ranger_base_node/port_name"] == "can0"
    assert p["/ranger_base_node/odom_frame"] == "odom"
    assert p["/ranger_base_node/base_frame"] == "base_footprint"  # the URDF's root
    assert p["/ranger_base_node/frame_prefix"] == ""
    assert p["/ranger_base_node/publish_odom_tf"] is True
    assert p["/ranger_base_node/cmd_vel_stamped"] == "auto"  # the node's default
    # The RANGER, its protocol settings identified from the chassis, no commissioning file.
    assert p["/ranger_base_node/model"] == "ranger"
    assert p["/ranger_base_node/protocol"] == "auto"
    assert "/ranger_base_node/commissioning_file" not in p
    assert p["/diagnostic_aggregator/analyzers/ranger/path"] == "RANGER"
    assert p["/diagnostic_aggregator/analyzers/ranger/expected"] == [
        f"ranger_base_node: {s}" for s in STATUSES]


def test_minimal_arguments_reach_the_node():
    p = params("ranger_minimal.launch", "port_name:=can1", "publish_odom_tf:=false",
               "cmd_vel_stamped:=true")
    assert p["/ranger_base_node/port_name"] == "can1"
    assert p["/ranger_base_node/publish_odom_tf"] is False
    assert p["/ranger_base_node/cmd_vel_stamped"] == "true"  # a string, as the node reads it
    assert params("ranger_minimal.launch", "sim:=true", "port_name:=can1")[
        "/ranger_base_node/port_name"] == "sim"


def test_model_protocol_and_commissioning_file_reach_the_node(tmp_path):
    # A file the node loads (one that does not exist fails the launch: see below).
    commissioned = tmp_path / "commissioned.yaml"
    commissioned.write_text("protocol: agx_v2\n")
    p = params("ranger_minimal.launch", "model:=ranger_mini_v3", "protocol:=agx_v2",
               f"commissioning_file:={commissioned}")
    assert p["/ranger_base_node/model"] == "ranger_mini_v3"
    assert p["/ranger_base_node/protocol"] == "agx_v2"
    assert p["/ranger_base_node/commissioning_file"] == str(commissioned)


def test_nodelet_manager_loads_the_driver_as_a_nodelet_with_the_same_parameters():
    """nodelet_manager:=NAME: the same node name (so the same private parameters), started as
    `nodelet load ranger_base/RangerNodelet NAME`; empty: the executable."""
    def command(*args):  # without roslaunch's leading VAR=value assignments
        words = roslaunch(["--args", "/ranger_base_node"], "ranger_minimal.launch", *args).split()
        return [w for w in words if "=" not in w or w.startswith("__")]
    args = command("nodelet_manager:=/manager")
    assert os.path.basename(args[0]) == "nodelet", args
    assert args[1:4] == ["load", "ranger_base/RangerNodelet", "/manager"], args
    assert os.path.basename(command()[0]) == "ranger_base_node"
    assert params("ranger_minimal.launch", "nodelet_manager:=/manager") == params(
        "ranger_minimal.launch")


def test_sim_variant_is_the_in_process_virtual_chassis():
    assert params("ranger_minimal.launch", "sim:=true", "sim_variant:=spin_cw")[
        "/ranger_base_node/port_name"] == "sim:spin_cw"
    # A variant is always the virtual chassis, whatever port_name says.
    assert params("ranger_minimal.launch", "sim_variant:=agx_v2", "port_name:=can1")[
        "/ranger_base_node/port_name"] == "sim:agx_v2"


def model_file(model):
    """A model's flat YAML (libranger_can/models/MODEL.yaml)."""
    with open(os.path.join(REPO, "libranger_can", "models", model + ".yaml"),
              encoding="utf-8") as f:
        return yaml.safe_load(f)


def front_left_steering_origin(robot_description):
    robot = ET.fromstring(robot_description)
    joint = robot.find("joint[@name='front_left_steering_joint']/origin")
    x, y, _ = (float(v) for v in joint.get("xyz").split())
    return x, y


def test_another_model_gives_node_and_urdf_its_geometry():
    """No geometry.yaml for another model: the node takes the model's geometry (model_preset),
    the URDF is the model's (generate_urdf.py --model)."""
    mini = model_file("ranger_mini_v2")
    p = params("ranger_minimal.launch", "model:=ranger_mini_v2")
    for key in ("wheelbase", "track", "wheel_radius"):
        assert f"/ranger_base_node/{key}" not in p
    assert front_left_steering_origin(p["/robot_description"]) == pytest.approx(
        (mini["wheelbase"] / 2, mini["track"] / 2))
    # An explicit geometry file still wins, for the node and the URDF alike.
    p = params("ranger_minimal.launch", "model:=ranger_mini_v2", f"geometry_file:={GEOMETRY}")
    assert p["/ranger_base_node/wheelbase"] == model_file("ranger")["wheelbase"]
    assert front_left_steering_origin(p["/robot_description"])[0] == pytest.approx(0.445)


def test_node_and_urdf_share_the_geometry_file():
    with open(GEOMETRY, encoding="utf-8") as f:
        geometry = yaml.safe_load(f)
    p = params("ranger_minimal.launch")
    for key in ("wheelbase", "track", "wheel_radius"):
        assert p[f"/ranger_base_node/{key}"] == geometry[key]
    robot = ET.fromstring(p["/robot_description"])
    joint = robot.find("joint[@name='front_left_steering_joint']/origin")
    x, y, _ = (float(v) for v in joint.get("xyz").split())
    assert (x, y) == pytest.approx((geometry["wheelbase"] / 2, geometry["track"] / 2))


def test_a_custom_geometry_file_changes_node_and_urdf_together(tmp_path):
    with open(GEOMETRY, encoding="utf-8") as f:
        geometry = yaml.safe_load(f)
    geometry["wheelbase"] = 1.0
    custom = tmp_path / "geometry.yaml"
    custom.write_text(yaml.safe_dump(geometry))
    p = params("ranger_minimal.launch", f"geometry_file:={custom}")
    assert p["/ranger_base_node/wheelbase"] == 1.0
    robot = ET.fromstring(p["/robot_description"])
    origin = robot.find("joint[@name='rear_right_steering_joint']/origin").get("xyz")
    assert float(origin.split()[0]) == pytest.approx(-0.5)


def test_namespace_moves_nodes_params_and_frames():
    # A robot in a namespace starts no aggregator of its own (the fleet shares one).
    assert nodes("ranger_minimal.launch", "namespace:=r1") == [
        "/r1/ranger_base_node", "/r1/robot_state_publisher"]
    p = params("ranger_minimal.launch", "namespace:=r1")
    assert p["/r1/ranger_base_node/odom_frame"] == "r1/odom"
    assert p["/r1/ranger_base_node/base_frame"] == "r1/base_footprint"
    assert p["/r1/ranger_base_node/frame_prefix"] == "r1/"
    assert p["/r1/robot_state_publisher/tf_prefix"] == "r1"
    assert "/r1/robot_description" in p and "/robot_description" not in p


def test_sim_in_process_and_on_vcan():
    assert "/virtual_chassis" not in nodes("ranger_sim.launch")
    assert params("ranger_sim.launch")["/ranger_base_node/port_name"] == "sim"
    assert "/virtual_chassis" in nodes("ranger_sim.launch", "interface:=vcan0")
    assert params("ranger_sim.launch", "interface:=vcan0")["/ranger_base_node/port_name"] == "vcan0"
    assert "/rviz" in nodes("ranger_sim.launch", "rviz:=true")
    # model, variant and protocol: the driver's, and the virtual chassis's on vcan0 too.
    p = params("ranger_sim.launch", "model:=ranger_mini_v1", "sim_variant:=mini_v1",
               "protocol:=manual")
    assert p["/ranger_base_node/port_name"] == "sim:mini_v1"
    assert p["/ranger_base_node/model"] == "ranger_mini_v1"
    assert p["/ranger_base_node/protocol"] == "manual"
    p = params("ranger_sim.launch", "interface:=vcan0", "sim_variant:=spin_cw")
    assert p["/ranger_base_node/port_name"] == "vcan0"
    out = roslaunch(["--args", "/virtual_chassis"], "ranger_sim.launch", "interface:=vcan0",
                    "model:=ranger_mini_v2", "sim_variant:=spin_cw")
    assert "vcan0 --model ranger_mini_v2 --chassis-variant spin_cw" in out


def test_display_opens_rviz_with_the_config_in_the_namespace():
    assert nodes("display.launch") == ["/rviz"]
    assert nodes("display.launch", "namespace:=r1") == ["/r1/rviz"]
    assert nodes("display.launch", "description:=true") == ["/robot_state_publisher", "/rviz"]
    mini = model_file("ranger_mini_v1")
    p = params("display.launch", "description:=true", "model:=ranger_mini_v1")
    assert front_left_steering_origin(p["/robot_description"]) == pytest.approx(
        (mini["wheelbase"] / 2, mini["track"] / 2))
    # The command line rviz gets: the config and the fixed frame.
    out = roslaunch(["--args", "/rviz"], "display.launch")
    assert os.path.join("rviz", "ranger.rviz") in out and "-f odom" in out
    out = roslaunch(["--args", "/r1/rviz"], "display.launch", "namespace:=r1")
    assert "-f r1/odom" in out


def test_teleop_parameters_and_namespace():
    assert nodes("ranger_teleop_keyboard.launch", "namespace:=r1") == [
        "/r1/ranger_teleop_keyboard"]
    p = params("ranger_teleop_keyboard.launch", "speed:=0.5")
    assert p["/ranger_teleop_keyboard/speed"] == 0.5
    assert p["/ranger_teleop_keyboard/key_timeout"] < 0.5  # the driver's cmd_vel_timeout


# ---- diagnostics: one aggregator per ROS master -------------------------------------------------

STATUSES = ["CAN link", "Control mode", "Protocol", "Chassis errors", "Battery", "Frame rates"]


def analyzer_of(p, robot):
    key = f"/diagnostic_aggregator/analyzers/ranger/analyzers/{robot}"
    return {k[len(key) + 1:]: v for k, v in p.items() if k.startswith(key + "/")}


def test_one_aggregator_groups_several_robots():
    assert nodes("ranger_diagnostics.launch", "robots:=robot1 robot2") == [
        "/diagnostic_aggregator"]
    p = params("ranger_diagnostics.launch", "robots:=robot1 /robot2/")
    assert p["/diagnostic_aggregator/analyzers/ranger/type"] == (
        "diagnostic_aggregator/AnalyzerGroup")
    assert p["/diagnostic_aggregator/analyzers/ranger/path"] == "RANGER"
    for robot in ("robot1", "robot2"):
        a = analyzer_of(p, robot)
        assert a["path"] == robot
        assert a["find_and_remove_prefix"] == [f"{robot}/ranger_base_node: "]
        assert a["expected"] == [f"{robot}/ranger_base_node: {s}" for s in STATUSES]


def test_the_aggregator_stays_at_the_root_when_asked_for_a_namespaced_robot():
    assert nodes("ranger_minimal.launch", "ns:=r1", "diagnostics_aggregator:=true") == [
        "/diagnostic_aggregator", "/r1/ranger_base_node", "/r1/robot_state_publisher"]
    p = params("ranger_minimal.launch", "ns:=r1", "diagnostics_aggregator:=true")
    assert analyzer_of(p, "r1")["path"] == "r1"


def test_two_simulated_robots_share_one_aggregator():
    p = params("ranger_sim_two.launch", "model:=ranger_mini_v3", "protocol:=agx_v2")
    assert p["/robot2/ranger_base_node/model"] == "ranger_mini_v3"
    assert p["/robot1/ranger_base_node/protocol"] == "agx_v2"
    assert nodes("ranger_sim_two.launch") == [
        "/diagnostic_aggregator", "/robot1/ranger_base_node", "/robot1/robot_state_publisher",
        "/robot2/ranger_base_node", "/robot2/robot_state_publisher"]
    p = params("ranger_sim_two.launch")
    for robot in ("robot1", "robot2"):
        assert p[f"/{robot}/ranger_base_node/port_name"] == "sim"
        assert p[f"/{robot}/ranger_base_node/model"] == "ranger"
        assert p[f"/{robot}/ranger_base_node/protocol"] == "auto"
        assert p[f"/{robot}/ranger_base_node/odom_frame"] == f"{robot}/odom"
        assert p[f"/{robot}/ranger_base_node/base_frame"] == f"{robot}/base_footprint"
        assert p[f"/{robot}/ranger_base_node/frame_prefix"] == f"{robot}/"
        assert p[f"/{robot}/robot_state_publisher/tf_prefix"] == robot
        assert analyzer_of(p, robot)["path"] == robot
    assert "/robot_description" not in p


def test_teleop_is_not_required():
    """Quitting the teleop is how it ends: not a reason for a REQUIRED-process-died banner
    (test_teleop_pty.py runs the launch file in a terminal and quits)."""
    import roslaunch.config

    config = roslaunch.config.load_config_default(
        [os.path.join(LAUNCH_DIR, "ranger_teleop_keyboard.launch")], None, verbose=False)
    assert [(n.name, n.required) for n in config.nodes] == [("ranger_teleop_keyboard", False)]


# ---- failures look like failures: checked before anything starts ------------------------------

def refused(launch, *args, option="--nodes"):
    """`roslaunch [OPTION] FILE ARGS...` must fail; returns its console output."""
    command = ["roslaunch"] + ([option] if option else []) + [os.path.join(LAUNCH_DIR, launch)]
    # A master nobody runs: a refused launch must not need (or start) one.
    env = dict(ENV, ROS_MASTER_URI="http://localhost:1")
    result = subprocess.run(command + list(args), capture_output=True, text=True, env=env,
                            timeout=120)
    assert result.returncode != 0, result.stdout + result.stderr
    return result.stdout + result.stderr


@pytest.mark.parametrize("option", ["--nodes", None])
def test_an_unusable_argument_fails_the_launch_with_the_drivers_reason(option):
    """protocol:=xyz: the node would exit FATAL under a roslaunch that exits 0; the launch's check
    (the node's own) refuses it while roslaunch reads the file: exit status 1, nothing started."""
    out = refused("ranger_minimal.launch", "sim:=true", "protocol:=xyz", option=option)
    assert "the launch is refused before anything starts" in out, out
    assert 'parameter ~protocol = "xyz": expected one of auto, manual, agx_v2' in out, out
    assert "REQUIRED process" not in out, "nothing may have been started"


@pytest.mark.parametrize("launch", ["ranger_minimal.launch", "ranger_sim.launch"])
def test_an_unknown_argument_fails_the_launch_naming_it(launch):
    out = refused(launch, "publish_rate:=abc")
    assert "unknown argument publish_rate:=abc" in out, out
    assert "params_file:=FILE" in out, out


def test_a_missing_commissioning_file_fails_the_launch():
    out = refused("ranger_minimal.launch", "sim:=true", "commissioning_file:=/no/such/file.yaml")
    assert "/no/such/file.yaml" in out, out


def test_a_parameter_file_reaches_the_node_and_is_checked_like_the_arguments(tmp_path):
    good = tmp_path / "driver.yaml"
    good.write_text("publish_rate: 20\ncmd_vel_timeout: 0.3\nport_name: sim\n"
                    "linear:\n  x:\n    has_velocity_limits: true\n    max_velocity: 1.0\n")
    p = params("ranger_minimal.launch", f"params_file:={good}")
    assert p["/ranger_base_node/publish_rate"] == 20
    assert p["/ranger_base_node/cmd_vel_timeout"] == 0.3
    assert p["/ranger_base_node/linear/x/max_velocity"] == 1.0
    assert p["/ranger_base_node/port_name"] == "sim", "the file's values win over the arguments"
    # Through ranger_sim.launch and to both robots of ranger_sim_two.launch.
    assert params("ranger_sim.launch", f"params_file:={good}")[
        "/ranger_base_node/publish_rate"] == 20
    two = params("ranger_sim_two.launch", f"params_file:={good}")
    assert two["/robot1/ranger_base_node/cmd_vel_timeout"] == 0.3
    assert two["/robot2/ranger_base_node/cmd_vel_timeout"] == 0.3
    bad = tmp_path / "bad.yaml"
    bad.write_text("publish_rate: abc\nodom_frame_id: odom\n")
    out = refused("ranger_minimal.launch", "sim:=true", f"params_file:={bad}")
    assert 'parameter ~publish_rate = "abc": expected a number in (0, 50] Hz' in out, out
    assert "parameter ~odom_frame_id is not one ranger_base_node reads" in out, out
