#include "ranger_can/control/driver_events.hpp"

#include <cmath>
#include <iterator>
#include <utility>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/json.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {
namespace {

using text::join;

using text::format;

std::string causes_text(StopCauses causes) {
  std::string out = describe(causes);  // "emergency_stop,remote"
  for (std::size_t i = out.find(','); i != std::string::npos; i = out.find(',', i + 2))
    out.replace(i, 1, ", ");
  return out;
}

std::string control_mode_text(const std::optional<protocol::ControlMode>& m) {
  return m ? std::string(protocol::to_string(*m)) : std::string("unknown");
}

// ---- the words of each payload ----

std::string text_of(const DriverEvent& e, const BusEvent& b) {
  if (e.kind == EventKind::kStillWaiting) {
    return format(
        "still waiting for the chassis on %s: nothing heard for %.0f s (is it powered "
        "on, and the bus at 500 kbit/s?)",
        b.bus.c_str(), seconds(b.waited));
  }
  if (e.kind == EventKind::kBusOpened) return b.bus + " open: waiting for the chassis on " + b.bus;
  if (b.socketcan) {
    return "cannot open CAN interface " + b.bus + ": " + b.error +
           ". Bring the adapter up with `rosrun ranger_bringup bringup_can2usb.bash` (or `sudo ip "
           "link set " +
           b.bus + " up type can bitrate 500000`); retrying every " +
           format("%.1f s", seconds(b.retry));
  }
  return "cannot open " + b.bus + ": " + b.error +
         format(" (retrying every %.1f s)", seconds(b.retry));
}

std::string text_of(const DriverEvent& e, const LinkEvent& l) {
  if (e.kind == EventKind::kLinkHeardAgain) {
    return "chassis heard again on " + l.bus + ": odometry resumes from the last pose";
  }
  if (e.kind == EventKind::kLinkConnected) return "chassis connected on " + l.bus;
  return "chassis on " + l.bus +
         format(
             " went silent (no system status for %.2f s): motion stopped, no odometry until "
             "it is heard again",
             seconds(l.link_timeout));
}

std::string text_of(const DriverEvent&, const ControlModeEvent& m) {
  std::string out = "control mode " + control_mode_text(m.to);
  if (!m.to) out += " (" + text::hex(m.raw, 2) + ")";
  return out + " (was " + control_mode_text(m.from) + ")";
}

std::string text_of(const DriverEvent& e, const RefusalEvent& r) {
  if (r.to == MotionRefusal::kNone) return "chassis accepts motion commands";
  if (e.severity >= Severity::kWarn) return "motion refused: " + r.detail;
  if (r.to == MotionRefusal::kIdentifying && e.severity == Severity::kInfo) {
    return "motion waits: " + r.detail;
  }
  return r.detail;
}

std::string text_of(const DriverEvent& e, const RearmEvent& r) {
  if (e.kind == EventKind::kRearmLatched) {
    return "re-arm latched after " + causes_text(r.causes) +
           ": motion stays stopped until a re-arm once the cause has cleared";
  }
  return std::string("re-armed (") + (r.by_resume ? "resume" : "zero twist") + ") after " +
         causes_text(r.causes);
}

std::string text_of(const DriverEvent& e, const IdentificationEvent& i) {
  const IdentificationStatus* st = i.status.get();
  if (e.kind == EventKind::kIdentificationFailed) {
    return (st ? st->message : std::string("identification failed")) + i.commission;
  }
  if (e.kind == EventKind::kIdentificationPhase) {
    std::string out = "identification: " + std::string(to_string(i.phase));
    if (st && !st->message.empty()) out += " (" + st->message + ")";
    return out;
  }
  if (!st) return "chassis identified: protocol settings " + i.settings;
  return format("chassis identified in %.2f s (confidence %.2f): protocol settings ",
                seconds(st->elapsed()), st->confidence) +
         i.settings + ". Evidence: " + join(st->evidence, "; ") + ". Kept at the " + st->revision +
         " preset's value (no frame at rest tells them; the plausibility monitors check them "
         "while driving): " +
         (st->undecided.empty() ? std::string("none") : join(st->undecided));
}

std::string text_of(const DriverEvent&, const SettingLearnedEvent& s) {
  return "learned while driving: " + s.setting.name + " = " + s.setting.value + " (" +
         s.setting.evidence + "); protocol settings now " + s.settings +
         ". The robot stopped: send a zero cmd_vel or call resume to drive again";
}

std::string text_of(const DriverEvent& e, const PlausibilityEvent& p) {
  if (e.kind == EventKind::kPlausibilityStop) {
    return "plausibility stop: " + p.finding.text() +
           ". The robot is stopped: set that parameter (or load a commissioning file) and "
           "restart, or call resume to try again";
  }
  return "plausibility: " + p.finding.text() +
         " (check that setting; a persisting mismatch of a sign or a unit stops the robot)";
}

std::string text_of(const DriverEvent&, const CommandRefusedEvent& c) {
  std::string out = c.code == Errc::kNotFinite ? "cmd_vel refused, chassis stopped: " + c.message
                                               : "cmd_vel not applied: " + c.message;
  if (c.count > 1) out += " (" + std::to_string(c.count) + " refused since the last report)";
  return out;
}

std::string text_of(const DriverEvent&, const CommandAdjustedEvent& c) {
  return "cmd_vel adjusted to what the chassis can do: " +
         describe_adjustments(c.flags, c.asked, c.driven);
}

std::string text_of(const DriverEvent&, const MotionModeEvent& m) {
  if (!m.mode) return "set_motion_mode: automatic motion-mode selection";
  return "set_motion_mode: motion mode pinned to " + std::string(protocol::to_string(*m.mode)) +
         " (the switch happens at standstill)";
}

std::string text_of(const DriverEvent& e, const FaultEvent& f) {
  const std::string word = " (error word " + text::hex(f.error_word, 8) + ")";
  if (e.kind == EventKind::kFaultCleared) return "chassis fault cleared: " + f.name + word;
  return "chassis fault: " + f.name + (f.description.empty() ? "" : " - " + f.description) +
         (f.critical ? ", the chassis does not drive until it is cleared" : "") + word;
}

std::string text_of(const DriverEvent&, const FirmwareEvent& f) {
  return "firmware version: " + f.version;
}

std::string text_of(const DriverEvent&, const ParkEvent& p) {
  return p.parked ? "chassis parked (0x291 reports park)" : "chassis left park";
}

std::string text_of(const DriverEvent&, const LightsEvent& l) {
  return "lights: " + describe(l.lights) +
         (l.lights.can_control ? "" : " (the lights do not follow CAN commands)");
}

std::string text_of(const DriverEvent&, const RequestEvent& r) {
  const RequestOutcome& o = r.outcome;
  std::string out = o.what;
  if (o.state == RequestOutcome::State::kFailed) out += " failed";
  if (!o.message.empty()) out += ": " + o.message;
  if (r.repeated > 0) {
    out += " (" + std::to_string(r.repeated) + " more answered alike since the last report)";
  }
  return out;
}

std::string text_of(const DriverEvent&, const PaddedFramesEvent& p) {
  return text::hex(p.id) + " (" + std::string(p.name) +
         ") frames arrive longer than their layout: decoded from their leading bytes, the rest "
         "ignored";
}

std::string text_of(const DriverEvent&, const ShutdownEvent& s) {
  if (!s.sent) return "no stop sent to the chassis: " + s.why_not;
  return "stop sent to the chassis (zero motion command, frame " + text::hex(s.frame_id) + ")";
}

// ---- JSON ----

void fields_of(JsonWriter& j, const BusEvent& b) {
  j.key("bus").string(b.bus);
  if (!b.error.empty()) j.key("error").string(b.error);
}
void fields_of(JsonWriter& j, const LinkEvent& l) {
  j.key("bus").string(l.bus);
  j.key("from").string(to_string(l.from));
  j.key("to").string(to_string(l.to));
}
void fields_of(JsonWriter& j, const ControlModeEvent& m) {
  j.key("from").string(control_mode_text(m.from));
  j.key("to").string(control_mode_text(m.to));
}
void fields_of(JsonWriter& j, const RefusalEvent& r) {
  j.key("from").string(to_string(r.from));
  j.key("to").string(to_string(r.to));
}
void fields_of(JsonWriter& j, const RearmEvent& r) {
  j.key("causes").string(describe(r.causes));
}
void fields_of(JsonWriter& j, const IdentificationEvent& i) {
  j.key("phase").string(to_string(i.phase));
  if (!i.settings.empty()) j.key("settings").string(i.settings);
}
void fields_of(JsonWriter& j, const SettingLearnedEvent& s) {
  j.key("setting").string(s.setting.name);
  j.key("value").string(s.setting.value);
}
void fields_of(JsonWriter& j, const PlausibilityEvent& p) {
  j.key("check").string(p.finding.check);
  j.key("setting").string(p.finding.setting);
  j.key("try").string(p.finding.try_value);
}
void fields_of(JsonWriter& j, const CommandRefusedEvent& c) {
  j.key("count").unsigned_integer(c.count);
}
void fields_of(JsonWriter& j, const CommandAdjustedEvent& c) {
  j.key("flags").string(kinematics_flags_to_string(c.flags));
}
void fields_of(JsonWriter& j, const MotionModeEvent& m) {
  j.key("mode").string(m.mode ? protocol::to_string(*m.mode) : std::string_view("auto"));
}
void fields_of(JsonWriter& j, const FaultEvent& f) {
  j.key("fault").string(f.name);
  j.key("critical").boolean(f.critical);
}
void fields_of(JsonWriter& j, const FirmwareEvent& f) {
  j.key("version").string(f.version);
}
void fields_of(JsonWriter& j, const ParkEvent& p) {
  j.key("parked").boolean(p.parked);
}
void fields_of(JsonWriter& j, const LightsEvent& l) {
  j.key("lights").string(describe(l.lights));
}
void fields_of(JsonWriter& j, const RequestEvent& r) {
  j.key("id").unsigned_integer(r.outcome.id);
  if (r.repeated > 0) j.key("repeated").unsigned_integer(r.repeated);
  j.key("request").string(to_string(r.outcome.kind));
  j.key("state").string(to_string(r.outcome.state));
}
void fields_of(JsonWriter& j, const PaddedFramesEvent& p) {
  j.key("id").string(text::hex(p.id));
}
void fields_of(JsonWriter& j, const ShutdownEvent& s) {
  j.key("sent").boolean(s.sent);
}

}  // namespace

std::string describe(const DriverEvent& event) {
  return std::visit([&](const auto& payload) { return text_of(event, payload); }, event.data);
}

std::string to_json(const DriverEvent& event, Timestamp origin) {
  std::string out;
  JsonWriter j(out);
  j.begin_object();
  j.key("seq").unsigned_integer(event.sequence);
  j.key("t").fixed(seconds(event.time - origin), 3);
  j.key("event").string(to_string(event.kind));
  j.key("severity").string(to_string(event.severity));
  j.key("text").string(describe(event));
  std::visit([&](const auto& payload) { fields_of(j, payload); }, event.data);
  j.end_object();
  return out;
}

// ---- the refusal in words -----------------------------------------------------------------

namespace {

std::string identifying_words(const ControllerState& c, const IdentificationStatus* id) {
  if (c.standstill_probe && !c.identifying) return "standstill probe (ranger_can commission)";
  // The identification's own words: its phase, or (failed) what to set.
  std::string words = id && !id->message.empty()
                          ? id->message
                          : std::string("identifying the chassis's protocol settings");
  if (c.quiet && c.identifying.has_value()) {
    words +=
        " (nothing is sent until the chassis has been heard; motion waits for the "
        "identification)";
  }
  return words;
}

std::string stop_words(const ControllerState& c) {
  switch (c.refusal) {
    case MotionRefusal::kRemote:
      return "remote control has the chassis: cmd_vel not applied";
    case MotionRefusal::kEstop:
      return "emergency stop pressed: release it, then call resume";
    case MotionRefusal::kCriticalError:
      return "critical chassis error (" + join(c.faults) +
             "): clear it (clear_errors), then call resume";
    case MotionRefusal::kLowBattery:
      return "battery below low_battery_soc: the chassis cuts the drives";
    case MotionRefusal::kModeSwitchFailed:
      return "motion-mode switch not confirmed by the chassis: send a zero cmd_vel (it abandons "
             "the switch), then call resume";
    case MotionRefusal::kImplausible:
      return "the chassis's feedback contradicts the protocol settings: " +
             (c.implausible_reason.empty() ? std::string("(no reason given)")
                                           : c.implausible_reason) +
             ". Set that parameter (or load a commissioning file), or call resume to try again";
    case MotionRefusal::kRearmRequired:
      return "rearm_required after " + causes_text(c.latched_causes) +
             (c.zero_twist_rearms ? ": call resume (or send a zero cmd_vel: rearm_on_zero_twist)"
                                  : ": call resume") +
             " to drive again";
    default:
      return "";
  }
}

std::string mode_words(const ControllerState& c) {
  switch (c.refusal) {
    case MotionRefusal::kStandby:
      if (c.reclaim_blocked)
        return "remote control had the chassis: call resume to take CAN control";
      return c.awaiting_command_mode ? "standby: requesting CAN command mode"
                                     : "standby (auto_command_mode is off)";
    case MotionRefusal::kModeUnknown:
      if (c.chassis_mode == protocol::MotionMode::kPark) {
        return "the chassis is in park mode (parked before this driver ran): call park with "
               "data = false to leave it";
      }
      return "motion mode unknown (no motion-mode feedback yet)";
    case MotionRefusal::kSwitching:
      return "motion-mode switch in progress";
    case MotionRefusal::kParked:
      return c.parked() ? "parked: call park with data = false to drive again"
                        : "parking (bringing the chassis to rest, then to park mode): call park "
                          "with data = false to drive again";
    default:
      return "";
  }
}

}  // namespace

std::string describe_refusal(const ControllerState& c, const IdentificationStatus* id) {
  switch (c.refusal) {
    case MotionRefusal::kNone:
      if (c.steer_first_factor < 1.0) {
        return "steering first: speed held at " +
               std::to_string(static_cast<int>(std::lround(c.steer_first_factor * 100.0))) +
               " % until the wheels reach the commanded angle";
      }
      return "";
    case MotionRefusal::kLinkLost:
      return c.link == LinkState::kNeverConnected
                 ? "no chassis heard yet (waiting for its system status)"
                 : "chassis silent (link lost): motion stopped";
    case MotionRefusal::kCmdTimeout:
      return "no recent cmd_vel (cmd_vel_timeout): chassis commanded to stop";
    case MotionRefusal::kInvalidCommand:
      return "invalid_command: cmd_vel refused, " + c.invalid_command +
             " (a NaN or an infinity in any of its six fields refuses the whole twist): chassis "
             "commanded to stop until a valid cmd_vel comes";
    case MotionRefusal::kStaleCommand:
      return "stale_command: cmd_vel refused, " + c.stale_command +
             " (a stamped cmd_vel older than cmd_vel_timeout must not drive; a zero stamp means "
             "now): chassis commanded to stop until a fresh cmd_vel comes";
    case MotionRefusal::kBelowMinimum:
      return "below_minimum: cmd_vel is below what the chassis can express (mode_selection/"
             "min_linear_speed, min_yaw_rate): not driven";
    case MotionRefusal::kIdentifying:
      return identifying_words(c, id);
    default:
      break;
  }
  std::string words = stop_words(c);
  if (words.empty()) words = mode_words(c);
  return words.empty() ? std::string(to_string(c.refusal)) : words;
}

// ---- the ring ------------------------------------------------------------------------------

void EventLog::append(std::vector<DriverEvent>& events) {
  if (events.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (DriverEvent& e : events) {
    e.sequence = ++last_;
    ring_.push_back(e);
  }
  while (ring_.size() > capacity_)
    ring_.pop_front();
}

std::uint64_t EventLog::read(std::uint64_t after, std::vector<DriverEvent>& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (ring_.empty() || after >= last_) return 0;
  const std::uint64_t oldest = ring_.front().sequence;
  const std::uint64_t missed = oldest > after + 1 ? oldest - after - 1 : 0;
  const std::uint64_t first = std::max(after + 1, oldest);
  for (auto it = ring_.begin() + static_cast<std::ptrdiff_t>(first - oldest); it != ring_.end();
       ++it)
    out.push_back(*it);
  return missed;
}

std::uint64_t EventLog::last_sequence() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_;
}

}  // namespace ranger
