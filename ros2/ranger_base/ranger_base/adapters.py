"""The seam where the library's diagnostics as data plug in (issue 27, point 2).

Until the library turns a snapshot into diagnostic groups, `diagnostic_groups` stands in, as
thinly as it can: snapshot fields grouped by concern, with the library's own words (the refusal's
detail, the identification's message, the plausibility findings). The node calls only this; when
the library provides it, it becomes a call into ranger_can (ranger_can.diagnostics(snapshot)) and
nothing else in the node changes. (The events and the refusal's words are the library's
already: driver.events(), snapshot.refusal_detail.)
"""

from dataclasses import dataclass, field
from typing import List, Tuple

OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels

# The refusals that need someone to act: WARN in diagnostics (the others OK).
_ACT = {"remote", "estop", "critical_error", "low_battery", "mode_switch_failed",
        "implausible_feedback", "rearm_required", "below_minimum"}


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
                    s.refusal_detail or "accepts motion commands",
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
