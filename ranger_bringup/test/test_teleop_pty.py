"""Drives scripts/ranger_teleop_keyboard through a pseudo-terminal and checks the cmd_vel it
publishes: the three motion modes, the stop after the keys stop, the stop and the restored
terminal on exit (quit key and signals), and the refusal to run without a terminal."""

import os
import signal
import subprocess
import sys
import termios
import threading

import pytest

sys.path.insert(0, os.path.dirname(__file__))
from rostest_support import (PACKAGE_DIR, TELEOP, PtyProcess, RosMaster,  # noqa: E402
                             TeleopProcess, wait_for)

SPEED, SPIN, RADIUS = 0.4, 0.6, 2.0


@pytest.fixture(scope="module")
def master():
    m = RosMaster()
    yield m
    m.stop()


@pytest.fixture(scope="module")
def cmd_vel(master):
    import rospy
    from geometry_msgs.msg import Twist

    rospy.init_node("teleop_pty_test", anonymous=True, disable_signals=True)
    received = CmdVelLog()
    sub = rospy.Subscriber("/teleop_test/cmd_vel", Twist, received.add)
    yield received
    sub.unregister()


class CmdVelLog:
    def __init__(self):
        self.lock = threading.Lock()
        self.messages = []

    def add(self, msg):
        with self.lock:
            self.messages.append((msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x,
                                  msg.angular.y, msg.angular.z))

    def since(self, n):
        with self.lock:
            return list(self.messages[n:])

    def count(self):
        with self.lock:
            return len(self.messages)


@pytest.fixture
def teleop(master, cmd_vel):
    t = TeleopProcess(master, "/teleop_test", speed=SPEED, spin_speed=SPIN,
                      turn_radius=RADIUS)
    try:
        assert wait_for(lambda: "RANGER keyboard teleop" in t.text(), timeout=30), t.text()
        # Prime: press "w" until its cmd_vel reaches us (the connection takes a moment), then stop.
        n = cmd_vel.count()
        assert wait_for(lambda: (t.type("w"), moving(cmd_vel.since(n)))[1], timeout=30,
                        interval=0.2), t.text()
        t.type("s")
        assert wait_for(lambda: is_stop(cmd_vel.since(n)[-1]), timeout=10)
        yield t
    finally:
        t.close()


def is_stop(msg):
    return all(v == 0.0 for v in msg)


def moving(messages):
    return [m for m in messages if not is_stop(m)]


@pytest.mark.parametrize("key,expected,mode", [
    ("w", (SPEED, 0, 0, 0, 0, 0), "Ackermann"),
    ("q", (SPEED, 0, 0, 0, 0, SPEED / RADIUS), "Ackermann"),
    ("x", (-SPEED, 0, 0, 0, 0, 0), "Ackermann"),
    ("a", (0, SPEED, 0, 0, 0, 0), "crab"),
    ("d", (0, -SPEED, 0, 0, 0, 0), "crab"),
    ("j", (0, 0, 0, 0, 0, SPIN), "spin"),
    ("l", (0, 0, 0, 0, 0, -SPIN), "spin"),
])
def test_held_key_publishes_its_mode_then_a_stop_when_released(teleop, cmd_vel, key, expected,
                                                                mode):
    n = cmd_vel.count()
    teleop.hold(key, 1.0)
    assert wait_for(lambda: moving(cmd_vel.since(n)), timeout=10)
    for msg in moving(cmd_vel.since(n)):
        assert msg == pytest.approx(expected), msg
    # Released: the teleop itself sends the stop (well before the driver's cmd_vel_timeout
    # would have to).
    assert wait_for(lambda: is_stop(cmd_vel.since(n)[-1]), timeout=10), cmd_vel.since(n)[-5:]
    assert f"mode: {mode}" in teleop.text()


def test_the_rearm_key_calls_resume_and_shows_its_answer(teleop, cmd_vel):
    import rospy
    from std_srvs.srv import Trigger, TriggerResponse

    calls = []

    def resume(request):
        calls.append(request)
        return TriggerResponse(success=False,
                               message="resume refused: still active: emergency_stop")

    service = rospy.Service("/teleop_test/resume", Trigger, resume)
    try:
        n = cmd_vel.count()
        teleop.type("r")
        assert wait_for(lambda: calls, timeout=10), teleop.text()[-2000:]
        assert wait_for(lambda: "resume refused: still active: emergency_stop" in teleop.text(),
                        timeout=10), teleop.text()[-2000:]
        assert len(calls) == 1
        assert not moving(cmd_vel.since(n))
    finally:
        service.shutdown()


def test_moving_messages_keep_coming_while_the_key_is_held(teleop, cmd_vel):
    n = cmd_vel.count()
    teleop.hold("w", 1.5)
    during = cmd_vel.since(n)
    # Published at the teleop's rate (20 Hz) the whole time: many moving messages, no stop in
    # between (a stutter would show up as a stop followed by motion).
    first_stop = next((i for i, m in enumerate(during) if is_stop(m)), len(during))
    assert len(moving(during)) >= 5
    assert not moving(during[first_stop:])


def test_speed_up_changes_the_published_speed(teleop, cmd_vel):
    teleop.type("+")
    n = cmd_vel.count()
    teleop.hold("w", 0.6)
    assert wait_for(lambda: moving(cmd_vel.since(n)), timeout=10)
    assert moving(cmd_vel.since(n))[-1][0] == pytest.approx(SPEED * 1.1)
    teleop.type("-")
    n = cmd_vel.count()
    teleop.hold("w", 0.6)
    assert wait_for(lambda: moving(cmd_vel.since(n)), timeout=10)
    assert moving(cmd_vel.since(n))[-1][0] == pytest.approx(SPEED)


@pytest.mark.parametrize("how", ["ctrl-c", "sigint", "sigterm", "hangup"])
def test_exit_while_moving_sends_a_stop_and_restores_the_terminal(teleop, cmd_vel, how):
    n = cmd_vel.count()
    teleop.hold("j", 0.4)
    assert wait_for(lambda: moving(cmd_vel.since(n)), timeout=10)
    if how == "ctrl-c":
        teleop.type("\x03")
    elif how == "sigint":
        teleop.process.send_signal(signal.SIGINT)
    elif how == "sigterm":
        teleop.process.send_signal(signal.SIGTERM)
    else:
        teleop.process.send_signal(signal.SIGHUP)
    assert teleop.wait_exit() == 0, teleop.text()
    assert wait_for(lambda: is_stop(cmd_vel.since(n)[-1]), timeout=10)
    assert termios.tcgetattr(teleop.slave) == teleop.original
    assert "stopped" in teleop.text()


def test_without_a_terminal_it_refuses_to_start(master):
    result = subprocess.run(["/usr/bin/python3", TELEOP], stdin=subprocess.DEVNULL,
                            capture_output=True, text=True, env=master.env, timeout=60)
    assert result.returncode == 1
    assert "stdin is not a terminal" in result.stderr


@pytest.mark.parametrize("quit_key", ["\x03", "\x04"])  # Ctrl-C, Ctrl-D
def test_quitting_the_launched_teleop_ends_roslaunch_without_a_required_banner(master, quit_key):
    """ranger_teleop_keyboard.launch in a terminal: quitting the teleop is how a user ends it,
    so roslaunch ends by itself, cleanly, and prints no REQUIRED-process-died banner."""
    env = dict(master.env, ROS_PACKAGE_PATH=os.pathsep.join(
        [PACKAGE_DIR] + [p for p in master.env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]))
    launch = PtyProcess(["roslaunch", os.path.join(PACKAGE_DIR, "launch",
                                                   "ranger_teleop_keyboard.launch"),
                         "ns:=launched_teleop"], env)
    try:
        assert wait_for(lambda: "RANGER keyboard teleop" in launch.text(), timeout=60), \
            launch.text()
        launch.type(quit_key)
        assert launch.wait_exit(timeout=60) == 0, launch.text()
        assert "REQUIRED" not in launch.text()
        assert "all processes on machine have died" in launch.text()
    finally:
        launch.close()
