# Type stubs of the ranger_can package (libranger_can/python/ranger_can/__init__.py).
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Tuple

from ._errors import RangerError as RangerError, RequestFailed as RequestFailed
from ._errors import RequestTimeout as RequestTimeout
from ._ranger_can import (Battery as Battery, Event as Event, event_kinds as event_kinds, FrameCount as FrameCount, GroundTruth as GroundTruth,
                          Identification as Identification, Joints as Joints, Lights as Lights,
                          Motor as Motor, MotionUpdate as MotionUpdate,
                          MotionWireEncoder as MotionWireEncoder, read_twist as read_twist,
                          Odometry as Odometry, ParameterRow as ParameterRow,
                          DiagnosticGroup as DiagnosticGroup,
                          check_parameter as check_parameter,
                          diagnostic_group_names as diagnostic_group_names,
                          RemoteState as RemoteState, RequestOutcome as RequestOutcome,
                          SentMotion as SentMotion, Snapshot as Snapshot,
                          UltrasonicReading as UltrasonicReading, __version__ as __version__,
                          bms_status_bit_names as bms_status_bit_names,
                          chassis_command_names as chassis_command_names,
                          driver_status_bit_names as driver_status_bit_names,
                          error_clear_description as error_clear_description,
                          error_names as error_names, fault_names as fault_names,
                          light_modes as light_modes, model_names as model_names,
                          motion_mode_pinned as motion_mode_pinned,
                          resume_answered as resume_answered,
                          request_answer as request_answer,
                          ultrasonic_request_refused as ultrasonic_request_refused,
                          lights_request_refused as lights_request_refused,
                          drive_mode_request as drive_mode_request,
                          answer_line as answer_line, answer_event_kinds as answer_event_kinds,
                          pose_covariance as pose_covariance,
                          diagonal_covariance as diagonal_covariance,
                          range_reading as range_reading, BatteryReport as BatteryReport,
                          PublicationSchedule as PublicationSchedule,
                          CmdVelTypeRule as CmdVelTypeRule,
                          CmdVelTypeDecision as CmdVelTypeDecision,
                          cmd_vel_type_names as cmd_vel_type_names,
                          clear_errors_answer as clear_errors_answer,
                          resume_refused_offline as resume_refused_offline,
                          unknown_motion_mode_number as unknown_motion_mode_number,
                          motion_mode_numbers as motion_mode_numbers,
                          light_mode_numbers as light_mode_numbers,
                          drive_mode_numbers as drive_mode_numbers,
                          motion_modes as motion_modes, parameters as parameters,
                          protocol_names as protocol_names, refusal_names as refusal_names,
                          steering_joint_names as steering_joint_names,
                          variant_names as variant_names, wheel_joint_names as wheel_joint_names)

class Driver:
    port: str
    model: str
    protocol: str
    protocol_source: str
    startup_lines: List[Tuple[str, str]]  # (severity, text): the model and the protocol settings
    is_sim: bool
    stop_sent: bool
    closed: bool
    events_missed: int
    settings: Dict[str, object]
    def __init__(self, port: str = ..., *, model: Optional[str] = ...,
                 protocol: Optional[str] = ..., params: Optional[Dict[str, object]] = ...,
                 record_sent: bool = ..., start: bool = ..., display_prefix: str = ...,
                 **kwargs: object) -> None: ...
    def start(self) -> Driver: ...
    def close(self) -> None: ...
    def stop(self) -> None: ...
    def __enter__(self) -> Driver: ...
    def __exit__(self, *exc: object) -> None: ...
    def snapshot(self) -> Snapshot: ...
    def wait_snapshot(self, after: Optional[int] = ..., timeout: float = ...) -> Snapshot: ...
    def wait_until(self, predicate: Callable[[Snapshot], bool],
                   timeout: float = ...) -> Snapshot: ...
    def wait_ready(self, timeout: float = ...) -> Snapshot: ...
    def wait_motion(self, rate: float = ..., timeout: float = ...) -> MotionUpdate: ...
    def events(self) -> List[Event]: ...
    def diagnostics(self, namespace: str = ...) -> List[DiagnosticGroup]: ...
    def hardware_id(self, namespace: str = ...) -> str: ...
    def command(self, vx: float = ..., vy: float = ..., wz: float = ...,
                mode: Optional[str] = ..., vz: float = ..., wx: float = ...,
                wy: float = ..., age: Optional[float] = ...) -> None: ...
    def set_motion_mode(self, mode: Optional[str]) -> None: ...
    def resume(self, timeout: Optional[float] = ...) -> RequestOutcome: ...
    def clear_errors(self, code: int = ..., timeout: Optional[float] = ...) -> RequestOutcome: ...
    def set_ultrasonic(self, enable: bool, timeout: Optional[float] = ...) -> RequestOutcome: ...
    def set_lights(self, front: str = ..., rear: str = ..., front_brightness: int = ...,
                   rear_brightness: int = ..., timeout: Optional[float] = ...) -> RequestOutcome: ...
    def park(self, on: bool = ..., timeout: Optional[float] = ...) -> RequestOutcome: ...
    def set_drive_mode(self, mode: str, timeout: Optional[float] = ...) -> RequestOutcome: ...
    def firmware_version(self, timeout: Optional[float] = ...) -> str: ...
    def budget(self, kind: str) -> float: ...
    def inject(self, line: str) -> str: ...
    def ground_truth(self) -> Optional[GroundTruth]: ...
    def sent(self) -> List[SentMotion]: ...
    def wait_sent(self, timeout: float = ...) -> List[SentMotion]: ...

def decode(log: str, *, protocol: str = ...,
           settings: Optional[Dict[str, str]] = ...) -> List[dict]: ...

@dataclass
class OdometryReplay:
    steps: List[dict]
    final: Dict[str, float]

def replay_odometry(log: str, *, model: Optional[str] = ..., protocol: str = ...,
                    source: str = ..., settings: Optional[Dict[str, str]] = ...) -> OdometryReplay: ...
