"""ranger_can: the AgileX RANGER driver library (libranger_can) for Python.

    import time, ranger_can
    with ranger_can.Driver("sim") as d:        # "can0", "sim:agx_v2", "replay:FILE", model=...
        d.wait_ready(timeout=10)                # identified and in CAN command mode
        for _ in range(40):                     # the driver stops after 500 ms without a command
            d.command(vx=0.5, vy=0.0, wz=0.0)
            time.sleep(0.05)
        s = d.snapshot()
        print(s.odometry.x, s.odometry.y, s.odometry.yaw, s.motion_mode, s.refusal)

Everything happens in the C++ library: the driver's own thread owns the bus, the 20 ms keep-alive,
the 500 ms command timeout, the re-arm after an involuntary stop, the identification of the
protocol settings and the odometry; this package maps it. Errors are RangerError (the library's
message); waiting releases the GIL; a driver is stopped (a zero motion command sent) when its
`with` block ends, on an exception, on close(), and at interpreter exit.
"""

import atexit
import json
import os
import threading
import time
import weakref
from dataclasses import dataclass, field
from typing import Dict, List, Optional

from ._errors import RangerError, RequestFailed, RequestTimeout
from ._ranger_can import (  # noqa: F401  (re-exported)
    Battery, CliResult, DiagnosticGroup, Event, FrameCount, GroundTruth, Identification, Joints, Lights, Motor,
    MotionUpdate, MotionWireEncoder, Odometry, read_twist,
    ParameterRow, RemoteState, RequestOutcome, SentMotion, Snapshot, UltrasonicReading,
    __version__, _cli, _Session, bms_status_bit_names, chassis_command_names, check_parameter,
    diagnostic_group_names,
    driver_status_bit_names, error_clear_description, error_names, event_kinds, fault_names,
    light_modes, model_names, motion_mode_pinned, resume_answered, resume_refused_offline,
    clear_errors_answer, request_answer, ultrasonic_request_refused, lights_request_refused,
    drive_mode_request, answer_line, answer_event_kinds, pose_covariance, diagonal_covariance,
    range_reading, BatteryReport, PublicationSchedule, CmdVelTypeRule, CmdVelTypeDecision,
    cmd_vel_type_names,
    unknown_motion_mode_number, motion_mode_numbers, light_mode_numbers, drive_mode_numbers,
    motion_modes, parameters, protocol_names, refusal_names, steering_joint_names, variant_names,
    wheel_joint_names)

__all__ = [
    "Driver", "RangerError", "RequestFailed", "RequestTimeout", "Snapshot", "RequestOutcome",
    "Event", "event_kinds", "MotionUpdate", "MotionWireEncoder", "read_twist", "DiagnosticGroup",
    "diagnostic_group_names",
    "check_parameter",
    "decode", "replay_odometry", "parameters", "model_names", "variant_names", "protocol_names",
    "motion_modes", "light_modes", "motion_mode_numbers", "light_mode_numbers",
    "drive_mode_numbers", "refusal_names", "fault_names", "steering_joint_names",
    "wheel_joint_names", "__version__",
]

# The drivers not closed yet: stopped at interpreter exit.
_open = weakref.WeakSet()
_open_lock = threading.Lock()

# Waits are cut into slices this long so that Ctrl-C (KeyboardInterrupt) is seen promptly.
_SLICE = 0.1


@atexit.register
def _close_all():
    with _open_lock:
        drivers = list(_open)
    for d in drivers:
        d.close()


class Driver:
    """The driver of one RANGER: `port` names the bus ("can0", "vcan0", "sim", "sim:VARIANT",
    "replay:FILE"; a `port_name` in `params` wins). Parameters by the ROS node's names (ranger_can.parameters() lists every
    one, with its range): as keywords (`cmd_vel_timeout=1.0`) or in `params` (names with a
    slash: `params={"linear/x/has_velocity_limits": True}`). A bad value raises RangerError
    naming every bad parameter and its valid range (each name after `display_prefix`). With
    record_sent, every motion frame sent is kept for sent(). The driver starts at once (start=False:
    call start()); use it as a context manager, or call close()."""

    def __init__(self, port: str = "sim", *, model: Optional[str] = None,
                 protocol: Optional[str] = None, params: Optional[Dict[str, object]] = None,
                 record_sent: bool = False, start: bool = True, display_prefix: str = "",
                 **kwargs):
        values = dict(params or {})
        values.update(kwargs)
        if model is not None:
            values["model"] = model
        if protocol is not None:
            values["protocol"] = protocol
        self._s = _Session(port, values, record_sent, display_prefix)
        self._closed = False
        self._event_seq = 0
        self.events_missed = 0
        with _open_lock:
            _open.add(self)
        if start:
            self.start()

    # ---- life cycle ----
    def start(self) -> "Driver":
        """Starts the driver's thread (the bus is opened, retried while it cannot be)."""
        self._check_open()
        self._s.start()
        return self

    def close(self) -> None:
        """Stops the chassis (a zero motion command) and the driver's thread. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._s.stop()
        with _open_lock:
            _open.discard(self)

    stop = close

    def __enter__(self) -> "Driver":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 (interpreter shutdown: nothing left to report to)
            pass

    @property
    def closed(self) -> bool:
        return self._closed

    def _check_open(self):
        if self._closed:
            raise RangerError("the driver is closed", "invalid_argument")

    # ---- what it runs with ----
    port = property(lambda self: self._s.port, doc="the bus, as given")
    model = property(lambda self: self._s.model, doc="the vehicle model")
    protocol = property(lambda self: self._s.protocol, doc="auto, manual or agx_v2")
    protocol_source = property(lambda self: self._s.protocol_source,
                               doc="where the protocol settings come from, in words")
    startup_lines = property(
        lambda self: self._s.startup_lines,
        doc="the start-up log's (severity, text) lines about the model and where the protocol "
            "settings come from, in the library's words (the ROS 1 node logs the same)")
    is_sim = property(lambda self: self._s.is_sim, doc="the in-process virtual chassis")
    settings = property(lambda self: self._s.settings,
                        doc="the node's own values of the parameter table, checked: port_name, "
                            "frames, publish rates, covariance diagonals, ultrasonic ranges "
                            "(what a ROS front end publishes with)")
    stop_sent = property(lambda self: self._s.stop_sent,
                         doc="the stop at close() was sent to the chassis")

    # ---- state ----
    def snapshot(self) -> Snapshot:
        """The driver's latest state (cheap: no copy)."""
        return self._s.snapshot()

    def wait_snapshot(self, after: Optional[int] = None, timeout: float = 1.0) -> Snapshot:
        """Waits (GIL released) for a snapshot newer than sequence `after` (default: the
        current one); returns the latest after at most `timeout` s."""
        seq = self._s.snapshot().sequence if after is None else after
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            s = self._s.wait_snapshot(seq, max(0.0, min(left, _SLICE)))
            if s.sequence > seq or left <= 0 or self._s.stopped:
                return s

    def wait_until(self, predicate, timeout: float = 10.0) -> Snapshot:
        """Waits until predicate(snapshot) is true; RequestTimeout after `timeout` s."""
        deadline = time.monotonic() + timeout
        s = self._s.snapshot()
        while not predicate(s):
            if time.monotonic() >= deadline:
                raise RequestTimeout(f"not reached within {timeout} s: {s!r}")
            s = self.wait_snapshot(s.sequence, min(_SLICE, max(0.0, deadline - time.monotonic())))
        return s

    def wait_ready(self, timeout: float = 10.0) -> Snapshot:
        """Waits until the chassis is heard, its protocol settings decided (protocol auto) and it
        is in CAN command mode with nothing refusing motion. RangerError at once when the
        identification failed (its message says what to set); RequestTimeout after `timeout`."""
        self._check_open()
        deadline = time.monotonic() + timeout
        s = self._s.snapshot()
        while True:
            ident = s.identification
            if ident is not None and ident.phase == "failed":
                raise RangerError(ident.message, "identification_failed")
            decided = ident is None or ident.phase == "decided"
            if (s.bus_open and s.link == "connected" and s.control_mode == "can" and decided
                    and s.refusal in ("none", "cmd_timeout")):
                return s
            left = deadline - time.monotonic()
            if left <= 0:
                why = s.bus_error if not s.bus_open else (
                    f"link {s.link}, control mode {s.control_mode}, refusal {s.refusal}"
                    + (f", identification {ident.phase}: {ident.message}" if ident else ""))
                raise RequestTimeout(f"{self.port}: not ready within {timeout} s ({why})")
            s = self._s.wait_snapshot(s.sequence, min(left, _SLICE))

    def wait_motion(self, rate: float = 50.0, timeout: float = 1.0) -> MotionUpdate:
        """For a publisher of the motion estimate (odom, TF, joint states), paced as the ROS 1
        node paces it: waits (GIL released) until a publication is due at `rate` (Hz) and the
        driver has an estimate not handed out before, then returns it (update.odometry,
        update.joints: ready tuples, None when not new). Returns early with update.sent when a
        motion frame was sent (record_sent), and empty after `timeout` s or close(). The driver's
        thread wakes the caller only for a frame sent or, once the publication is due, for a new
        estimate. One caller per driver."""
        if not rate > 0:
            raise RangerError(f"wait_motion: rate {rate} Hz: expected > 0", "invalid_argument")
        period = 1.0 / rate
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            update = self._s.wait_motion(period, max(0.0, min(left, _SLICE)))
            if (update.new_estimate or update.sent or left <= _SLICE
                    or self._s.stopped):
                return update

    def diagnostics(self, namespace: str = "/") -> List[DiagnosticGroup]:
        """The library's diagnostic groups of the latest snapshot, in the order of
        diagnostic_group_names() — CAN link, control mode, protocol settings, chassis errors,
        battery, frame rates — each with its level, message, key/values and hardware_id
        ("ranger:<namespace>:<port>"): what the ROS 1 node's /diagnostics shows. The frame-rate
        group counts frames rejected since the previous call."""
        return self._s.diagnostics(namespace)

    def hardware_id(self, namespace: str = "/") -> str:
        """"ranger:<namespace>:<port>": the hardware_id of every diagnostic group."""
        return self._s.hardware_id(namespace)

    def events(self) -> List[Event]:
        """The driver's events (transitions with a severity: link, control mode, re-arm,
        identification, refusals, faults, plausibility, requests, the shutdown stop, ...) since
        the last call, oldest first; events_missed counts those the driver's ring no longer held."""
        events, missed = self._s.events_since(self._event_seq)
        self.events_missed += missed
        if events:
            self._event_seq = events[-1].sequence
        return events

    # ---- commands (the driver's mailbox: never waits for the bus) ----
    def command(self, vx: float = 0.0, vy: float = 0.0, wz: float = 0.0,
                mode: Optional[str] = None, vz: float = 0.0, wx: float = 0.0,
                wy: float = 0.0, age: Optional[float] = None) -> None:
        """The motion wanted from now on (REP-103: m/s, rad/s), optionally in a forced mode.
        Repeat it at least every cmd_vel_timeout (0.5 s), or the driver stops the chassis.
        vz, wx, wy (a twist's linear.z, angular.x, angular.y) are not driven, only checked.
        age: how old a stamped command is (s; None: unstamped, or a zero stamp): older than
        cmd_vel_timeout, it is not obeyed (the chassis is commanded to stop and the snapshot's
        refusal is "stale_command", saying how old, until a fresh command).
        RangerError for NaN/inf in any of the six (the chassis is then commanded to stop, and the
        snapshot's refusal is "invalid_command" naming it until a valid command) or a bus never
        opened."""
        self._check_open()
        self._s.command(float(vx), float(vy), float(wz), mode, float(vz), float(wx), float(wy),
                        None if age is None else float(age))

    def set_motion_mode(self, mode: Optional[str]) -> None:
        """Pins every later command to "ackermann", "oblique", "spin" or "side_slip" (where the
        chassis's mode numbering has it); None: automatic selection from the twist."""
        self._check_open()
        self._s.set_motion_mode(mode)

    # ---- requests: each waits for its answer (GIL released) ----
    def _request(self, kind: str, request_id: int, timeout: Optional[float]) -> RequestOutcome:
        budget = self._s.budget(kind) if timeout is None else timeout
        deadline = time.monotonic() + budget
        while True:
            left = deadline - time.monotonic()
            outcome = self._s.wait_for(request_id, max(0.0, min(left, _SLICE)))
            if outcome.state == "answered":
                return outcome
            if outcome.state == "failed":
                raise RequestFailed(outcome.message or f"{kind} failed", outcome)
            if left <= 0 or self._s.stopped:
                raise RequestTimeout(
                    f"{outcome.what or kind}: no answer within {budget:.2f} s ({outcome.state})",
                    outcome)

    def resume(self, timeout: Optional[float] = None) -> RequestOutcome:
        """The explicit re-arm after a stop the commander did not ask for (e-stop, remote
        control, fault, link loss). RequestFailed (naming the cause) while one is still active."""
        self._check_open()
        return self._request("resume", self._s.resume(), timeout)

    def clear_errors(self, code: int = 0, timeout: Optional[float] = None) -> RequestOutcome:
        """0x441 with `code` (0 all non-critical, ...); answered with the chassis's error word
        (outcome.error_word)."""
        self._check_open()
        return self._request("clear_errors", self._s.clear_errors(code), timeout)

    def set_ultrasonic(self, enable: bool, timeout: Optional[float] = None) -> RequestOutcome:
        """Switches the chassis's ultrasonic obstacle avoidance; answered once it confirms."""
        self._check_open()
        return self._request("ultrasonic", self._s.set_ultrasonic(bool(enable)), timeout)

    def set_lights(self, front: str = "on", rear: str = "on", front_brightness: int = 0,
                   rear_brightness: int = 0, timeout: Optional[float] = None) -> RequestOutcome:
        """Lights ("off", "on", "breathing", "custom" with a brightness 0-100), on a chassis with
        the vendor's frames; answered once it reports them."""
        self._check_open()
        rid = self._s.set_lights(front, int(front_brightness), rear, int(rear_brightness))
        return self._request("lights", rid, timeout)

    def park(self, on: bool = True, timeout: Optional[float] = None) -> RequestOutcome:
        """Park (agx_v2): brought to rest, switched to park, motion refused until park(False)."""
        self._check_open()
        return self._request("park", self._s.set_park(bool(on)), timeout)

    def set_drive_mode(self, mode: str, timeout: Optional[float] = None) -> RequestOutcome:
        """The motor drivers' drive mode ("current" or "voltage"; 0x423, the RANGER MINI 3.0's);
        answered once the chassis reports it. RequestFailed on a protocol without drive modes."""
        self._check_open()
        return self._request("drive_mode", self._s.set_drive_mode(mode), timeout)

    def firmware_version(self, timeout: Optional[float] = None) -> str:
        """Asks the chassis for its firmware version (0x4A1) and returns the text."""
        self._check_open()
        self._request("firmware_version", self._s.request_firmware_version(), timeout)
        return self._s.snapshot().firmware_version

    def budget(self, kind: str) -> float:
        """How long a request of `kind` ("resume", "clear_errors", "ultrasonic", "lights",
        "park", "drive_mode", "firmware_version") is waited for by default, in s."""
        return self._s.budget(kind)

    # ---- the virtual chassis ----
    def inject(self, line: str) -> str:
        """One line of the virtual chassis's control language ("estop on", "remote on",
        "error NAME", "battery PCT", ...); what it says. RangerError for another port or a line
        the language refuses (the valid commands listed)."""
        self._check_open()
        return self._s.inject(line)

    def ground_truth(self) -> Optional[GroundTruth]:
        """The virtual chassis's true pose and twist (None on another port)."""
        return self._s.ground_truth()

    # ---- the frames sent (record_sent=True) ----
    def sent(self) -> List[SentMotion]:
        """The motion frames sent since the last call: the twist each realises."""
        return self._s.take_sent()

    def wait_sent(self, timeout: float = 1.0) -> List[SentMotion]:
        """As sent(), waiting (GIL released) up to `timeout` s for one."""
        return self._s.wait_sent(timeout)

    def __repr__(self):
        return f"<ranger_can.Driver {self.port} ({'closed' if self._closed else 'open'})>"


# ---- candump logs: the ranger_can tool's decode and odom, in-process ---------------------------
def _run_tool(args: List[str], input_text: str = "") -> str:
    result = _cli(args, input_text)
    if result.exit_code != 0:
        message = result.err.strip() or f"ranger_can {args[0]} exited with {result.exit_code}"
        raise RangerError(message, "usage" if result.exit_code == 2 else "no_data")
    return result.out


def _profile_args(protocol: str, settings: Optional[Dict[str, str]], model: Optional[str] = None):
    args = ["--protocol", protocol]
    if model:
        args += ["--model", model]
    for name, value in (settings or {}).items():
        args += ["--set", f"{name}={value}"]
    return args


def decode(log: str, *, protocol: str = "auto",
           settings: Optional[Dict[str, str]] = None) -> List[dict]:
    """Decodes a candump log (a file path, or the log's text when it holds a newline): one dict
    per frame (t, iface, id, name, dlc, data, and the message's fields in SI units), as
    `ranger_can decode --json` prints them. protocol auto identifies the settings from the log."""
    is_text = "\n" in log
    args = ["decode", "-" if is_text else os.fspath(log), "--json"]
    out = _run_tool(args + _profile_args(protocol, settings), log if is_text else "")
    return [json.loads(line) for line in out.splitlines() if line.strip()]


@dataclass
class OdometryReplay:
    """A log replayed through the driver's odometry: every integrated step and the final pose."""
    steps: List[dict] = field(default_factory=list)
    final: Dict[str, float] = field(default_factory=dict)


def replay_odometry(log: str, *, model: Optional[str] = None, protocol: str = "auto",
                    source: str = "wheels",
                    settings: Optional[Dict[str, str]] = None) -> OdometryReplay:
    """Replays a candump log (path or text) through ranger::Odometry, as `ranger_can odom` does:
    the pose (m, rad; REP-103/105) after every step, and the final pose."""
    is_text = "\n" in log
    args = ["odom", "-" if is_text else os.fspath(log), "--source", source]
    out = _run_tool(args + _profile_args(protocol, settings, model), log if is_text else "")
    rows = [json.loads(line) for line in out.splitlines() if line.strip()]
    return OdometryReplay(steps=rows[:-1], final=rows[-1] if rows else {})
