"""Two virtual RANGERs on one ROS master (ranger_sim_two.launch: robot1 and robot2, one
diagnostics aggregator): each is driven by its own cmd_vel (one moves, the other stays put), each
has its own frames, and one aggregated diagnostics view shows both.

Each robot's diagnostics carry a hardware_id of their own ("ranger:/robot1:sim": the node's
namespace and port), and its ultrasonic Range frames the same prefix as odom_frame/base_frame
("robot1/ultrasonic_1_link": the launch file passes its frame_prefix to the node)."""

import math
import os
import sys
import threading

import pytest

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import Launch, Latest, RosMaster, wait_for  # noqa: E402

ROBOTS = ("robot1", "robot2")
STATUSES = ("CAN link", "Control mode", "Protocol", "Chassis errors", "Battery", "Frame rates")


@pytest.fixture(scope="module")
def fleet():
    import rospy
    from diagnostic_msgs.msg import DiagnosticArray
    from nav_msgs.msg import Odometry
    from ranger_msgs.msg import SystemState
    from sensor_msgs.msg import Range

    master = RosMaster()
    launch = Launch(master, "ranger_sim_two.launch", "log_output:=log")
    try:
        rospy.init_node("two_robots_test", anonymous=True, disable_signals=True)

        class Fleet:
            pass

        f = Fleet()
        f.launch = launch
        f.truth = {r: Latest(f"/{r}/sim/ground_truth", Odometry) for r in ROBOTS}
        f.odom = {r: Latest(f"/{r}/odom", Odometry) for r in ROBOTS}
        f.state = {r: Latest(f"/{r}/system_state", SystemState) for r in ROBOTS}
        f.range = {r: Latest(f"/{r}/ultrasonic/range_1", Range) for r in ROBOTS}
        f.aggregated = Latest("/diagnostics_agg", DiagnosticArray)
        f.raw = RawDiagnostics()
        # Both in CAN command mode with their protocol settings identified (protocol auto).
        launch.wait_until(lambda: all(
            f.state[r].get() is not None and f.state[r].get().control_mode == 1
            and f.state[r].get().identification == "decided" for r in ROBOTS),
            timeout=90)
        yield f
    finally:
        launch.stop()
        master.stop()


class RawDiagnostics:
    """Every status name on /diagnostics with the hardware_id it was last reported with."""

    def __init__(self):
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray

        self.lock = threading.Lock()
        self.hardware_ids = {}
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self._on, queue_size=50)

    def _on(self, msg):
        with self.lock:
            for s in msg.status:
                self.hardware_ids[s.name] = s.hardware_id

    def get(self):
        with self.lock:
            return dict(self.hardware_ids)


def moved(msg):
    p = msg.pose.pose.position
    return math.hypot(p.x, p.y)


def test_each_robot_is_driven_by_its_own_cmd_vel(fleet):
    import rospy
    from geometry_msgs.msg import Twist

    start = {r: moved(fleet.truth[r].get()) for r in ROBOTS}
    pub = rospy.Publisher("/robot1/cmd_vel", Twist, queue_size=1)
    twist = Twist()
    twist.linear.x = 0.4
    stop = threading.Event()

    def drive():
        while not stop.is_set():
            pub.publish(twist)
            stop.wait(0.05)

    driver = threading.Thread(target=drive, daemon=True)
    driver.start()
    try:
        fleet.launch.wait_until(lambda: moved(fleet.truth["robot1"].get()) > start["robot1"] + 0.3,
                                timeout=60)
    finally:
        stop.set()
        driver.join()
        pub.unregister()
    # robot1 moved and its odometry saw it; robot2 (chassis and odometry) did not move at all.
    assert wait_for(lambda: moved(fleet.odom["robot1"].get()) > 0.25, timeout=20)
    assert moved(fleet.truth["robot2"].get()) == pytest.approx(start["robot2"], abs=1e-6)
    assert moved(fleet.odom["robot2"].get()) < 1e-3


def test_each_robot_has_its_own_frames(fleet):
    for r in ROBOTS:
        odom = fleet.odom[r].get()
        assert odom.header.frame_id == f"{r}/odom"
        assert odom.child_frame_id == f"{r}/base_footprint"


def test_one_aggregated_view_shows_both_robots(fleet):
    wanted = {f"/RANGER/{r}/{s}" for r in ROBOTS for s in STATUSES}

    def names():
        msg = fleet.aggregated.get()
        return {s.name for s in msg.status} if msg else set()

    fleet.launch.wait_until(lambda: wanted <= names(), timeout=30)


def test_each_robot_reports_its_own_hardware_id(fleet):
    assert wait_for(lambda: all(f"{r}/ranger_base_node: CAN link" in fleet.raw.get()
                                for r in ROBOTS), timeout=30)
    ids = fleet.raw.get()
    assert ids["robot1/ranger_base_node: CAN link"] != ids["robot2/ranger_base_node: CAN link"]
    assert ids["robot1/ranger_base_node: CAN link"] == "ranger:/robot1:sim"


def test_ultrasonic_frames_are_prefixed_like_every_other_frame(fleet):
    assert wait_for(lambda: all(fleet.range[r].get() for r in ROBOTS), timeout=30)
    for r in ROBOTS:
        assert fleet.range[r].get().header.frame_id == f"{r}/ultrasonic_1_link"
