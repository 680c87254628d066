"""The seams where the library's events and diagnostics-as-data plug in (issue 27, points 1 and 2).

Until the library reports transitions as typed events and turns a snapshot into diagnostic
groups, this module stands in for both, as thinly as it can: `Events.poll` reports the
transitions of a few snapshot fields, `diagnostic_groups` groups snapshot fields by concern,
`refusal_detail` puts the library's own words (the identification's message, the plausibility
finding) beside the refusal's name. The node calls only these three; when the library provides
them, each becomes a call into ranger_can (driver.events(), ranger_can.diagnostics(snapshot),
snapshot.refusal_detail) and nothing else in the node changes.
"""

from dataclasses import dataclass, field
from typing import List, Tuple

OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels

# The refusals that need someone to act: logged at WARN (the others at INFO).
_ACT = {"remote", "estop", "critical_error", "low_battery", "mode_switch_failed",
        "implausible_feedback", "rearm_required", "below_minimum"}


def refusal_detail(s) -> str:
    """Why motion is refused, with what the library says about it; "" while driven."""
    if s.refusal == "none":
        if s.steer_first_factor < 1.0:
            return f"steering first: speed held at {round(s.steer_first_factor * 100)} %"
        return ""
    words = [s.refusal]
    if s.refusal == "identifying" and s.identification is not None:
        words.append(s.identification.message)
    if s.refusal == "implausible_feedback" and s.implausible_reason:
        words.append(s.implausible_reason)
    if s.refusal in ("rearm_required",) and s.latched_causes:
        words.append("after " + ", ".join(s.latched_causes) + ": call resume")
    if s.refusal == "critical_error" and s.faults:
        words.append(", ".join(s.faults))
    return ": ".join(w for w in words if w)


@dataclass
class Event:
    level: int  # OK (INFO), WARN, ERROR
    text: str


class Events:
    """The transitions of one driver, from its snapshots (stands in for the library's events)."""

    def __init__(self, port: str):
        self._port = port
        self._last = {}

    def _changed(self, key, value) -> bool:
        old = self._last.get(key, object())
        self._last[key] = value
        return old != value

    def poll(self, s) -> List[Event]:
        out = []
        if self._changed("bus_error", s.bus_error) and s.bus_error:
            out.append(Event(ERROR, f"cannot open {self._port}: {s.bus_error}"))
        if self._changed("link", s.link):
            if s.link == "connected":
                out.append(Event(OK, f"chassis connected on {self._port}"))
            elif s.link == "stale":
                out.append(Event(WARN, f"chassis on {self._port} went silent: motion stopped"))
        ident = s.identification
        phase = ident.phase if ident is not None else None
        if self._changed("identification", phase) and ident is not None and ident.done:
            if phase == "decided":
                out.append(Event(OK, f"chassis identified: protocol settings {s.profile}. "
                                     f"Evidence: {'; '.join(ident.evidence)}"))
            else:
                out.append(Event(ERROR, ident.message))
        if self._changed("refusal", s.refusal):
            detail = refusal_detail(s)
            if s.refusal == "none":
                out.append(Event(OK, "chassis accepts motion commands"))
            elif s.refusal != "link_lost":
                level = WARN if s.refusal in _ACT else OK
                out.append(Event(level, ("motion refused: " if level else "") + detail))
        if self._changed("errors", tuple(s.error_names)):
            if s.error_names:
                out.append(Event(WARN, f"chassis error word {s.error_word:#010x}: "
                                       + ", ".join(s.error_names)))
        if self._changed("plausibility_stop", s.plausibility_stop) and s.plausibility_stop:
            out.append(Event(ERROR, "plausibility stop: " + s.plausibility_stop))
        for w in s.plausibility_warnings:
            if self._changed("warning:" + w.split(" (")[0], True):
                out.append(Event(WARN, "plausibility: " + w))
        return out


@dataclass
class Group:
    name: str
    level: int
    message: str
    values: List[Tuple[str, object]] = field(default_factory=list)


def diagnostic_groups(s, protocol_source: str) -> List[Group]:
    """The driver's state by concern (stands in for the library's diagnostics as data)."""
    link_level = OK if s.link == "connected" else (ERROR if not s.bus_open else WARN)
    link = Group("CAN link", link_level,
                 f"{s.port}: " + (s.bus_error if not s.bus_open else s.link),
                 [("port", s.port), ("bus_state", s.bus_state), ("link", s.link),
                  ("vendor_frames", s.vendor_frames), ("firmware_version", s.firmware_version),
                  ("firmware_version_state", s.firmware_state)])
    act = s.refusal in _ACT
    control = Group("Control mode", WARN if act else OK,
                    refusal_detail(s) or "accepts motion commands",
                    [("control_mode", s.control_mode), ("motion_mode", s.motion_mode),
                     ("refusal", s.refusal), ("rearm_required", s.rearm_required),
                     ("latched_causes", ", ".join(s.latched_causes)),
                     ("park_requested", s.park_requested), ("parked", s.parked)])
    ident = s.identification
    failed = ident is not None and ident.phase == "failed"
    protocol = Group("Protocol",
                     ERROR if failed or s.plausibility_stop else (WARN if s.plausibility_warnings
                                                                  else OK),
                     (ident.message if failed else s.plausibility_stop or s.profile),
                     [("source", protocol_source), ("profile", s.profile),
                      ("identification", ident.phase if ident else "")]
                     + [("warning", w) for w in s.plausibility_warnings])
    errors = Group("Chassis errors", WARN if s.error_names else OK,
                   ", ".join(s.error_names) or "no errors",
                   [("error_word", f"{s.error_word:#010x}")])
    battery = Group("Battery", OK, f"{s.battery_voltage or 0.0:.1f} V",
                    [("voltage", s.battery_voltage), ("soc", s.battery_soc)])
    frames = Group("Frame rates", OK, f"{sum(f.frames for f in s.frames)} frames",
                   [(f"{f.id:#05x} {f.name}", f.frames) for f in s.frames])
    return [link, control, protocol, errors, battery, frames]
