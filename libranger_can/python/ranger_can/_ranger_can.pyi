# Type stubs of the extension module (libranger_can/python/src/module.cpp).
from typing import Dict, List, Optional, Sequence, Tuple

__version__: str

class Odometry:
    x: float; y: float; yaw: float; vx: float; vy: float; wz: float
    stamp_ns: int  # the frames' time (wall clock), 0 = none yet
    distance: float
    pose_variance: Tuple[float, float, float]  # x, y, yaw
    twist_variance: Tuple[float, float, float]  # vx, vy, wz
    source: str  # "wheels" | "motion"
    steps: int
    last_gap: float  # s: the latest gap in the feedback, not integrated (its variance added)
    last_gap_end_ns: int  # the frame time the feedback returned after it, 0 = no gap yet
    gaps: int

class Joints:
    steering_names: List[str]; wheel_names: List[str]
    steering_position: List[float]; steering_velocity: List[float]
    wheel_position: List[float]; wheel_velocity: List[float]
    has_steering: bool; has_wheels: bool
    stamp_ns: int

class Motor:
    motor: int; joint: str; rpm: float; current: float; position: int
    driver_voltage: float; driver_temperature: float; motor_temperature: float
    driver_status: int; driver_status_names: List[str]
    high_speed_stamp_ns: int; low_speed_stamp_ns: int

class Battery:
    battery: int  # 0 = the pack, 1..4 the slots
    present: bool; soc: float; soh: float; voltage: float; current: float; temperature: float
    alarm1: int; alarm2: int; warning1: int; warning2: int
    alarms: List[str]; warnings: List[str]
    stamp_ns: int

class UltrasonicReading:
    sensor: int; raw: int; range: Optional[float]; status: str; stamp_ns: int

class Identification:
    phase: str; revision: str; message: str
    evidence: List[str]; undecided: List[str]; decided: List[Tuple[str, str]]
    confidence: float; done: bool; elapsed: float

class RemoteState:
    swa: str; swb: str; swc: str; swd: str
    left_vertical: float; left_horizontal: float; right_vertical: float
    right_horizontal: float; knob: float
    stamp_ns: int; received_ns: int

class Lights:
    can_control: bool; front: str; rear: str; front_brightness: int; rear_brightness: int

class FrameCount:
    id: int; name: str; frames: int; rejected: int; padded: int

class RequestOutcome:
    id: int; kind: str; what: str
    state: str  # "pending" | "sent" | "answered" | "failed"
    message: str
    error_word: Optional[int]
    @property
    def done(self) -> bool: ...

class Event:
    sequence: int
    time_ns: int  # the driver's (monotonic) clock
    kind: str  # event_kinds(): "link_silent", "refusal_changed", "shutdown_stop", ...
    severity: str  # "debug" | "info" | "warn" | "error"
    text: str  # the line for people
    json: str

class GroundTruth:
    x: float; y: float; yaw: float; vx: float; vy: float; wz: float
    distance_travelled: float; yaw_travelled: float
    control_mode: str; motion_mode: str; emergency_stop: bool; motion_allowed: bool
    motion_refused_reason: str; stamp_ns: int; lights: Lights

class SentMotion:
    vx: float; vy: float; wz: float; wall: float; shutdown: bool

class MotionUpdate:
    snapshot: Optional[Snapshot]  # None: nothing new (timeout, close, only frames sent)
    # (sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw); None when not new
    odometry: Optional[Tuple[int, int, float, float, float, float, float, float, float, float,
                             float, float]]
    # (sec, nanosec, positions, velocities): steering joints 1-4, then wheels 1-4; None: not new
    joints: Optional[Tuple[int, int, List[float], List[float]]]
    new_estimate: bool  # odometry or joints is new (snapshot is not None)
    sent: List[SentMotion]

class MotionWireEncoder:
    # The motion estimate as serialised ROS 2 messages (CDR little endian, as rclpy's
    # serialize_message gives them): what Publisher.publish takes as bytes. joint_names: the 8
    # joints in MotionUpdate.joints' order; the diagonals: 6 values each.
    def __init__(self, odom_frame: str, base_frame: str, joint_names: List[str],
                 pose_covariance_diagonal: List[float],
                 twist_covariance_diagonal: List[float]) -> None: ...
    def odometry(self, values: Tuple[int, int, float, float, float, float, float, float, float,
                                     float, float, float]) -> bytes: ...  # nav_msgs/Odometry
    def transform(self, values: Tuple[int, int, float, float, float, float, float, float, float,
                                      float, float, float]) -> bytes: ...  # tf2_msgs/TFMessage
    def joint_state(self, values: Tuple[int, int, List[float], List[float]]
                    ) -> bytes: ...  # sensor_msgs/JointState
    # (odom, tf, joint_states) of an update: the bytes of each new part, else None
    def encode(self, update: MotionUpdate
               ) -> Tuple[Optional[bytes], Optional[bytes], Optional[bytes]]: ...

# geometry_msgs/Twist's serialised bytes (CDR or XCDR2, either byte order) -> (linear x, y, z,
# angular x, y, z); None for what it does not read (the rmw's deserialize_message reads those).
def read_twist(data: bytes) -> Optional[Tuple[float, float, float, float, float, float]]: ...

class ParameterRow:
    # A row of the library's parameter table (frontend/node_parameters.hpp). type: bool, int,
    # double, string, double_list, string_list; table_type: the library's (seconds, choice, ...).
    name: str; type: str; table_type: str; unit: str; lo: float; hi: float; lo_open: bool
    hi_open: bool; has_range: bool; default: object; default_note: str; valid: str
    choices: List[str]; size: int; meaning: str; driver_setting: bool; markdown: str

class DiagnosticGroup:
    # A group of the library's diagnostics (control/diagnostics.hpp); level as
    # diagnostic_msgs numbers it (0 OK, 1 WARN, 2 ERROR, 3 STALE).
    name: str; level: int; level_name: str; message: str; values: List[Tuple[str, str]]
    hardware_id: str
    def value(self, key: str) -> Optional[str]: ...

class CliResult:
    exit_code: int; out: str; err: str

class BatteryReport:
    # sensor_msgs/BatteryState as the library says it (the pack's BMS, or the system status's
    # voltage alone); stamp_ns 0: none; status and health: the message's numbers.
    present: bool; stamp_ns: int
    voltage: float; current: float; temperature: float; percentage: float
    power_supply_status: int; power_supply_health: int
    cell_voltage: List[float]; cell_temperature: List[float]

class PublicationSchedule:
    # A fixed-rate schedule (times: time.monotonic() s): due from min(5 ms, period / 4) early;
    # after a stall from now.
    def __init__(self, rate_hz: float) -> None: ...
    def start(self, now: float) -> None: ...
    def due(self, now: float) -> bool: ...
    def advance(self, now: float, rate_hz: Optional[float] = ...) -> None: ...
    wake_at: float

class CmdVelTypeDecision:
    change: str  # "none", "taken" (none was), "switched" (auto: the other type)
    taken: Optional[str]  # the type taken from now on, in the rule's spelling; None: none yet
    stamped: Optional[bool]  # taken is TwistStamped; None: none yet
    line: str  # the one line to log at info; "": nothing to say

class CmdVelTypeRule:
    # Which message cmd_vel is taken as (cmd_vel_stamped "auto", "true" or "false"), type names
    # spelt as `spelling` has them ("ros2": geometry_msgs/msg/Twist; "ros1": geometry_msgs/Twist).
    def __init__(self, setting: str, spelling: str = ...) -> None: ...
    def start(self, publisher_types: List[str]) -> CmdVelTypeDecision: ...
    def on_publishers(self, publisher_types: List[str],
                      since_last_message: Optional[float] = ...) -> CmdVelTypeDecision: ...
    def on_message(self, type: str) -> CmdVelTypeDecision: ...
    follows_publishers: bool  # auto: the publishers matter
    setting: str
    taken: Optional[str]

class Snapshot:
    sequence: int; now_ns: int; port: str; bus_open: bool; read_only: bool; bus_error: str
    bus_state: str; link: str
    control_mode: Optional[str]; control_mode_raw: int
    vehicle_status: Optional[str]; vehicle_status_raw: Optional[int]
    motion_mode: Optional[str]; chassis_mode: Optional[str]; chassis_mode_raw: Optional[int]
    switching: bool; mode_override: Optional[str]
    refusal: str  # ranger_can.refusal_names(): "none", "estop", "rearm_required", ...
    refusal_detail: str  # what it means and what to do, in words ("" while driven)
    link_up: bool  # system_state's link_up
    motion_inhibited_reason: str  # system_state's: the refusal's name, "" while driven
    battery_report: BatteryReport  # sensor_msgs/BatteryState's facts
    rearm_required: bool; latched_causes: List[str]; active_causes: List[str]
    reclaim_blocked: bool; awaiting_command_mode: bool; cmd_timed_out: bool
    steer_first_factor: float
    faults: List[str]; error_word: int; error_layout: str; error_names: List[str]
    battery_voltage: Optional[float]; battery_soc: Optional[float]
    park_requested: bool; parked: bool; ultrasonic_enabled: Optional[bool]
    identifying: Optional[str]; standstill_probe: bool; quiet: bool; implausible_reason: str
    motion_known: bool
    odometry: Odometry; joints: Joints; motors: List[Motor]; batteries: List[Battery]
    ultrasonic: List[UltrasonicReading]
    protocol: str; profile: str; profile_revision: str
    drivable_modes: List[str]  # the motion modes the settings in use can drive
    identification: Optional[Identification]
    plausibility_warnings: List[str]; plausibility_stop: Optional[str]
    vendor_frames: str; remote: Optional[RemoteState]; lights: Optional[Lights]
    firmware_version: str; firmware_state: str
    drive_mode: Optional[str]; drive_mode_raw: Optional[int]
    wheel_odometers: Tuple[float, float, float, float]
    bms_alarms: List[str]; bms_warnings: List[str]
    frames: List[FrameCount]; requests: List[RequestOutcome]; loop_iterations: int

class _Session:
    def __init__(self, port: str, params: Dict[str, object], record_sent: bool = ...,
                 display_prefix: str = ...) -> None: ...
    def __getattr__(self, name: str): ...

def parameters() -> List[ParameterRow]: ...
def check_parameter(name: str, value: object) -> object: ...
def diagnostic_group_names() -> List[str]: ...
def model_names() -> List[str]: ...
def variant_names() -> List[str]: ...
def protocol_names() -> List[str]: ...
def motion_modes() -> List[str]: ...
def light_modes() -> List[str]: ...
# The numbers of ranger_msgs' SetMotionMode (None: automatic), SetLights, SetDriveMode.
def motion_mode_numbers() -> List[Tuple[int, Optional[str]]]: ...
def light_mode_numbers() -> List[Tuple[int, str]]: ...
def drive_mode_numbers() -> List[Tuple[int, str]]: ...
def refusal_names() -> List[str]: ...
def event_kinds() -> List[str]: ...
def fault_names() -> List[str]: ...
def driver_status_bit_names() -> List[str]: ...
def bms_status_bit_names() -> List[str]: ...
def chassis_command_names() -> List[str]: ...
def steering_joint_names() -> List[str]: ...
def wheel_joint_names() -> List[str]: ...
def cmd_vel_type_names(spelling: str = ...) -> List[str]: ...
def error_clear_description(code: int) -> str: ...
def unknown_motion_mode_number(number: int, snapshot: Snapshot) -> str: ...
def motion_mode_pinned(mode: Optional[str]) -> str: ...
def resume_refused_offline(snapshot: Snapshot, port: str) -> Optional[str]: ...
def resume_answered() -> str: ...
# Any request's answer (success, message) after the wait, by its kind: the ROS 1 node's words.
def request_answer(outcome: RequestOutcome) -> Tuple[bool, str]: ...
# The services' checks before anything is sent: why not (ending ": nothing sent"), or None.
def ultrasonic_request_refused(enable: bool, disable: bool) -> Optional[str]: ...
def lights_request_refused(front_mode: int, front_brightness: int, rear_mode: int,
                           rear_brightness: int) -> Optional[str]: ...
# SetDriveMode's number: the drive mode's name; RangerError naming the valid numbers.
def drive_mode_request(number: int) -> str: ...
# A service's answer as its one log line: (severity, text).
def answer_line(service: str, success: bool, message: str) -> Tuple[str, str]: ...
# The driver's event kinds that are a service's answer (not logged besides it).
def answer_event_kinds() -> List[str]: ...
# Row-major 6x6: `floor` on the diagonal plus the x, y, yaw variance.
def pose_covariance(floor: Sequence[float], variance: Sequence[float]) -> List[float]: ...
def diagonal_covariance(diagonal: Sequence[float]) -> List[float]: ...
# sensor_msgs/Range's range (REP-117): m; NaN for no reading; +inf beyond max_range.
def range_reading(raw: int, max_range: float) -> float: ...
# clear_errors' answer (success, message) from its outcome (answered, failed or unanswered) and
# the snapshot's error-word layout: the error word and its faults by name, or why not.
def clear_errors_answer(code: int, outcome: RequestOutcome,
                        snapshot: Snapshot) -> Tuple[bool, str]: ...
def error_names(error_word: int, layout: str) -> List[str]: ...
def _cli(args: List[str], input: str = ...) -> CliResult: ...
