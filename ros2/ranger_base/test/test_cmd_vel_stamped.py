"""cmd_vel as geometry_msgs/Twist or TwistStamped (cmd_vel_stamped: auto, the default, takes the
type of the topic's publishers and follows them when they all use the other; true; false). A
stamped twist older than cmd_vel_timeout is not obeyed (system_state: stale_command, in the
library's words); a zero stamp means now. Judged by the virtual chassis's ground truth and by
system_state, never by a wall-clock duration."""

import os

import pytest
import rclpy
from geometry_msgs.msg import Twist, TwistStamped

NS_PREFIX = "st"


@pytest.fixture
def robot(robots):
    """robot(cmd_type=Twist, **params): a node on `sim`."""
    return lambda cmd_type=Twist, **params: robots("sim", cmd_type=cmd_type, **params)


def stamped(client, vx, age=0.0, zero=False):
    m = TwistStamped()
    if not zero:
        now = client.node.get_clock().now().nanoseconds - int(age * 1e9)
        m.header.stamp.sec, m.header.stamp.nanosec = divmod(now, 10**9)
    m.twist.linear.x = float(vx)
    return m


def plain(vx):
    t = Twist()
    t.linear.x = float(vx)
    return t


def drives(r, pub, make, what):
    r.client.wait_for(lambda: r.truth().twist.twist.linear.x > 0.2, 30, what,
                      pace=lambda: pub.publish(make()))


def rests(r, pub, make, what):
    r.client.wait_for(lambda: abs(r.truth().twist.twist.linear.x) < 1e-3, 30, what,
                      pace=lambda: pub.publish(make()))


def test_stamped_drives_a_stale_stamp_does_not_and_a_zero_stamp_is_now(robot, client):
    r = robot(cmd_type=None, cmd_vel_stamped=True, cmd_vel_timeout=0.5)
    r.wait_ready()
    pub = client.node.create_publisher(TwistStamped, f"{r.ns}/cmd_vel", 10)
    drives(r, pub, lambda: stamped(client, 0.4), "driving on fresh stamps")
    # Stamped a second ago: older than cmd_vel_timeout, so not obeyed, and said.
    s = r.wait_state(lambda s: s.motion_inhibited_reason == "stale_command", 30, "stale_command",
                     pace=lambda: pub.publish(stamped(client, 0.4, age=1.0)))
    assert "older than cmd_vel_timeout" in s.motion_inhibited_detail, s.motion_inhibited_detail
    rests(r, pub, lambda: stamped(client, 0.4, age=1.0), "rest on stale stamps")
    drives(r, pub, lambda: stamped(client, 0.4, zero=True), "driving on zero stamps")
    assert r.state().motion_inhibited_reason != "stale_command"
    assert "TwistStamped (cmd_vel_stamped true)" in r.process.output()


def test_plain_drives_with_cmd_vel_stamped_false(robot, client):
    r = robot(cmd_vel_stamped=False)
    r.wait_ready()
    drives(r, r.cmd, lambda: plain(0.4), "driving on Twist")
    assert "Twist (cmd_vel_stamped false)" in r.process.output()


def test_auto_follows_a_publisher_of_each_type_in_turn(robot, client):
    r = robot(cmd_type=None)  # cmd_vel_stamped: auto, the default; no publisher yet
    r.wait_ready()
    assert "no publisher yet" in r.process.output()
    for msg_type, make in ((TwistStamped, lambda: stamped(client, 0.4)),
                           (Twist, lambda: plain(0.4)),
                           (TwistStamped, lambda: stamped(client, 0.4, zero=True))):
        # A participant of its own for each publisher (a teleop, then a planner, ...): a
        # participant keeps a topic's first type.
        context = rclpy.Context()
        rclpy.init(context=context)
        node = rclpy.create_node(f"cmd_vel_{msg_type.__name__}_{os.getpid()}", context=context)
        try:
            pub = node.create_publisher(msg_type, f"{r.ns}/cmd_vel", 10)
            drives(r, pub, make, f"driving on {msg_type.__name__}")
            rests(r, pub, lambda: msg_type(), f"rest on a zero {msg_type.__name__}")
        finally:
            node.destroy_node()
            context.try_shutdown()
    out = r.process.output()
    assert out.count("TwistStamped (cmd_vel_stamped auto: the type of its publishers)") == 2, out
    assert out.count("Twist (cmd_vel_stamped auto: the type of its publishers)") == 1, out
