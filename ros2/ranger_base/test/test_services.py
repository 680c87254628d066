"""Every service answered, whatever came before: each one called with a success, then a failure,
then a success on the same node, which goes on answering, publishing odometry and driving; each
answer has exactly one line in the node's log (the answer's words: the driver's events that are
the same answer are not logged again). rclpy keeps a logging call site's severity and refuses
another there (ValueError, on Jazzy where Kilted's deprecated warn() hid it): an info answer
after a warning one must still be answered and logged."""

import pytest
from nav_msgs.msg import Odometry
from ranger_msgs.msg import SystemState
from ranger_msgs.srv import ClearErrors, SetDriveMode, SetLights, SetMotionMode, SetUltrasonic
from std_srvs.srv import SetBool, Trigger

NS_PREFIX = "svc"


@pytest.fixture
def robot(robots):
    """robot(port, **params): a node whose states and odometry the client keeps, every one."""
    return lambda port, **params: robots(
        port, keep=[("system_state", SystemState), ("odom", Odometry)], **params)


def count(r, topic):
    with r.client.lock:
        return len(r.client.history.get(f"{r.ns}/{topic}", []))


def lines_with(r, message):
    return [line for line in r.process.output().splitlines() if message in line]


def flushed(r):
    """Two more system_state messages: the driver's events are logged after each one is
    published, so whatever line an answer given before this makes is in the log by then."""
    at = count(r, "system_state")
    r.client.wait_for(lambda: count(r, "system_state") >= at + 2, 30, "two more states")


def call_in_turn(r, calls):
    """Each (name, type, request, expected success) in turn: answered as expected, and on
    exactly one more line of the node's log."""
    for name, srv, request, success in calls:
        before = r.process.output()  # every line of the answers before (flushed after each)
        answer = r.client.call(srv, f"{r.ns}/{name}", request)
        assert answer.success == success, (name, answer.message)
        flushed(r)
        lines = lines_with(r, answer.message)
        earlier = sum(answer.message in line for line in before.splitlines())
        assert len(lines) == earlier + 1, (name, answer.message, lines)


def still_running(r):
    """Odometry flows and cmd_vel drives."""
    at = count(r, "odom")
    r.client.wait_for(lambda: count(r, "odom") >= at + 10, 30, "odometry flowing")
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, "driving",
                      pace=lambda: r.send(vx=0.4))
    r.client.wait_for(lambda: abs(r.truth().twist.twist.linear.x) < 1e-3, 30, "rest",
                      pace=lambda: r.send())


def S(name, srv, success, **fields):
    return (name, srv, srv.Request(**fields), success)


def test_every_service_success_failure_success_on_agx_v2(robot):
    r = robot("sim:agx_v2")
    r.wait_ready()
    lights = dict(front_mode=SetLights.Request.CUSTOM, front_brightness=40,
                  rear_mode=SetLights.Request.ON)
    call_in_turn(r, [
        S("clear_errors", ClearErrors, True, code=0),
        S("clear_errors", ClearErrors, False, code=0x42),  # no such code: nothing sent
        S("clear_errors", ClearErrors, True, code=0),
        S("set_ultrasonic", SetUltrasonic, True, enable=True),
        S("set_ultrasonic", SetUltrasonic, False, enable=True, disable=True),
        S("set_ultrasonic", SetUltrasonic, True, enable=True),
        S("set_motion_mode", SetMotionMode, True, mode=SetMotionMode.Request.SPIN),
        S("set_motion_mode", SetMotionMode, False, mode=99),
        S("set_motion_mode", SetMotionMode, True, mode=SetMotionMode.Request.AUTOMATIC),
        S("set_lights", SetLights, True, **lights),
        S("set_lights", SetLights, False, front_mode=9),
        S("set_lights", SetLights, True, **lights),
        S("set_drive_mode", SetDriveMode, False, mode=SetDriveMode.Request.VOLTAGE),  # agx_v2
        S("set_drive_mode", SetDriveMode, False, mode=7),
        S("park", SetBool, True, data=True),
        S("park", SetBool, True, data=False),
    ])
    # resume: a success, a failure (the e-stop is on), a success (the latch re-armed).
    call_in_turn(r, [S("resume", Trigger, True)])
    r.inject("estop on")
    r.wait_state(lambda s: s.motion_inhibited_reason == "estop", 10, "estop")
    call_in_turn(r, [S("resume", Trigger, False)])
    r.inject("estop off")
    r.wait_state(lambda s: s.rearm_required and not s.active_causes, 10, "latched")
    call_in_turn(r, [S("resume", Trigger, True)])
    still_running(r)
    assert "ValueError" not in r.process.output()


def test_drive_mode_and_park_success_failure_success(robot):
    """The services whose failure the agx_v2 chassis does not give by itself: drive mode on the
    MINI 3.0 (a success, an unknown mode, a success); park refused on the manual's chassis
    between two that are answered, on the same node: a refusal and an answer alike."""
    r = robot("sim:mini_v3", model="ranger_mini_v3")
    r.wait_ready()
    call_in_turn(r, [
        S("set_drive_mode", SetDriveMode, True, mode=SetDriveMode.Request.VOLTAGE),
        S("set_drive_mode", SetDriveMode, False, mode=7),
        S("set_drive_mode", SetDriveMode, True, mode=SetDriveMode.Request.CURRENT),
    ])
    still_running(r)
    m = robot("sim")
    m.wait_ready()
    call_in_turn(m, [
        S("set_ultrasonic", SetUltrasonic, True, enable=True),
        S("park", SetBool, False, data=True),  # unsupported by protocol manual
        S("set_ultrasonic", SetUltrasonic, True, disable=True),
        S("park", SetBool, False, data=True),
        S("clear_errors", ClearErrors, True, code=0),
    ])
    still_running(m)
    for node in (r, m):
        assert "ValueError" not in node.process.output()
