"""The binding's serialised odom, /tf and joint_states (ranger_can.MotionWireEncoder), which the
node publishes as bytes: read by this rmw as exactly the messages the node would otherwise publish
(conversions.MotionMessages), and byte for byte the rmw's own serialisation of them except where
the rmw leaves bytes unwritten (alignment padding, slack at the end: the encoder writes zeros and
no slack), for frame names of every length modulo the alignment, joint names of every prefix,
stamps and values of every sign; read back by rclpy as the values given; and the node's check
(conversions.motion_encoder) that falls back to messages when the rmw misreads the bytes.
cmd_vel's bytes (ranger_can.read_twist): the rmw's serialisation of every twist read bit for bit,
what the binding does not read handed to the rmw, and messages where the two disagree."""

import math
import random
import struct

import pytest
from nav_msgs.msg import Odometry
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

import ranger_can
from ranger_base import conversions

JOINTS = ranger_can.steering_joint_names() + ranger_can.wheel_joint_names()
FRAMES = [("odom", "base_link"), ("", ""), ("o", "b"), ("ab", "abc"), ("odom_", "base_lin"),
          ("robot_1/odom", "robot_1/base_footprint"), ("x" * 61, "y" * 7)]


def params_of(odom_frame, base_frame, rng):
    return {"odom_frame": odom_frame, "base_frame": base_frame,
            "pose_covariance_diagonal": [rng.uniform(0, 1) for _ in range(6)],
            "twist_covariance_diagonal": [rng.uniform(0, 1) for _ in range(6)]}


def random_values(rng):
    sec, nanosec = rng.randrange(0, 2**31), rng.randrange(0, 10**9)
    yaw = rng.uniform(-math.pi, math.pi)
    odometry = (sec, nanosec, rng.uniform(-1e4, 1e4), rng.uniform(-1e4, 1e4),
                math.sin(yaw / 2), math.cos(yaw / 2), rng.uniform(-3, 3), rng.uniform(-3, 3),
                rng.uniform(-2, 2), rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0, 1))
    joints = (sec, nanosec, [rng.uniform(-1e3, 1e3) for _ in range(8)],
              [rng.uniform(-50, 50) for _ in range(8)])
    return odometry, joints


def encoder_of(params, names=JOINTS):
    return ranger_can.MotionWireEncoder(
        params["odom_frame"], params["base_frame"], names, params["pose_covariance_diagonal"],
        params["twist_covariance_diagonal"])


@pytest.mark.parametrize("odom_frame,base_frame", FRAMES)
def test_bytes_are_the_rmws_own(odom_frame, base_frame):
    rng = random.Random(f"{odom_frame}|{base_frame}")
    params = params_of(odom_frame, base_frame, rng)
    for prefix in ("", "r", "ro", "rob", "robot_1/"):
        names = [prefix + n for n in JOINTS]
        encoder, reference = encoder_of(params, names), conversions.MotionMessages(params, names)
        for _ in range(5):
            odometry, joints = random_values(rng)
            reference.fill_odometry(odometry)
            reference.fill_joints(joints)
            for ours, theirs in ((encoder.odometry(odometry), reference.odom),
                                 (encoder.transform(odometry), reference.tf),
                                 (encoder.joint_state(joints), reference.joints)):
                assert deserialize_message(ours, type(theirs)) == theirs
                rmw = serialize_message(theirs)
                assert len(ours) <= len(rmw) <= len(ours) + 8
                differ = [i for i in range(len(ours)) if ours[i] != rmw[i] and ours[i] != 0]
                assert not differ, f"{type(theirs).__name__}: bytes {differ} differ"


def test_rclpy_reads_the_values_given():
    rng = random.Random(7)
    params = params_of("odom", "base_link", rng)
    encoder = encoder_of(params)
    odometry, joints = random_values(rng)
    sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw = odometry

    odom = deserialize_message(encoder.odometry(odometry), Odometry)
    assert (odom.header.stamp.sec, odom.header.stamp.nanosec) == (sec, nanosec)
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
    p = odom.pose.pose
    assert (p.position.x, p.position.y, p.position.z) == (x, y, 0.0)
    assert (p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w) == (0, 0, qz, qw)
    t = odom.twist.twist
    assert (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z) == (
        vx, vy, 0.0, 0.0, 0.0, wz)
    floor, twist_floor = params["pose_covariance_diagonal"], params["twist_covariance_diagonal"]
    added = [var_x, var_y, 0.0, 0.0, 0.0, var_yaw]
    for i in range(36):
        row, col = divmod(i, 6)
        assert odom.pose.covariance[i] == (floor[row] + added[row] if row == col else 0.0)
        assert odom.twist.covariance[i] == (twist_floor[row] if row == col else 0.0)

    tf = deserialize_message(encoder.transform(odometry), TFMessage)
    assert len(tf.transforms) == 1
    tr = tf.transforms[0]
    assert (tr.header.frame_id, tr.child_frame_id) == ("odom", "base_link")
    assert (tr.header.stamp.sec, tr.header.stamp.nanosec) == (sec, nanosec)
    assert (tr.transform.translation.x, tr.transform.translation.y) == (x, y)
    assert (tr.transform.rotation.z, tr.transform.rotation.w) == (qz, qw)

    js = deserialize_message(encoder.joint_state(joints), JointState)
    assert list(js.name) == JOINTS
    assert list(js.position) == joints[2] and list(js.velocity) == joints[3]
    assert list(js.effort) == []
    assert (js.header.stamp.sec, js.header.stamp.nanosec) == (sec, nanosec)


def test_the_node_uses_the_encoder_under_this_rmw():
    encoder, mismatch = conversions.motion_encoder(params_of("odom", "base_link", random.Random(1)),
                                                   JOINTS)
    assert mismatch is None
    assert isinstance(encoder, ranger_can.MotionWireEncoder)


@pytest.mark.parametrize("differs", ["odom", "/tf", "joint_states"])
def test_bytes_the_rmw_misreads_fall_back_to_messages(monkeypatch, differs):
    kinds = {"odom": Odometry, "/tf": TFMessage, "joint_states": JointState}

    def other_rmw(data, kind):
        msg = deserialize_message(data, kind)
        if kind is kinds[differs]:
            msg.header.stamp.sec += 1 if kind is not TFMessage else 0
            if kind is TFMessage:
                msg.transforms[0].transform.translation.z = 1.0
        return msg

    monkeypatch.setattr(conversions, "deserialize_message", other_rmw)
    encoder, mismatch = conversions.motion_encoder(
        params_of("odom", "base_link", random.Random(2)), JOINTS)
    assert encoder is None and mismatch == differs


def test_bytes_the_rmw_cannot_read_fall_back_to_messages(monkeypatch):
    def refusing_rmw(data, kind):
        raise RuntimeError("unknown encapsulation")

    monkeypatch.setattr(conversions, "deserialize_message", refusing_rmw)
    encoder, mismatch = conversions.motion_encoder(
        params_of("odom", "base_link", random.Random(3)), JOINTS)
    assert encoder is None and mismatch == "odom"


def test_bad_encoder_arguments_are_named():
    with pytest.raises(ranger_can.RangerError, match="joint_names must name the 8 joints"):
        ranger_can.MotionWireEncoder("odom", "base_link", JOINTS[:7], [0.0] * 6, [0.0] * 6)
    with pytest.raises(ranger_can.RangerError, match="covariance diagonal has 6 values, not 5"):
        ranger_can.MotionWireEncoder("odom", "base_link", JOINTS, [0.0] * 5, [0.0] * 6)


# cmd_vel's bytes (ranger_can.read_twist, through conversions.twist_reader): what the node reads
# for every command instead of a Python message.
def same_values(a, b):
    """Equal bit for bit, field by field (NaN equals NaN, -0.0 differs from 0.0)."""
    return len(a) == len(b) and all(struct.pack("<d", x) == struct.pack("<d", y)
                                    for x, y in zip(a, b))


def test_the_reader_reads_the_rmws_own_twists_bit_for_bit():
    rng = random.Random(4)
    specials = [0.0, -0.0, math.nan, math.inf, -math.inf, 5e-324, -1.7976931348623157e308]
    for i in range(300):
        values = tuple(rng.choice(specials) if rng.random() < 0.2 else
                       rng.uniform(-1e3, 1e3) * 10.0 ** rng.randint(-12, 12) for _ in range(6))
        data = serialize_message(conversions.twist_of(values))
        assert same_values(ranger_can.read_twist(data), values), (i, data.hex())


def test_the_node_reads_cmd_vel_bytes_under_this_rmw():
    read = conversions.twist_reader()
    assert read is not None
    values = (0.5, -0.25, 0.0, 0.0, 0.0, 1.5)
    assert read(serialize_message(conversions.twist_of(values))) == values


def test_bytes_the_reader_does_not_read_go_to_the_rmw(monkeypatch):
    """An encapsulation the binding does not read (read_twist gives None): the rmw reads it."""
    read = conversions.twist_reader()
    monkeypatch.setattr(ranger_can, "read_twist", lambda data: None)
    values = (0.125, 0.0, -1.0, 2.0, 0.0, -0.75)
    assert read(serialize_message(conversions.twist_of(values))) == values


def test_a_reader_that_misreads_this_rmw_means_messages(monkeypatch):
    real = ranger_can.read_twist

    def swapped(data):  # linear and angular the other way round
        v = real(data)
        return v[3:] + v[:3]
    monkeypatch.setattr(ranger_can, "read_twist", swapped)
    assert conversions.twist_reader() is None
