"""ranger_can values -> ROS 2 messages, field for field as the ROS 1 node fills them
(ranger_base/src/conversions.cpp). Names, units and signs all come from the library; this module
only places them. Stamps: a frame's time (bus clock = wall time) as it is.
"""

import math

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Quaternion, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.serialization import deserialize_message, serialize_message
from ranger_msgs.msg import (ActuatorState, ActuatorStateArray, BmsFlags, BmsState, BmsStateArray,
                             DriverStatus, RemoteState, SystemErrors, SystemState,
                             UltrasonicReading, UltrasonicState)
from sensor_msgs.msg import BatteryState, JointState, Range
from tf2_msgs.msg import TFMessage

import ranger_can

NAN = float("nan")


def to_time(stamp_ns: int) -> Time:
    return Time(sec=int(stamp_ns // 1_000_000_000), nanosec=int(stamp_ns % 1_000_000_000))


def yaw_quaternion(yaw: float) -> Quaternion:
    return Quaternion(z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0))


def _odometry(stamp_ns, params, pose, twist) -> Odometry:
    msg = Odometry()
    msg.header.stamp = to_time(stamp_ns)
    msg.header.frame_id = params["odom_frame"]
    msg.child_frame_id = params["base_frame"]
    msg.pose.pose.position.x, msg.pose.pose.position.y = pose[0], pose[1]
    msg.pose.pose.orientation = yaw_quaternion(pose[2])
    msg.twist.twist.linear.x, msg.twist.twist.linear.y = twist[0], twist[1]
    msg.twist.twist.angular.z = twist[2]
    return msg


class MotionMessages:
    """odom, its transform on /tf and joint_states, each allocated once and refilled from the
    binding's ready values (ranger_can.MotionUpdate.odometry, .joints) at every estimate: only
    the fields that change are set, and the transform shares the odometry's header and
    orientation. Pose covariance = diag(pose_covariance_diagonal) + the odometry's x/y/yaw
    variance; twist covariance = diag(twist_covariance_diagonal)."""

    def __init__(self, params, joint_names):
        self.odom = Odometry()
        self.odom.header.frame_id = params["odom_frame"]
        self.odom.child_frame_id = params["base_frame"]
        # The covariances are the library's (ranger_can.pose_covariance, diagonal_covariance).
        self._pose_floor = list(params["pose_covariance_diagonal"])
        self.odom.pose.covariance = ranger_can.pose_covariance(self._pose_floor, (0.0, 0.0, 0.0))
        self.odom.twist.covariance = ranger_can.diagonal_covariance(
            list(params["twist_covariance_diagonal"]))
        transform = TransformStamped()
        transform.header = self.odom.header
        transform.child_frame_id = self.odom.child_frame_id
        transform.transform.rotation = self.odom.pose.pose.orientation
        self.tf = TFMessage(transforms=[transform])
        self.joints = JointState(name=list(joint_names))
        self._stamp = self.odom.header.stamp
        self._position = self.odom.pose.pose.position
        self._orientation = self.odom.pose.pose.orientation
        self._translation = transform.transform.translation
        self._linear = self.odom.twist.twist.linear
        self._angular = self.odom.twist.twist.angular

    def fill_odometry(self, values):
        """values: (sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw)."""
        sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw = values
        self._stamp.sec, self._stamp.nanosec = sec, nanosec
        self._position.x = self._translation.x = x
        self._position.y = self._translation.y = y
        self._orientation.z, self._orientation.w = qz, qw
        self._linear.x, self._linear.y, self._angular.z = vx, vy, wz
        self.odom.pose.covariance = ranger_can.pose_covariance(self._pose_floor,
                                                               (var_x, var_y, var_yaw))

    def fill_joints(self, values):
        """values: (sec, nanosec, positions, velocities) in the order of the names."""
        sec, nanosec, position, velocity = values
        stamp = self.joints.header.stamp
        stamp.sec, stamp.nanosec = sec, nanosec
        self.joints.position = position
        self.joints.velocity = velocity


# Samples the encoder's bytes are compared on: odometry (sec, nanosec, x, y, qz, qw, vx, vy, wz,
# var_x, var_y, var_yaw) and joints (sec, nanosec, positions, velocities), negative values and
# stamps of every width among them.
_WIRE_SAMPLES = (
    ((1_795_000_000, 123_456_789, 12.5, -3.25, -0.6, 0.8, 0.5, -0.125, 0.75, 1e-4, 2.5e-4, 3e-5),
     (1_795_000_000, 5, [0.1, -0.2, 0.3, -0.4, 10.0, -20.0, 30.5, 1e6],
      [0.0, 1.0, -1.0, 0.5, 2.0, -2.0, 3.0, -3.0])),
    ((0, 0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0, 0, [0.0] * 8, [0.0] * 8)),
)


def motion_encoder(params, joint_names):
    """The binding's encoder of odom, /tf and joint_states (ranger_can.MotionWireEncoder: the
    messages serialised in C++, what Publisher.publish takes as bytes), if this ROS 2's rmw reads
    its bytes as exactly the messages MotionMessages makes of the same values (checked on samples
    with the rmw's own deserialisation: a distribution or rmw that reads them otherwise is caught
    here); else None, and the node publishes the messages themselves. Second: the topic whose
    bytes were misread, for the log."""
    encoder = ranger_can.MotionWireEncoder(
        params["odom_frame"], params["base_frame"], list(joint_names),
        list(params["pose_covariance_diagonal"]), list(params["twist_covariance_diagonal"]))
    reference = MotionMessages(params, joint_names)
    for odometry, joints in _WIRE_SAMPLES:
        reference.fill_odometry(odometry)
        reference.fill_joints(joints)
        for name, ours, theirs in (
                ("odom", encoder.odometry(odometry), reference.odom),
                ("/tf", encoder.transform(odometry), reference.tf),
                ("joint_states", encoder.joint_state(joints), reference.joints)):
            try:
                read = deserialize_message(ours, type(theirs))
            except Exception:  # noqa: BLE001 (any failure to read is a mismatch)
                return None, name
            if read != theirs:
                return None, name
    return encoder, None


# Twists the reader is compared on: (linear x, y, z, angular x, y, z), signs, magnitudes and
# special values of every kind among them.
_TWIST_SAMPLES = (
    (0.5, -0.25, 0.0, 0.0, 0.0, 1.5),
    (-1.0e-300, 3.0e300, -0.125, 7.0, -8.5, -0.0),
    (float("inf"), float("-inf"), 1.0, -1.0, 2.0, -2.0),
)


def twist_of(values) -> Twist:
    msg = Twist()
    (msg.linear.x, msg.linear.y, msg.linear.z,
     msg.angular.x, msg.angular.y, msg.angular.z) = values
    return msg


def twist_values(msg: Twist):
    """(linear x, y, z, angular x, y, z): what ranger_can.read_twist gives."""
    return (msg.linear.x, msg.linear.y, msg.linear.z,
            msg.angular.x, msg.angular.y, msg.angular.z)


def twist_reader():
    """cmd_vel's bytes -> twist_values: the binding's reader (ranger_can.read_twist: no Python
    message built for a command), with the rmw's deserialize_message for what it does not read
    (another encapsulation); None if this rmw serialises a Twist otherwise than the reader reads
    it (checked on samples: the node then subscribes with messages)."""
    for values in _TWIST_SAMPLES:
        if ranger_can.read_twist(serialize_message(twist_of(values))) != values:
            return None

    def read(data: bytes):
        values = ranger_can.read_twist(data)
        return values if values is not None else twist_values(deserialize_message(data, Twist))
    return read


def to_ground_truth(g, params) -> Odometry:
    """The virtual chassis's true pose and twist (zero covariance: exact)."""
    return _odometry(g.stamp_ns, params, (g.x, g.y, g.yaw), (g.vx, g.vy, g.wz))


def to_twist_stamped(sent, frame_id) -> TwistStamped:
    msg = TwistStamped()
    msg.header.stamp = to_time(int(sent.wall * 1e9))
    msg.header.frame_id = frame_id
    msg.twist.linear.x = sent.vx
    msg.twist.linear.y = sent.vy
    msg.twist.angular.z = sent.wz
    return msg


def _set_named(msg, names):
    for n in names:
        if hasattr(msg, n):
            setattr(msg, n, True)
    return msg


def to_system_state(s, stamp, detail: str) -> SystemState:
    msg = SystemState()
    msg.header.stamp = stamp
    msg.link_up = s.link_up
    msg.motion_known = s.motion_known
    if s.vehicle_status_raw is not None:
        msg.vehicle_status = s.vehicle_status_raw
        msg.vehicle_status_name = s.vehicle_status or "unknown"
        msg.control_mode = s.control_mode_raw
        msg.control_mode_name = s.control_mode or "unknown"
        msg.battery_voltage = float(s.battery_voltage or 0.0)
    else:
        msg.vehicle_status_name = msg.control_mode_name = "unknown"
    if s.chassis_mode_raw is not None:
        msg.motion_mode = s.chassis_mode_raw
        msg.motion_mode_name = s.chassis_mode or "unknown"
        msg.motion_mode_switching = s.switching
    else:
        msg.motion_mode_name = "unknown"
    msg.error_word = s.error_word
    msg.active_errors = list(s.error_names)
    msg.errors = _set_named(SystemErrors(), msg.active_errors)
    msg.motion_inhibited_reason = s.motion_inhibited_reason
    msg.motion_inhibited_detail = detail
    msg.protocol = s.protocol
    msg.protocol_profile = s.profile
    ident = s.identification
    msg.identification = ident.phase if ident is not None else ""
    msg.rearm_required = s.rearm_required
    msg.latched_causes = list(s.latched_causes)
    msg.active_causes = list(s.active_causes)
    msg.reclaim_blocked = s.reclaim_blocked
    msg.steer_first_factor = float(s.steer_first_factor)
    msg.park_requested = s.park_requested
    msg.parked = s.parked
    msg.firmware_version = s.firmware_version
    msg.firmware_version_state = s.firmware_state
    raw = s.drive_mode_raw
    msg.drive_mode = SystemState.DRIVE_MODE_NONE if raw is None else raw
    msg.drive_mode_name = s.drive_mode or ""
    (msg.front_left_distance, msg.front_right_distance, msg.rear_left_distance,
     msg.rear_right_distance) = s.wheel_odometers
    msg.bms_alarms = list(s.bms_alarms)
    msg.bms_warnings = list(s.bms_warnings)
    o = s.odometry  # the latest gap in the feedback (its variance is in odom's covariance)
    msg.odometry_gap = float(o.last_gap)
    msg.odometry_gap_end = to_time(o.last_gap_end_ns) if o.last_gap_end_ns > 0 else Time()
    msg.odometry_gaps = o.gaps
    return msg


def to_remote_state(r) -> RemoteState:
    msg = RemoteState()
    msg.header.stamp = to_time(r.stamp_ns)
    msg.swa, msg.swb, msg.swc, msg.swd = r.swa, r.swb, r.swc, r.swd
    msg.left_vertical = float(r.left_vertical)
    msg.left_horizontal = float(r.left_horizontal)
    msg.right_vertical = float(r.right_vertical)
    msg.right_horizontal = float(r.right_horizontal)
    msg.knob = float(r.knob)
    return msg


def to_actuator_state(motors, stamp) -> ActuatorStateArray:
    msg = ActuatorStateArray()
    msg.header.stamp = stamp
    for m in motors:
        a = ActuatorState(motor=m.motor, joint_name=m.joint, rpm=m.rpm, current=m.current,
                          position=m.position, driver_voltage=m.driver_voltage,
                          driver_temperature=m.driver_temperature,
                          motor_temperature=m.motor_temperature, driver_status=m.driver_status)
        a.driver_status_bits = _set_named(DriverStatus(), m.driver_status_names)
        a.high_speed_stamp = to_time(m.high_speed_stamp_ns)
        a.low_speed_stamp = to_time(m.low_speed_stamp_ns)
        msg.actuators.append(a)
    return msg


def to_bms_state(batteries, stamp) -> BmsStateArray:
    msg = BmsStateArray()
    msg.header.stamp = stamp
    for b in batteries:
        s = BmsState(battery=b.battery, present=b.present, soc=float(b.soc), soh=float(b.soh),
                     voltage=float(b.voltage), current=float(b.current),
                     temperature=float(b.temperature), alarm_status1=b.alarm1,
                     alarm_status2=b.alarm2, warning_status1=b.warning1,
                     warning_status2=b.warning2)
        s.header.stamp = to_time(b.stamp_ns)
        s.alarms = _set_named(BmsFlags(), b.alarms)
        s.warnings = _set_named(BmsFlags(), b.warnings)
        msg.batteries.append(s)
    return msg


def to_battery_state(s, stamp) -> BatteryState:
    """The library's battery report (ranger_can.Snapshot.battery_report: the pack from the BMS, or
    the system status's voltage alone; status and health as sensor_msgs numbers them), field for
    field."""
    r = s.battery_report
    msg = BatteryState()
    msg.header.stamp = to_time(r.stamp_ns) if r.stamp_ns > 0 else stamp
    msg.present = r.present
    msg.voltage, msg.current = float(r.voltage), float(r.current)
    msg.temperature, msg.percentage = float(r.temperature), float(r.percentage)
    msg.charge = msg.capacity = msg.design_capacity = NAN
    msg.power_supply_status = r.power_supply_status
    msg.power_supply_health = r.power_supply_health
    msg.power_supply_technology = BatteryState.POWER_SUPPLY_TECHNOLOGY_LIFE
    msg.location = "pack"
    msg.cell_voltage = [float(v) for v in r.cell_voltage]
    msg.cell_temperature = [float(t) for t in r.cell_temperature]
    return msg


def ultrasonic_frame_id(prefix, sensor) -> str:
    return f"{prefix}ultrasonic_{sensor}_link"


def to_ultrasonic_state(s, stamp) -> UltrasonicState:
    msg = UltrasonicState()
    msg.header.stamp = stamp
    msg.avoidance_known = s.ultrasonic_enabled is not None
    msg.avoidance_enabled = bool(s.ultrasonic_enabled)
    for u in s.ultrasonic:
        msg.sensors.append(UltrasonicReading(sensor=u.sensor, raw=u.raw,
                                             range=NAN if u.range is None else float(u.range),
                                             status=u.status))
    return msg


def to_range(u, params) -> Range:
    msg = Range()
    msg.header.stamp = to_time(u.stamp_ns)
    msg.header.frame_id = ultrasonic_frame_id(params["frame_prefix"], u.sensor)
    msg.radiation_type = Range.ULTRASOUND
    msg.field_of_view = float(params["ultrasonic/field_of_view"])
    msg.min_range = float(params["ultrasonic/min_range"])
    msg.max_range = float(params["ultrasonic/max_range"])
    # REP-117 as the library says it: NaN for no reading, +inf for nothing seen.
    msg.range = ranger_can.range_reading(u.raw, float(params["ultrasonic/max_range"]))
    return msg


def to_diagnostics(groups, stamp, node_name) -> DiagnosticArray:
    """The library's diagnostic groups (ranger_can.DiagnosticGroup: name, level, message,
    key/values, hardware_id) one to one onto diagnostic_msgs; each status named
    "<node_name>: <group>", as diagnostic_updater names its tasks."""
    msg = DiagnosticArray()
    msg.header.stamp = stamp
    msg.status = [DiagnosticStatus(level=bytes([g.level]), name=f"{node_name}: {g.name}",
                                   message=g.message, hardware_id=g.hardware_id,
                                   values=[KeyValue(key=k, value=v) for k, v in g.values])
                  for g in groups]
    return msg
