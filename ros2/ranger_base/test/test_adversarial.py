"""The adversarial trial (issue 28) against ranger_base_node (ROS 2), on the virtual chassis of the
manual's reading (`sim`) and of the vendor's (`sim:agx_v2`), as the ROS 1 node's rostests do
(ranger_base/test/test_node_sim.cpp, Adversarial): each attack is judged by the chassis's ground
truth (sim/ground_truth) and what the node says (system_state), never by a log line.
  * NaN and infinities in each of the twist's six fields: nothing moves, system_state names the
    refusal (invalid_command, the field in the detail) for as long as it lasts;
  * e-stop, a remote takeover handed back, link loss: a zero twist and then 0.5 m/s for 4 s (40
    of the node's 10 Hz states) move nothing until resume; with rearm_on_zero_twist the zero
    twist re-arms;
  * sign flips as fast as the test can publish and two publishers fighting never exceed what was
    asked nor drive a direction neither asked;
  * bad service arguments are refused naming what is valid on that chassis;
  * odometry across `silent 2` while driving: system_state says the gap, odom's covariance grew.
  * after each attack the latest command drives (still_obeying); a silence of the link latched
    meanwhile (under load, or on purpose: `silent 0.5`) holds the chassis at rest until resume.
The robots are shared by the tests of this module (one node per chassis); the fixture hands each
test its robot at rest and armed, re-arming what an earlier test left latched (fleet). Durations
only pace the commands, as a teleop would."""

import itertools
import math
import os
import time

import pytest
from geometry_msgs.msg import Twist
from ranger_msgs.msg import SystemState
from ranger_msgs.srv import SetMotionMode
from std_srvs.srv import SetBool, Trigger

from support import Client, Robot

PORTS = ["sim", "sim:agx_v2"]
# As node_sim.test: the odometry's reach in a gap is max_linear_speed times the gap.
MAX_LINEAR_SPEED = 1.0
NODE_PARAMS = {"cmd_vel_timeout": 0.3, "max_linear_speed": MAX_LINEAR_SPEED,
               "max_speed_at_large_steering": MAX_LINEAR_SPEED}
FIELDS = [("linear", "x"), ("linear", "y"), ("linear", "z"),
          ("angular", "x"), ("angular", "y"), ("angular", "z")]
EXACT = 1e-9  # the virtual chassis at rest stands exactly still
_ns = itertools.count(1)


@pytest.fixture(scope="module")
def client(ros):
    """One client for the module's shared robots (conftest's is one per test)."""
    c = Client()
    yield c
    c.close()


@pytest.fixture(scope="module")
def fleet(client, tmp_path_factory):
    """fleet(port, **params): the module's robot on that chassis with those parameters, started
    once (the two plain ones at once, their start-ups overlapping), at rest and armed."""
    log_dir = str(tmp_path_factory.mktemp("adversarial"))
    robots = {}

    def start(port, params):
        key = (port, tuple(sorted(params.items())))
        if key not in robots:
            r = Robot(client, f"/adv{os.getpid()}_{next(_ns)}", log_dir, port_name=port,
                      **NODE_PARAMS, **params)
            client.listen(f"{r.ns}/system_state", SystemState, keep=True)
            robots[key] = r
        return robots[key]

    for port in PORTS:
        start(port, {})

    def get(port, **params):
        # Each test gets its robot at rest and armed, whatever the test before it left latched
        # (a silence under load beyond link_timeout latches rearm_required after link_lost):
        # the fixture re-arms it (settle) before it waits for the robot to be ready, never
        # handing one test's latch to the next.
        r = start(port, params)
        r.wait_state(lambda s: s.link_up and s.control_mode_name == "can"
                     and s.identification in ("", "decided"), 60, f"{r.ns} up")
        settle(r)
        r.wait_ready()
        return r
    yield get
    for r in robots.values():
        r.stop()


# ---- what the chassis did, what the node said ------------------------------------------------

def at_rest(r):
    t = r.truth().twist.twist
    return abs(t.linear.x) < EXACT and abs(t.linear.y) < EXACT and abs(t.angular.z) < EXACT


def settle(r):
    """At rest, the last refusal of the commander's own ended, re-armed if a stop latched."""
    r.client.wait_for(lambda: at_rest(r) and r.state().motion_inhibited_reason
                      != "invalid_command", 30, f"{r.ns} at rest", pace=lambda: r.send())
    def rearmed():
        # resume once the causes cleared; again if another silence under load latched anew.
        s = r.state()
        if s.rearm_required and s.link_up and not s.active_causes:
            r.client.call(Trigger, f"{r.ns}/resume", Trigger.Request())
            return False
        return not s.rearm_required
    r.client.wait_for(rearmed, 60, f"{r.ns} re-armed")


def history(r, topic):
    with r.client.lock:
        return list(r.client.history.get(f"{r.ns}/{topic}", []))


def mark(r):
    """Where the ground truth and system_state histories stand now."""
    return len(history(r, "sim/ground_truth")), len(history(r, "system_state"))


def truths_since(r, at):
    return history(r, "sim/ground_truth")[at[0]:]


def states_since(r, at):
    return history(r, "system_state")[at[1]:]


def twist(vx=0.0, vy=0.0, wz=0.0):
    t = Twist()
    t.linear.x, t.linear.y, t.angular.z = float(vx), float(vy), float(wz)
    return t


def drive_for_states(r, t, n):
    """Publishes `t` at 20 Hz (a teleop's pace) until the node said n more states; those."""
    at = mark(r)
    r.client.wait_for(lambda: len(states_since(r, at)) >= n, 30, f"{n} states",
                      pace=lambda: r.cmd.publish(t))
    return states_since(r, at)


def drive_until(r, t, predicate, what, timeout=30.0):
    r.client.wait_for(predicate, timeout, what, pace=lambda: r.cmd.publish(t))


def position(r):
    p = r.truth().pose.pose.position
    return p.x, p.y


def moved_since(r, at):
    x, y = position(r)
    return math.hypot(x - at[0], y - at[1])


def fastest(truths):
    """The largest |vx|, |vy|, |wz| the ground truth showed."""
    out = [0.0, 0.0, 0.0]
    for m in truths:
        t = m.twist.twist
        out = [max(out[0], abs(t.linear.x)), max(out[1], abs(t.linear.y)),
               max(out[2], abs(t.angular.z))]
    return out


def assert_within(truths, vx, vy, wz):
    """No ground truth faster than what was asked, in any of the three."""
    seen = fastest(truths)
    assert all(f <= limit + 1e-6 for f, limit in zip(seen, (vx, vy, wz))), (
        f"beyond what was asked: |vx|, |vy|, |wz| up to {seen}")


def still_obeying(r):
    """No fault, and the latest command drives: 0.3 m/s, then at rest. A silence of the link
    (the machine loaded beyond link_timeout while the attack ran) latches rearm_required after
    link_lost: the node must then not move, whatever the commander asks, until it is re-armed
    deliberately (resume), and obey after it (held_until_resume); any other latch fails."""
    assert not r.state().active_errors
    for _ in range(3):  # a silence may latch again while the commander drives: held again
        s = r.state()
        if s.rearm_required:
            assert list(s.latched_causes) == ["link_lost"], (
                "latched by the attack, not by a silence of the link", s)
            held_until_resume(r)
        drive_until(r, twist(0.3), lambda: abs(r.truth().twist.twist.linear.x - 0.3) < 0.01
                    or r.state().rearm_required, "obeying the latest command")
        if abs(r.truth().twist.twist.linear.x - 0.3) < 0.01:
            break
    else:
        raise AssertionError(f"{r.ns}: latched by a silence of the link at every attempt")
    stop_and_settle(r)


def held_until_resume(r):
    """After a silence of the link: once heard again and at rest, 0.3 m/s asked for five states
    moves nothing and every state says rearm_required; after resume, 0.3 m/s drives."""
    drive_until(r, twist(0.3), lambda: (lambda s: s.link_up and not s.active_causes)(r.state()),
                "the link heard again after its silence")
    drive_until(r, twist(0.3), lambda: at_rest(r),
                "at rest while latched after a silence of the link (asked 0.3 m/s, no resume)")
    at, start = position(r), mark(r)
    for s in drive_for_states(r, twist(0.3), 5):
        assert s.rearm_required, ("re-armed without resume after a silence of the link", s)
    assert max(fastest(truths_since(r, start))) < EXACT, "moved after a silence without resume"
    assert moved_since(r, at) < EXACT, "moved after a silence without resume"

    def resumed():  # the deliberate re-arm (again, should the link fall silent meanwhile)
        s = r.state()
        if s.rearm_required and s.link_up and not s.active_causes:
            r.client.call(Trigger, f"{r.ns}/resume", Trigger.Request())
        return not r.state().rearm_required
    r.client.wait_for(resumed, 60, f"{r.ns} re-armed by resume")


def drives(r, vx=0.5):
    drive_until(r, twist(vx), lambda: r.truth().twist.twist.linear.x > 0.8 * vx, "driving")


def stop_and_settle(r):
    drive_until(r, twist(), lambda: at_rest(r), "rest")
    settle(r)


# ---- the trial -------------------------------------------------------------------------------

@pytest.mark.parametrize("port", PORTS)
def test_a_non_finite_field_moves_nothing_and_is_named_while_it_lasts(fleet, port):
    r = fleet(port)
    for i, (part, axis) in enumerate(FIELDS):
        bad = math.inf if i % 2 else math.nan
        named = f"{part}.{axis} is " + ("NaN" if math.isnan(bad) else "infinite")
        t = twist(0.3)  # {linear: {x: 0.3, z: .nan}} and the like
        setattr(getattr(t, part), axis, bad)
        at, start = position(r), mark(r)
        r.wait_state(lambda s: s.motion_inhibited_reason == "invalid_command"
                     and named in s.motion_inhibited_detail, 10, named,
                     pace=lambda: r.cmd.publish(t))
        for s in drive_for_states(r, t, 8):  # for as long as it lasts
            assert s.motion_inhibited_reason == "invalid_command", (named, s)
            assert named in s.motion_inhibited_detail, s.motion_inhibited_detail
        assert max(fastest(truths_since(r, start))) < EXACT, named
        assert moved_since(r, at) < EXACT, named
        # The commander's next valid twist ends it (its own mistake: no re-arm needed).
        s = r.wait_state(lambda s: s.motion_inhibited_reason != "invalid_command", 10,
                         "the refusal ended", pace=lambda: r.send())
        assert s.motion_inhibited_reason in ("", "cmd_timeout") and not s.rearm_required, s
    drives(r, 0.3)
    stop_and_settle(r)


# An involuntary stop: the injection that starts it, the one that ends it (None: it ends by
# itself), the cause latched.
STOPS = [("emergency_stop", "estop on", "estop off"),
         ("remote", "remote on", "remote can"),  # handed back with SWB: CAN mode again
         ("link_lost", "silent 2", None)]


def stop_then_released(r, cause, begin, end):
    """Driving at 0.5 m/s, the stop; the commander keeps asking; the stop released: latched."""
    drives(r)
    r.inject(begin)
    drive_until(r, twist(0.5), lambda: r.state().rearm_required and
                cause in r.state().latched_causes, f"{cause} latched")
    if end:
        r.inject(end)
    drive_until(r, twist(0.5), lambda: (
        lambda s: s.link_up and s.control_mode_name == "can" and not s.active_causes
        and s.motion_inhibited_reason == "rearm_required" and cause in s.latched_causes)(
            r.state()) and at_rest(r), f"{cause} released, latched, at rest")


@pytest.mark.parametrize("port", PORTS)
def test_after_a_stop_a_zero_twist_and_four_seconds_of_motion_move_nothing_until_resume(
        fleet, port):
    r = fleet(port)
    for cause, begin, end in STOPS:
        stop_then_released(r, cause, begin, end)
        drive_for_states(r, twist(), 3)  # what a planner at its goal publishes
        at, start = position(r), mark(r)
        for s in drive_for_states(r, twist(0.5), 40):
            assert s.motion_inhibited_reason == "rearm_required", (cause, s)
            assert "call resume" in s.motion_inhibited_detail, s.motion_inhibited_detail
            assert "zero" not in s.motion_inhibited_detail, (
                "a zero cmd_vel is no re-arm: " + s.motion_inhibited_detail)
        assert max(fastest(truths_since(r, start))) < EXACT, f"{cause}: moved without resume"
        assert moved_since(r, at) < EXACT, cause
        answer = r.client.call(Trigger, f"{r.ns}/resume", Trigger.Request())
        assert answer.success, (cause, answer.message)
        drives(r)
        stop_and_settle(r)


def test_with_rearm_on_zero_twist_a_zero_twist_re_arms(fleet):
    r = fleet("sim", rearm_on_zero_twist=True)
    stop_then_released(r, "emergency_stop", "estop on", "estop off")
    at = position(r)
    drive_for_states(r, twist(0.5), 5)  # a moving twist alone re-arms nothing
    assert r.state().rearm_required and moved_since(r, at) < EXACT
    r.wait_state(lambda s: not s.rearm_required and s.motion_inhibited_reason != "rearm_required",
                 10, "re-armed by the zero twist", pace=lambda: r.send())
    drives(r)
    stop_and_settle(r)


@pytest.mark.parametrize("port", PORTS)
def test_sign_flips_as_fast_as_published_stay_within_what_was_asked(fleet, port):
    r = fleet(port)
    start = mark(r)
    for i in range(2000):  # up to 1 kHz, for about 2 s
        r.send(vx=0.5 if i % 2 else -0.5)
        time.sleep(0.001)
    assert_within(truths_since(r, start), 0.5, 0.0, 0.0)
    still_obeying(r)


@pytest.mark.parametrize("port", PORTS)
def test_two_publishers_fighting_never_drive_a_direction_neither_asked(fleet, port, client):
    r = fleet(port)
    other = client.node.create_publisher(Twist, f"{r.ns}/cmd_vel", 10)
    client.wait_for(lambda: other.get_subscription_count() > 0, what="the second publisher")
    start = mark(r)
    forward, spin = twist(0.4), twist(wz=0.5)
    # Forward at 20 Hz and a spin at 20 Hz, 25 ms apart, for 5 s: the latest one wins each time.
    for i in range(200):
        (r.cmd if i % 2 else other).publish(forward if i % 2 else spin)
        time.sleep(0.025)
    client.node.destroy_publisher(other)
    backwards = sideways = clockwise = 0.0
    for m in truths_since(r, start):
        t = m.twist.twist
        backwards = max(backwards, -t.linear.x)
        sideways = max(sideways, abs(t.linear.y))
        clockwise = max(clockwise, -t.angular.z)
    assert backwards <= 1e-6 and sideways <= 1e-6 and clockwise <= 1e-6, (
        backwards, sideways, clockwise)
    assert_within(truths_since(r, start), 0.4, 0.0, 0.5)
    still_obeying(r)


@pytest.mark.parametrize("port", PORTS)
def test_bad_service_arguments_are_refused_naming_what_is_valid_here(fleet, port, client):
    r = fleet(port)
    manual = port == "sim"
    at, start = position(r), mark(r)

    def set_mode(mode):
        return client.call(SetMotionMode, f"{r.ns}/set_motion_mode",
                           SetMotionMode.Request(mode=mode))
    unknown = set_mode(7)
    assert not unknown.success
    assert "0 (ackermann), 1 (oblique), 2 (spin)" in unknown.message, unknown.message
    assert ("side_slip" in unknown.message) == (not manual), (
        "side slip is valid only where the chassis has it: " + unknown.message)
    side_slip = set_mode(SetMotionMode.Request.SIDE_SLIP)
    if manual:
        assert not side_slip.success
        assert side_slip.message == ("side_slip: unsupported by protocol manual "
                                     "(it drives ackermann, oblique, spin)"), side_slip.message
    else:
        assert side_slip.success, side_slip.message
        assert set_mode(SetMotionMode.Request.AUTOMATIC).success
    release = client.call(SetBool, f"{r.ns}/park", SetBool.Request(data=False))
    if manual:  # no park to release: refused, never answered with success
        assert not release.success, release.message
        assert "park: unsupported by protocol manual" in release.message, release.message
    else:
        assert release.success, release.message
    drive_for_states(r, twist(), 3)
    assert max(fastest(truths_since(r, start))) < EXACT and moved_since(r, at) < EXACT
    drives(r, 0.3)
    stop_and_settle(r)


@pytest.mark.parametrize("port", PORTS)
def test_odometry_across_a_silence_says_the_gap_and_grows_the_covariance(fleet, port):
    r = fleet(port)
    drives(r)
    gaps = r.state().odometry_gaps
    variance = r.odom().pose.covariance[0]
    r.inject("silent 2")
    drive_until(r, twist(0.5), lambda: not r.state().link_up, "silent")
    drive_until(r, twist(0.5), lambda: (lambda s: s.link_up and s.motion_known
                                        and s.odometry_gaps > gaps)(r.state()), "heard again")
    s = r.state()
    assert s.odometry_gaps == gaps + 1
    assert s.odometry_gap >= 1.95, s.odometry_gap  # the silence, on the frames' clock
    end = s.odometry_gap_end.sec * 10**9 + s.odometry_gap_end.nanosec
    assert end > 0

    def odom_after_the_gap():
        stamp = r.odom().header.stamp
        return stamp.sec * 10**9 + stamp.nanosec >= end
    r.client.wait_for(odom_after_the_gap, 10, "odom after the gap")
    reach = MAX_LINEAR_SPEED * s.odometry_gap  # what the chassis could have moved in it
    covariance = r.odom().pose.covariance
    assert covariance[0] >= variance + reach * reach - 1e-6, (covariance[0], variance, reach)
    assert covariance[7] >= reach * reach - 1e-6, (covariance[7], reach)
    stop_and_settle(r)  # the link loss latched: settle resumes


@pytest.mark.parametrize("port", PORTS)
def test_after_a_silence_of_the_link_still_obeying_holds_until_resume(fleet, port):
    """still_obeying's re-arm after a silence of the link, on purpose (under load it comes by
    itself, mid-attack): the latch holds the chassis at rest while 0.3 m/s is asked, and resume
    alone re-arms it."""
    r = fleet(port)
    drives(r, 0.3)
    r.inject("silent 0.5")
    drive_until(r, twist(0.3), lambda: (lambda s: s.rearm_required
                                        and "link_lost" in s.latched_causes)(r.state()),
                "link_lost latched")
    still_obeying(r)
