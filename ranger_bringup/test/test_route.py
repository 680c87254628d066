"""The demo's route and its odometry-vs-ground-truth analysis, on synthetic tracks."""

import math
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "src"))
from ranger_bringup import route as R  # noqa: E402


def test_default_route_uses_every_mode_with_switches():
    R.validate_route(R.DEFAULT_ROUTE)
    assert {s.mode for s in R.DEFAULT_ROUTE} == {R.ACKERMANN, R.OBLIQUE, R.SPIN}
    assert R.mode_switches(R.DEFAULT_ROUTE) >= 3
    assert any(s.mode == R.ACKERMANN and s.wz != 0 for s in R.DEFAULT_ROUTE)  # an arc
    # Well under a minute of driving, leaving time for start-up and mode switches.
    assert sum(R.driving_time(s) for s in R.DEFAULT_ROUTE) <= 30


def test_each_spin_turns_what_its_label_says():
    """A spin's label names its angle, and the segment turns that angle (Segment.turn) instead of
    driving for a time."""
    words = {"a quarter turn": math.pi / 2, "half a turn": math.pi, "a full turn": 2 * math.pi}
    spins = [s for s in R.DEFAULT_ROUTE if s.mode == R.SPIN]
    assert spins
    for s in spins:
        named = [angle for text, angle in words.items() if text in s.label]
        assert named == [pytest.approx(s.turn)], s
        assert ("left" in s.label) == (s.wz > 0) and ("right" in s.label) == (s.wz < 0), s


def chassis_turn(segment, speed_up, slow_down, delay, dt=0.02):
    """The yaw (rad) a chassis turns under R.spin_rate: its yaw rate follows the command `delay` s
    late, at most speed_up / slow_down rad/s^2; braking to standstill after the last command is
    counted."""
    rate, yaw, queue = 0.0, 0.0, [0.0] * round(delay / dt)
    commanding = True
    for _ in range(round(60 / dt)):
        turned = yaw * math.copysign(1.0, segment.wz)
        command = R.spin_rate(segment, turned) if commanding else 0.0
        commanding = commanding and command != 0.0
        queue.append(command)
        target = queue.pop(0)
        limit = (speed_up if abs(target) > abs(rate) and target * rate >= 0 else slow_down) * dt
        rate += max(-limit, min(limit, target - rate))
        yaw += rate * dt
        if not commanding and rate == 0.0 and not any(queue):
            return yaw
    raise AssertionError("the chassis never stopped")


@pytest.mark.parametrize("speed_up,slow_down,delay", [
    (2.9, 5.7, 0.1),  # the virtual RANGER: 1 and 2 m/s^2 at the wheels, 0.35 m from the centre
    (1.0, 2.0, 0.2),  # a sluggish chassis
    (6.0, 6.0, 0.05),  # a brisk one
])
def test_a_spin_by_angle_ends_on_its_turn(speed_up, slow_down, delay):
    segment = next(s for s in R.DEFAULT_ROUTE if s.turn)
    turned = chassis_turn(segment, speed_up, slow_down, delay)
    assert math.degrees(turned) == pytest.approx(math.degrees(segment.turn), abs=2.5)
    mirrored = R.Segment("spin right", R.SPIN, wz=-segment.wz, turn=segment.turn)
    assert chassis_turn(mirrored, speed_up, slow_down, delay) == pytest.approx(-turned)


def test_spin_rate_slows_down_near_the_end_and_stops_there():
    segment = R.Segment("spin right half a turn", R.SPIN, wz=-0.9, turn=math.pi)
    assert R.spin_rate(segment, 0.0) == -0.9
    assert -0.9 < R.spin_rate(segment, math.pi - 0.5) < -R.MIN_SPIN_RATE
    assert R.spin_rate(segment, math.pi - 0.05) == -R.MIN_SPIN_RATE
    assert R.spin_rate(segment, math.pi) == 0.0
    assert R.spin_rate(segment, math.pi + 0.3) == 0.0


def test_yaw_change_is_signed_across_the_wrap():
    samples = [(0.0, 0, 0, 3.0), (1.0, 0, 0, -3.0), (2.0, 0, 0, -2.0)]
    assert R.yaw_change(samples) == pytest.approx(2 * math.pi - 6.0 + 1.0)
    assert R.yaw_change(list(reversed(samples))) == pytest.approx(-(2 * math.pi - 5.0))


@pytest.mark.parametrize("segment,message", [
    (R.Segment("x", R.SPIN, vx=0.1, wz=1.0), "spin needs"),
    (R.Segment("x", R.OBLIQUE, vy=0.1, wz=0.1), "crab needs"),
    (R.Segment("x", R.ACKERMANN, vy=0.1, vx=1.0), "Ackermann needs"),
    (R.Segment("x", R.ACKERMANN, vx=float("nan")), "finite"),
    (R.Segment("x", R.ACKERMANN, vx=1.0, duration=0), "duration"),
    (R.Segment("x", R.ACKERMANN, vx=1.0, turn=1.0), "a turn is a spin's"),
    (R.Segment("x", R.SPIN, wz=1.0, turn=-1.0), "a turn is a spin's"),
])
def test_inconsistent_segments_are_refused(segment, message):
    with pytest.raises(ValueError, match=message):
        R.validate_route([segment])


def test_pose_algebra_round_trips():
    a, b = (1.0, 2.0, 0.5), (-0.3, 0.7, -2.0)
    assert R.compose(a, R.between(a, b)) == pytest.approx(b)
    assert R.compose(a, R.inverse(a)) == pytest.approx((0, 0, 0))
    assert R.wrap(3 * math.pi) == pytest.approx(-math.pi)


def test_interpolation_handles_the_yaw_wrap():
    samples = [(0.0, 0.0, 0.0, math.pi - 0.1), (1.0, 1.0, 0.0, -math.pi + 0.1)]
    x, _, yaw = R.interpolate(samples, 0.5)
    assert x == pytest.approx(0.5)
    assert abs(R.wrap(yaw - math.pi)) == pytest.approx(0.0, abs=1e-9)
    assert R.interpolate(samples, -5)[0] == 0.0 and R.interpolate(samples, 5)[0] == 1.0


def circle(t_end, v, w, x0=0.0, y0=0.0, yaw0=0.0, dt=0.02, scale=1.0):
    """Samples of a body driving an arc; `scale` mimics odometry over-reading the distance."""
    samples, x, y, yaw, t = [], x0, y0, yaw0, 0.0
    while t <= t_end + 1e-9:
        samples.append((t, x, y, yaw))
        x += scale * v * math.cos(yaw) * dt
        y += scale * v * math.sin(yaw) * dt
        yaw = R.wrap(yaw + w * dt)
        t += dt
    return samples


def test_identical_tracks_have_no_error_even_from_different_origins():
    truth = circle(4.0, 0.5, 0.3)
    # Odometry started elsewhere (its own odom frame): same motion, other origin.
    odom = [(t,) + R.compose((5.0, -2.0, 1.0), (x, y, yaw)) for t, x, y, yaw in truth]
    windows = [(R.DEFAULT_ROUTE[1], 0.0, 2.0), (R.DEFAULT_ROUTE[1], 2.0, 4.0)]
    results = R.analyse(windows, odom, truth)
    for r in results:
        assert r.drift == pytest.approx(0, abs=1e-9) and r.error == pytest.approx(0, abs=1e-9)
        assert r.distance == pytest.approx(1.0, rel=0.02)
        assert r.turned == pytest.approx(0.6, rel=0.02)


def test_odometry_that_over_reads_shows_growing_error():
    truth = circle(4.0, 0.5, 0.0)
    odom = circle(4.0, 0.5, 0.0, scale=1.1)  # 10 % too far
    segment = R.Segment("straight", R.ACKERMANN, vx=0.5, duration=2.0)
    results = R.analyse([(segment, 0.0, 2.0), (segment, 2.0, 4.0)], odom, truth)
    assert results[0].drift == pytest.approx(0.1, rel=0.05)
    assert results[1].error == pytest.approx(0.2, rel=0.05)
    assert results[1].error > results[0].error
    text = R.summarise(results, odom, truth)
    assert "final pose error 0.2" in text and "Ackermann" in text
    assert "10.0 cm" in text  # the first segment drifted 10 cm


def test_summary_and_plot_cover_every_mode(tmp_path):
    truth = circle(6.0, 0.5, 0.2)
    odom = circle(6.0, 0.5, 0.21)
    segs = [R.Segment("a", R.ACKERMANN, vx=0.5, wz=0.2), R.Segment("c", R.OBLIQUE, vy=0.5),
            R.Segment("s", R.SPIN, wz=0.5)]
    windows = [(s, 2.0 * i, 2.0 * (i + 1)) for i, s in enumerate(segs)]
    results = R.analyse(windows, odom, truth)
    text = R.summarise(results, odom, truth)
    for title in R.MODE_TITLES.values():
        assert title in text
    png = tmp_path / "plot.png"
    R.plot(results, odom, truth, str(png))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10000
