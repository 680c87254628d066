"""Word-for-word parity of the ROS 2 node's answers with the library (frontend/answers.hpp through
the binding): every service's response message is the library's (the checks, the requests'
answers, the motion-mode words; the same functions test_node_answers.cpp holds the ROS 1 node
to), and each answer has exactly one log line, the library's answer_line of it. A front end that
re-words an answer, or logs one twice, fails here."""

import itertools
import os

import pytest
import rclpy
import ranger_can
from ranger_msgs.msg import SystemState
from ranger_msgs.srv import ClearErrors, SetDriveMode, SetLights, SetMotionMode, SetUltrasonic
from std_srvs.srv import SetBool, Trigger

from support import Client, Robot

_ns = itertools.count(1)


@pytest.fixture(scope="module", autouse=True)
def ros():
    rclpy.init()
    yield
    rclpy.shutdown()


@pytest.fixture
def client():
    c = Client()
    yield c
    c.close()


@pytest.fixture
def robot(client, tmp_path):
    r = Robot(client, f"/words{os.getpid()}_{next(_ns)}", str(tmp_path), port_name="sim",
              protocol="manual")
    client.listen(f"{r.ns}/system_state", SystemState, keep=True)
    yield r
    r.stop()


def flushed(r):
    """Two more system_state messages: whatever an answer given before logs is in the log."""
    def count():
        with r.client.lock:
            return len(r.client.history.get(f"{r.ns}/system_state", []))
    at = count()
    r.client.wait_for(lambda: count() >= at + 2, 30, "two more states")


def logged_once(r, service, answer):
    """The answer's one log line is the library's line of it (answer_line), once."""
    flushed(r)
    _, line = ranger_can.answer_line(service, bool(answer.success), answer.message)
    found = [l for l in r.process.output().splitlines()
             if l.rstrip().endswith("]: " + line) or ("]: " + line + "\x1b") in l]
    assert len(found) == 1, (service, line, found)


def test_every_answer_is_the_librarys_words_and_logged_once(robot):
    r = robot
    r.wait_ready()
    call = r.client.call
    # The checks, before anything is sent.
    a = call(SetLights, f"{r.ns}/set_lights", SetLights.Request(front_mode=7, rear_mode=1))
    assert (a.success, a.message) == (False, ranger_can.lights_request_refused(7, 0, 1, 0))
    logged_once(r, "set_lights", a)
    a = call(SetLights, f"{r.ns}/set_lights",
             SetLights.Request(front_mode=1, rear_mode=3, rear_brightness=101))
    assert (a.success, a.message) == (False, ranger_can.lights_request_refused(1, 0, 3, 101))
    logged_once(r, "set_lights", a)
    a = call(SetUltrasonic, f"{r.ns}/set_ultrasonic", SetUltrasonic.Request(enable=True,
                                                                            disable=True))
    assert (a.success, a.message) == (False, ranger_can.ultrasonic_request_refused(True, True))
    logged_once(r, "set_ultrasonic", a)
    a = call(SetDriveMode, f"{r.ns}/set_drive_mode", SetDriveMode.Request(mode=5))
    with pytest.raises(ranger_can.RangerError) as refused:
        ranger_can.drive_mode_request(5)
    assert (a.success, a.message) == (False, str(refused.value))
    logged_once(r, "set_drive_mode", a)
    # The motion modes.
    a = call(SetMotionMode, f"{r.ns}/set_motion_mode", SetMotionMode.Request(mode=7))
    with ranger_can.Driver("sim", protocol="manual", start=False) as manual:  # its profile
        words = ranger_can.unknown_motion_mode_number(7, manual.snapshot())
    assert (a.success, a.message) == (False, words)
    logged_once(r, "set_motion_mode", a)
    a = call(SetMotionMode, f"{r.ns}/set_motion_mode", SetMotionMode.Request(mode=2))
    assert (a.success, a.message) == (True, ranger_can.motion_mode_pinned("spin"))
    logged_once(r, "set_motion_mode", a)
    # The requests: the library's answer (resume re-armed), logged once each.
    a = call(Trigger, f"{r.ns}/resume", Trigger.Request())
    if a.success:
        assert a.message == ranger_can.resume_answered()
    logged_once(r, "resume", a)
    a = call(SetBool, f"{r.ns}/park", SetBool.Request(data=True))
    assert not a.success  # the manual's chassis has no park: the driver's words
    logged_once(r, "park", a)
    a = call(ClearErrors, f"{r.ns}/clear_errors", ClearErrors.Request(code=0))
    assert a.message.startswith("clear_errors code 0 ("), a.message
    logged_once(r, "clear_errors", a)
