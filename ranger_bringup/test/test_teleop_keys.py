"""The keyboard teleop's logic with a fake clock: modes, key repeat and timeout, speed steps."""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "src"))
from ranger_bringup.teleop_keys import (  # noqa: E402
    HELP, MOTION_KEYS, STOP, Command, Event, Mode, Settings, Teleop, split_keys)


@pytest.fixture
def teleop():
    return Teleop(Settings(speed=0.4, spin_speed=0.5, turn_radius=2.0, key_timeout=0.3,
                           first_repeat_delay=0.6))


def test_nothing_moves_before_a_key(teleop):
    assert teleop.command(0.0) == STOP
    assert teleop.command(100.0).is_stop()


@pytest.mark.parametrize("key,expected", [
    ("w", Command(linear_x=0.4, mode=Mode.ACKERMANN)),
    ("x", Command(linear_x=-0.4, mode=Mode.ACKERMANN)),
    ("q", Command(linear_x=0.4, angular_z=0.2, mode=Mode.ACKERMANN)),
    ("e", Command(linear_x=0.4, angular_z=-0.2, mode=Mode.ACKERMANN)),
    # Reversing along the left arc, as a car: backwards with the yaw rate negative.
    ("z", Command(linear_x=-0.4, angular_z=-0.2, mode=Mode.ACKERMANN)),
    ("c", Command(linear_x=-0.4, angular_z=0.2, mode=Mode.ACKERMANN)),
    ("a", Command(linear_y=0.4, mode=Mode.CRAB)),
    ("d", Command(linear_y=-0.4, mode=Mode.CRAB)),
    ("j", Command(angular_z=0.5, mode=Mode.SPIN)),
    ("l", Command(angular_z=-0.5, mode=Mode.SPIN)),
])
def test_each_motion_key_commands_its_mode(teleop, key, expected):
    assert teleop.on_key(key, 0.0) is Event.MOTION
    got = teleop.command(0.01)
    assert got.mode is expected.mode
    assert (got.linear_x, got.linear_y, got.angular_z) == pytest.approx(
        (expected.linear_x, expected.linear_y, expected.angular_z))


def test_spin_has_no_linear_velocity_and_crab_no_yaw(teleop):
    teleop.on_key("j", 0.0)
    spin = teleop.command(0.0)
    assert spin.linear_x == 0.0 and spin.linear_y == 0.0 and spin.angular_z > 0
    teleop.on_key("a", 0.1)
    crab = teleop.command(0.1)
    assert crab.linear_x == 0.0 and crab.angular_z == 0.0 and crab.linear_y > 0


def test_a_single_press_lasts_the_first_repeat_delay_then_stops(teleop):
    teleop.on_key("w", 10.0)
    assert not teleop.command(10.59).is_stop()  # auto-repeat has not started yet
    assert teleop.command(10.61) == STOP


def test_held_key_keeps_moving_and_stops_key_timeout_after_the_last_repeat(teleop):
    teleop.on_key("w", 0.0)
    t = 0.5  # auto-repeat starts after 0.5 s, then every 33 ms
    while t < 3.0:
        assert teleop.on_key("w", t) is Event.MOTION
        assert not teleop.command(t + 0.03).is_stop()
        t += 0.033
    last = t - 0.033
    assert not teleop.command(last + 0.29).is_stop()
    assert teleop.command(last + 0.31) == STOP
    # ... and stays stopped.
    assert teleop.command(last + 5.0) == STOP


def test_key_timeout_is_below_the_drivers_cmd_vel_timeout():
    assert Settings().key_timeout < 0.5


def test_switching_keys_switches_mode_immediately(teleop):
    teleop.on_key("w", 0.0)
    teleop.on_key("j", 0.1)
    assert teleop.command(0.1).mode is Mode.SPIN
    teleop.on_key("d", 0.2)
    assert teleop.command(0.2).mode is Mode.CRAB


@pytest.mark.parametrize("key", ["s", "k", " "])
def test_stop_keys_stop_at_once(teleop, key):
    teleop.on_key("w", 0.0)
    assert teleop.on_key(key, 0.1) is Event.STOP
    assert teleop.command(0.1) == STOP


@pytest.mark.parametrize("key", ["\x03", "\x04", "\x1b"])
def test_quit_keys_quit_and_stop(teleop, key):
    teleop.on_key("a", 0.0)
    assert teleop.on_key(key, 0.1) is Event.QUIT
    assert teleop.command(0.1) == STOP


def test_speed_steps_scale_both_speeds_within_limits():
    t = Teleop(Settings(speed=1.0, spin_speed=1.0, max_speed=1.2, max_spin_speed=1.05,
                        min_speed=0.1, speed_step=1.1))
    assert t.on_key("+", 0.0) is Event.SPEED
    assert (t.settings.speed, t.settings.spin_speed) == pytest.approx((1.1, 1.05))
    for _ in range(20):
        t.on_key("=", 0.0)
    assert (t.settings.speed, t.settings.spin_speed) == pytest.approx((1.2, 1.05))
    for _ in range(100):
        t.on_key("-", 0.0)
    assert (t.settings.speed, t.settings.spin_speed) == pytest.approx((0.1, 0.1))
    t.on_key("w", 1.0)
    assert t.command(1.0).linear_x == pytest.approx(0.1)


def test_speed_change_applies_to_the_motion_in_progress(teleop):
    teleop.on_key("w", 0.0)
    teleop.on_key("+", 0.1)
    assert teleop.command(0.1).linear_x == pytest.approx(0.44)


def test_initial_speeds_are_clamped_to_the_limits():
    t = Teleop(Settings(speed=5.0, spin_speed=0.01, max_speed=1.0, min_speed=0.05))
    assert (t.settings.speed, t.settings.spin_speed) == (1.0, 0.05)


def test_other_keys_are_ignored_and_do_not_stop_a_motion(teleop):
    teleop.on_key("w", 0.0)
    assert teleop.on_key("y", 0.1) is Event.IGNORED
    assert not teleop.command(0.1).is_stop()
    assert teleop.on_key("h", 0.1) is Event.HELP


@pytest.mark.parametrize("field,value", [
    ("speed", float("nan")), ("spin_speed", 0.0), ("turn_radius", -1.0),
    ("key_timeout", float("inf")), ("speed_step", 1.0), ("first_repeat_delay", 0.1)])
def test_bad_settings_are_refused_naming_the_setting(field, value):
    with pytest.raises(ValueError, match=field):
        Teleop(Settings(**{field: value}))


def test_status_line_shows_mode_and_speeds(teleop):
    teleop.on_key("d", 0.0)
    line = teleop.status_line(0.0)
    assert "mode: crab" in line and "y -0.40 m/s" in line and "speed 0.40 m/s" in line
    assert "mode: stopped" in teleop.status_line(10.0)


def test_help_names_every_motion_key(teleop):
    text = teleop.help_text()
    assert "%" not in text.replace("10 %", "")
    for key in MOTION_KEYS:
        assert key in text
    assert HELP.count("\n") == text.count("\n")


def test_split_keys_keeps_escape_sequences_whole():
    assert split_keys("w\x1b[Aa") == ["w", "\x1b[A", "a"]
    assert split_keys("\x1bOB") == ["\x1bOB"]
    assert split_keys("\x1b") == ["\x1b"]
    assert split_keys("\x03") == ["\x03"]


def test_arrow_keys_do_not_move_or_quit(teleop):
    for key in split_keys("\x1b[A\x1b[D"):
        assert teleop.on_key(key, 0.0) is Event.IGNORED
    assert teleop.command(0.0) == STOP


def test_the_rearm_key_asks_for_the_rearm_and_moves_nothing(teleop):
    assert teleop.on_key("r", 0.0) is Event.REARM
    assert teleop.command(0.01) == STOP
    # While moving, it changes nothing of the motion (the shell calls resume).
    teleop.on_key("w", 1.0)
    assert teleop.on_key("r", 1.1) is Event.REARM
    assert teleop.command(1.2).mode is Mode.ACKERMANN
    assert "r : re-arm" in teleop.help_text()
