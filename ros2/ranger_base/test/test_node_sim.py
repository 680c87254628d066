"""ranger_base_node (ROS 2) against the in-process virtual chassis: the ROS 1 node's behaviour
suite where it applies. Each test runs the node as owners do, in a process of its own, under a
namespace of its own; discovery stays on this host (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST and
the stage's ROS_DOMAIN_ID, set by scripts/test_ros2.sh)."""

import math
import signal
import subprocess
import time

import pytest

import ranger_can
from ranger_msgs.msg import SystemState
from ranger_msgs.srv import ClearErrors, SetDriveMode, SetLights
from std_srvs.srv import SetBool, Trigger

from support import node_executable, ros_args, yaw


NS_PREFIX = "t"


def drive(robot, vx=0.0, vy=0.0, wz=0.0, distance=None, angle=None):
    start_dist, start_angle = robot.truth_path()

    def done():
        d, a = robot.truth_path()
        return (distance is not None and d - start_dist >= distance) or \
               (angle is not None and a - start_angle >= angle)
    robot.client.wait_for(done, 60, "the distance driven", pace=lambda: robot.send(vx, vy, wz))
    # Stop, and wait until the chassis is at rest and the odometry has seen it.
    robot.client.wait_for(lambda: abs(robot.truth().twist.twist.linear.x) < 1e-3
                          and abs(robot.truth().twist.twist.linear.y) < 1e-3
                          and abs(robot.truth().twist.twist.angular.z) < 1e-3
                          and abs(robot.odom().twist.twist.linear.x) < 1e-3
                          and abs(robot.odom().twist.twist.angular.z) < 1e-3,
                          30, "rest", pace=lambda: robot.send())


def assert_odometry_follows(robot):
    o, g = robot.odom().pose.pose, robot.truth().pose.pose
    dist, turned = robot.truth_path()
    error = math.hypot(o.position.x - g.position.x, o.position.y - g.position.y)
    assert error <= 0.01 * dist + 0.02, (error, dist)
    yaw_error = abs(math.remainder(yaw(o.orientation) - yaw(g.orientation), 2 * math.pi))
    assert yaw_error <= 0.01 * turned + 0.02, (yaw_error, turned)


@pytest.mark.parametrize("port,model,profile", [("sim", "ranger", "manual"),
                                                ("sim:agx_v2", "ranger", "agx_v2"),
                                                ("sim:mini_v3", "ranger_mini_v3", "mini_v3")])
def test_drives_every_mode_with_odometry_following_the_ground_truth(robots, port, model, profile):
    r = robots(port, model=model)
    s = r.wait_ready()
    assert s.protocol == "auto" and s.identification == "decided"
    assert s.protocol_profile == profile
    drive(r, vx=0.6, wz=0.2, distance=1.0)
    assert r.state().motion_mode_name == "ackermann"
    assert_odometry_follows(r)
    drive(r, vx=0.3, vy=0.3, distance=1.0)
    assert r.state().motion_mode_name == "oblique"
    assert_odometry_follows(r)
    drive(r, wz=0.5, angle=1.5)
    assert r.state().motion_mode_name == "spin"
    assert_odometry_follows(r)


def test_refuses_motion_while_identifying_then_drives(robots):
    r = robots("sim")
    s = r.wait_state(lambda s: s.identification not in ("", "decided"), 30, "identifying",
                     pace=lambda: r.send(vx=0.4))
    assert s.motion_inhibited_reason == "identifying"
    assert r.truth() is None or abs(r.truth().twist.twist.linear.x) < 1e-6
    r.wait_state(lambda s: s.identification == "decided", 60, "decided",
                 pace=lambda: r.send(vx=0.4))
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, "driving",
                      pace=lambda: r.send(vx=0.4))


def test_timeout_stops_the_chassis(robots):
    r = robots("sim")
    r.wait_ready()
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.3, 30, "driving",
                      pace=lambda: r.send(vx=0.4))
    s = r.wait_state(lambda s: s.motion_inhibited_reason == "cmd_timeout", 10, "timeout")
    assert not s.rearm_required
    r.client.wait_for(lambda: abs(r.truth().twist.twist.linear.x) < 1e-3, 10, "rest")


def test_estop_latches_until_resume(robots, client):
    r = robots("sim")
    r.wait_ready()
    r.inject("estop on")
    s = r.wait_state(lambda s: s.motion_inhibited_reason == "estop", 10, "estop")
    assert "emergency_stop" in s.active_causes
    refused = client.call(Trigger, f"{r.ns}/resume", Trigger.Request())
    assert not refused.success and "emergency_stop" in refused.message
    r.inject("estop off")
    s = r.wait_state(lambda s: s.motion_inhibited_reason == "rearm_required", 10, "latched",
                     pace=lambda: r.send(vx=0.3))
    assert s.rearm_required and "emergency_stop" in s.latched_causes
    end = time.monotonic() + 1.0
    while time.monotonic() < end:  # however long cmd_vel keeps coming
        r.send(vx=0.3)
        time.sleep(0.05)
    assert r.state().motion_inhibited_reason == "rearm_required"
    assert abs(r.truth().twist.twist.linear.x) < 1e-3
    assert client.call(Trigger, f"{r.ns}/resume", Trigger.Request()).success
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, "driving",
                      pace=lambda: r.send(vx=0.3))


def test_remote_control_takes_over_until_resume(robots, client):
    r = robots("sim")
    r.wait_ready()
    r.inject("remote on")
    s = r.wait_state(lambda s: s.motion_inhibited_reason == "remote", 10, "remote")
    assert s.control_mode_name == "remote"
    r.inject("remote can")
    r.wait_state(lambda s: s.motion_inhibited_reason == "rearm_required", 10, "rearm",
                 pace=lambda: r.send(vx=0.3))
    assert client.call(Trigger, f"{r.ns}/resume", Trigger.Request()).success
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, "driving",
                      pace=lambda: r.send(vx=0.3))


def test_clear_errors_answers_with_the_chassis_error_word(robots, client):
    """The library's answer (frontend/answers.hpp, as the ROS 1 node gives it): the error word
    the chassis answered with, its faults by name."""
    r = robots("sim")
    r.wait_ready()
    answer = client.call(ClearErrors, f"{r.ns}/clear_errors", ClearErrors.Request(code=0))
    assert answer.success, answer.message
    assert answer.message.startswith(
        f"clear_errors code 0 ({ranger_can.error_clear_description(0)}): the chassis answered "
        f"with error word {answer.error_word:#010x}"), answer.message
    assert answer.message.endswith("(no errors)") == (answer.error_word == 0)


def test_park_and_lights_on_agx_v2(robots, client):
    r = robots("sim:agx_v2")
    r.wait_ready()
    lights = client.call(SetLights, f"{r.ns}/set_lights", SetLights.Request(
        front_mode=SetLights.Request.CUSTOM, front_brightness=40,
        rear_mode=SetLights.Request.BREATHING))
    assert lights.success, lights.message
    assert (lights.front_mode, lights.front_brightness, lights.rear_mode) == (
        SetLights.Request.CUSTOM, 40, SetLights.Request.BREATHING)
    too_bright = client.call(SetLights, f"{r.ns}/set_lights", SetLights.Request(
        front_mode=SetLights.Request.CUSTOM, front_brightness=101))
    assert not too_bright.success and "brightness" in too_bright.message
    park = client.call(SetBool, f"{r.ns}/park", SetBool.Request(data=True))
    assert park.success, park.message
    r.wait_state(lambda s: s.parked and s.motion_inhibited_reason == "parked", 10, "parked",
                 pace=lambda: r.send(vx=0.3))
    assert abs(r.truth().twist.twist.linear.x) < 1e-3
    assert client.call(SetBool, f"{r.ns}/park", SetBool.Request(data=False)).success
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, "driving",
                      pace=lambda: r.send(vx=0.3))
    assert r.state().firmware_version == "ranger_sim 0.1.0"


def test_park_and_lights_refused_by_name_on_the_manuals_chassis(robots, client):
    r = robots("sim")
    r.wait_ready()
    lights = client.call(SetLights, f"{r.ns}/set_lights", SetLights.Request(front_mode=1))
    assert not lights.success and "unsupported by protocol manual" in lights.message
    park = client.call(SetBool, f"{r.ns}/park", SetBool.Request(data=True))
    assert not park.success and "park: unsupported" in park.message


def test_two_robots_in_namespaces_do_not_cross_talk(robots):
    a, b = robots("sim"), robots("sim")
    a.wait_ready()
    b.wait_ready()
    a.client.wait_for(lambda: a.truth().pose.pose.position.x > 0.3, 30, "robot a moved",
                      pace=lambda: a.send(vx=0.5))
    assert abs(b.truth().pose.pose.position.x) < 1e-3 and abs(b.odom().pose.pose.position.x) < 0.01


def test_bad_parameters_refuse_start_up_naming_each(tmp_path):
    params = {"port_name": "sim", "cmd_vel_timeout": 100.0, "publish_rate": 100.0,
              "model": "ranger_maxi", "wheelbase": -1.0, "base_frame": "odom",
              "spin_sign": "sideways"}
    result = subprocess.run([node_executable()] + ros_args(params, "/badparams"),
                            capture_output=True, text=True, timeout=60, check=False)
    out = result.stdout + result.stderr
    assert result.returncode == 2, out
    prefix = "parameter /badparams/ranger_base_node."
    for expected in (
            prefix + "cmd_vel_timeout = 100 is out of range: valid [0.02, 60] s",
            prefix + "publish_rate = 100 is out of range: valid (0, 50] Hz",
            prefix + "model = \"ranger_maxi\": expected one of ranger, ranger_mini_v1",
            prefix + "wheelbase = -1 is out of range: valid (0, 10] m",
            prefix + "base_frame = \"odom\" must differ from odom_frame",
            prefix + "spin_sign = \"sideways\": expected one of ccw, cw"):
        assert expected in out, out


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_shutdown_stops_the_chassis(robots, sig):
    r = robots("sim", publish_cmd=True)
    r.wait_ready()
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.3, 30, "driving",
                      pace=lambda: r.send(vx=0.5))
    for _ in range(5):
        r.send(vx=0.5)
    assert r.stop(sig) == 0
    log = r.process.output()
    assert "stop sent to the chassis" in log
    # The shutdown's stop is the last cmd_vel_out the node published.
    def last_is_zero():
        last = r.client.history[f"{r.ns}/cmd_vel_out"][-1]
        return last.twist.linear.x == 0.0 and last.twist.angular.z == 0.0
    r.client.wait_for(last_is_zero, 10, "the stop on cmd_vel_out")


def test_drive_mode_on_the_mini_v3_and_refused_by_name_elsewhere(robots, client):
    r = robots("sim:mini_v3", model="ranger_mini_v3")
    r.wait_ready()
    answer = client.call(SetDriveMode, f"{r.ns}/set_drive_mode",
                         SetDriveMode.Request(mode=SetDriveMode.Request.VOLTAGE))
    assert answer.success, answer.message
    assert answer.drive_mode == SystemState.DRIVE_MODE_VOLTAGE
    s = r.wait_state(lambda s: s.drive_mode_name == "voltage", 10, "voltage")
    assert s.drive_mode == SystemState.DRIVE_MODE_VOLTAGE
    bad = client.call(SetDriveMode, f"{r.ns}/set_drive_mode", SetDriveMode.Request(mode=7))
    assert not bad.success and "not one of 0 (CURRENT), 1 (VOLTAGE)" in bad.message
    other = robots("sim")
    other.wait_ready()
    refused = client.call(SetDriveMode, f"{other.ns}/set_drive_mode",
                          SetDriveMode.Request(mode=SetDriveMode.Request.CURRENT))
    assert not refused.success and "unsupported by protocol manual" in refused.message
    assert refused.drive_mode == SystemState.DRIVE_MODE_NONE
    assert other.state().drive_mode_name == ""


def test_diagnostics_are_the_librarys_groups_one_to_one(robots):
    """/diagnostics carries the library's groups (ranger_can's Driver.diagnostics, the ROS 1
    node's groups): the same names in the same order (as diagnostic_updater names them), the
    hardware_id ranger:<namespace>:<port>, the same keys, the level and message as they are."""
    from diagnostic_msgs.msg import DiagnosticArray
    r = robots("sim")
    r.client.listen("/diagnostics", DiagnosticArray, keep=True)
    r.wait_ready()
    hardware_id = f"ranger:{r.ns}:sim"

    def latest():
        for m in reversed(list(r.client.history.get("/diagnostics", []))):
            mine = [s for s in m.status if s.hardware_id == hardware_id]
            if mine:
                return mine
        return None

    def decided():
        values = {kv.key: kv.value for kv in latest()[2].values}
        link = {kv.key: kv.value for kv in latest()[0].values}
        return values.get("Identification") == "decided" and link["Chassis link"] == "connected"
    r.client.wait_for(decided, 30, "diagnostics of an identified chassis")
    node_groups = latest()
    with ranger_can.Driver("sim") as d:
        d.wait_ready(timeout=30)
        library = d.diagnostics(r.ns)
    assert [s.name for s in node_groups] == [f"ranger_base_node: {g.name}" for g in library]
    assert [g.name for g in library] == ranger_can.diagnostic_group_names()
    for status, group in zip(node_groups, library):
        if group.name in ("CAN link", "Control mode", "Chassis errors"):
            assert [kv.key for kv in status.values] == [k for k, _ in group.values], group.name
    link = node_groups[0]
    assert link.level == b"\x00", link
    assert {kv.key: kv.value for kv in link.values}["Port"] == "sim"
