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
    assert sum(s.duration for s in R.DEFAULT_ROUTE) <= 30


@pytest.mark.parametrize("segment,message", [
    (R.Segment("x", R.SPIN, vx=0.1, wz=1.0), "spin needs"),
    (R.Segment("x", R.OBLIQUE, vy=0.1, wz=0.1), "crab needs"),
    (R.Segment("x", R.ACKERMANN, vy=0.1, vx=1.0), "Ackermann needs"),
    (R.Segment("x", R.ACKERMANN, vx=float("nan")), "finite"),
    (R.Segment("x", R.ACKERMANN, vx=1.0, duration=0), "duration"),
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
