"""ranger_minimal.launch sim:=true end to end: the TF tree the driver and robot_state_publisher
build from the URDF, the aggregated diagnostics, and the keyboard teleop (through a
pseudo-terminal) driving the virtual chassis in all three motion modes and stopping it."""

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import Launch, Latest, RosMaster, wait_for  # noqa: E402
from rostest_support import TeleopProcess  # noqa: E402

ACKERMANN, OBLIQUE, SPIN = 0, 1, 2  # ranger_msgs/SystemState.motion_mode
SPEED, SPIN_SPEED = 0.4, 0.6  # m/s, rad/s: the teleop's


@pytest.fixture(scope="module")
def sim():
    import rospy
    from nav_msgs.msg import Odometry
    from diagnostic_msgs.msg import DiagnosticArray
    from ranger_msgs.msg import SystemState
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage

    master = RosMaster()
    launch = Launch(master, "ranger_minimal.launch", "sim:=true", "log_output:=log")
    try:
        rospy.init_node("sim_bringup_test", anonymous=True, disable_signals=True)

        class Sim:
            pass

        s = Sim()
        s.master, s.launch = master, launch
        s.truth = Latest("/sim/ground_truth", Odometry)
        s.state = Latest("/system_state", SystemState)
        s.joints = Latest("/joint_states", JointState)
        s.diagnostics = Latest("/diagnostics_agg", DiagnosticArray)
        s.frames = {}  # child frame -> parent frame, from /tf and /tf_static

        def on_tf(msg):
            for t in msg.transforms:
                s.frames[t.child_frame_id] = t.header.frame_id

        s.tf_subs = [rospy.Subscriber(topic, TFMessage, on_tf, queue_size=100)
                     for topic in ("/tf", "/tf_static")]
        # CAN command mode, and the protocol settings identified (protocol auto, the default:
        # about 3.6 s after the chassis is first heard nothing is driven).
        launch.wait_until(
            lambda: s.state.get() is not None and s.state.get().control_mode == 1
            and s.state.get().identification == "decided", timeout=60)
        yield s
    finally:
        launch.stop()
        master.stop()


def test_tf_tree_reaches_every_urdf_link_from_odom(sim):
    import xml.etree.ElementTree as ET

    import rospy

    robot = ET.fromstring(rospy.get_param("/robot_description"))
    links = {link.get("name") for link in robot.findall("link")}
    assert wait_for(lambda: links - {"base_footprint"} <= set(sim.frames), timeout=30), (
        sorted(links - set(sim.frames)))
    assert sim.frames["base_footprint"] == "odom"  # the driver's odometry TF
    for link in links:  # every link chains up to odom
        frame, hops = link, 0
        while frame != "odom":
            frame, hops = sim.frames[frame], hops + 1
            assert hops < 10, f"{link} does not reach odom"


def test_joint_states_name_every_urdf_joint_that_moves(sim):
    import xml.etree.ElementTree as ET

    import rospy

    robot = ET.fromstring(rospy.get_param("/robot_description"))
    movable = {j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed"}
    assert wait_for(lambda: sim.joints.get() is not None, timeout=30)
    assert set(sim.joints.get().name) == movable


def test_diagnostics_are_aggregated_under_ranger(sim):
    wanted = {"/RANGER", "/RANGER/CAN link", "/RANGER/Control mode", "/RANGER/Protocol",
              "/RANGER/Chassis errors", "/RANGER/Battery", "/RANGER/Frame rates"}

    def names():
        msg = sim.diagnostics.get()
        return msg and {s.name: s for s in msg.status}

    stale = 3  # diagnostic_msgs/DiagnosticStatus.STALE: also what "Missing" items report

    def all_reported():
        n = names()
        return n and wanted <= set(n) and all(n[w].level != stale for w in wanted)

    # Until the node's first /diagnostics arrive the aggregator lists the expected items as
    # missing; then all of them must report.
    assert wait_for(all_reported, timeout=30), {
        k: v.message for k, v in (names() or {}).items() if k in wanted}
    assert names()["/RANGER/CAN link"].level == 0, names()["/RANGER/CAN link"].message
    # The identification's decision, with its evidence (protocol auto on the plain sim); the
    # aggregator publishes once a second, so its view may still show the identification going on.
    assert wait_for(lambda: names()["/RANGER/Protocol"].message == "identified: manual",
                    timeout=30), names()["/RANGER/Protocol"].message
    protocol = names()["/RANGER/Protocol"]
    assert protocol.level == 0, protocol.message
    values = {kv.key: kv.value for kv in protocol.values}
    assert values["Identification"] == "decided"
    assert "Evidence 1" in values


def moving(truth):
    t = truth.get().twist.twist
    return t.linear.x, t.linear.y, t.angular.z


# In this order, each key changes the motion mode (the driver keeps the oblique mode for a plain
# forward/backward request, so "x" comes after a spin, not after a crab).
@pytest.mark.parametrize("key,mode,axis,sign", [
    ("w", ACKERMANN, 0, +1), ("a", OBLIQUE, 1, +1), ("j", SPIN, 2, +1), ("d", OBLIQUE, 1, -1),
    ("l", SPIN, 2, -1), ("x", ACKERMANN, 0, -1)])
def test_teleop_drives_the_virtual_chassis_in_each_mode(sim, key, mode, axis, sign):
    teleop = TeleopProcess(sim.master, "/", speed=SPEED, spin_speed=SPIN_SPEED)
    try:
        assert wait_for(lambda: "RANGER keyboard teleop" in teleop.text(), timeout=30)

        wanted = [0.0, 0.0, 0.0]
        wanted[axis] = sign * (SPIN_SPEED if axis == 2 else SPEED)

        def held_until_moving_as_wanted():
            # The wheels steer while the body accelerates, so a crab starts diagonally: hold
            # until the steady state (about a second after the mode switch).
            teleop.hold(key, 0.1)
            state, v = sim.state.get(), moving(sim.truth)
            return (state.motion_mode == mode and not state.motion_mode_switching
                    and all(abs(a - b) < 0.05 for a, b in zip(v, wanted)))

        assert wait_for(held_until_moving_as_wanted, timeout=30, interval=0), (
            f"mode {sim.state.get().motion_mode_name}, twist {moving(sim.truth)} instead of "
            f"{wanted}\n" + teleop.text()[-500:])
        # Released: the chassis comes to rest (the teleop's stop, not a driver timeout).
        assert wait_for(lambda: max(abs(x) for x in moving(sim.truth)) < 0.01, timeout=30), (
            moving(sim.truth))
        teleop.type("\x03")
        assert teleop.wait_exit() == 0
    finally:
        teleop.close()


def test_quitting_the_teleop_while_moving_stops_the_chassis(sim):
    teleop = TeleopProcess(sim.master, "/", speed=SPEED, key_timeout=0.3, first_repeat_delay=5.0)
    try:
        assert wait_for(lambda: "RANGER keyboard teleop" in teleop.text(), timeout=30)
        # One press keeps moving for first_repeat_delay (5 s): quit before that.
        teleop.type("w")
        assert wait_for(lambda: moving(sim.truth)[0] > 0.1, timeout=30)
        teleop.type("\x03")
        assert teleop.wait_exit() == 0
        assert wait_for(lambda: max(abs(x) for x in moving(sim.truth)) < 0.01, timeout=30)
        assert "cmd_vel timeout" not in (sim.state.get().motion_inhibited_reason or "")
    finally:
        teleop.close()
