#include "ranger_can/control/event_tracker.hpp"

#include <algorithm>
#include <utility>
#include <variant>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {
namespace {

void emit(std::vector<DriverEvent>& out, Timestamp t, EventKind kind, Severity severity,
          EventData data) {
  DriverEvent e;
  e.time = t;
  e.kind = kind;
  e.severity = severity;
  e.data = std::move(data);
  out.push_back(std::move(e));
}

// How much a refusal matters: the commander's own stops and waits are news, a stop the
// commander did not ask for a warning; the link's loss and an ended identification are told by
// their own events.
Severity refusal_severity(const DriverSnapshot& s) {
  const ControllerState& c = s.controller;
  switch (c.refusal) {
    case MotionRefusal::kNone:
    case MotionRefusal::kCmdTimeout:
    case MotionRefusal::kModeUnknown:
    case MotionRefusal::kSwitching:
    case MotionRefusal::kParked:
      return Severity::kInfo;
    case MotionRefusal::kLinkLost:
      return Severity::kDebug;
    case MotionRefusal::kIdentifying:
      return s.identification && s.identification->done() ? Severity::kDebug : Severity::kInfo;
    case MotionRefusal::kStandby:
      return c.reclaim_blocked ? Severity::kWarn : Severity::kInfo;
    default:
      return Severity::kWarn;
  }
}

// The fault behind `bit` of the error word in `layout`.
FaultEvent fault_of(int bit, std::uint32_t word, ErrorWordLayout layout) {
  FaultEvent f;
  f.name = "reserved_bit_" + std::to_string(bit);
  f.error_word = word;
  f.critical = protocol::is_critical_error(1u << bit, layout);
  for (const protocol::NamedBit& b : protocol::system_error_bits(layout)) {
    if (b.index != bit) continue;
    f.name = std::string(b.name);
    f.description = std::string(b.description);
  }
  if (const protocol::FaultInfo* info = protocol::find_fault(f.name)) {
    f.fault = info->fault;
    f.motor = info->motor;
  }
  return f;
}

}  // namespace

void DriverEventTracker::observe(const DriverSnapshot& s, bool resumed,
                                 std::vector<DriverEvent>& out) {
  observe_bus(s, out);
  if (!s.bus_open) return;
  observe_link(s, out);
  observe_control_mode(s, out);
  observe_identification(s, out);  // the decision before "accepts motion"
  observe_plausibility(s, out);
  if (config_.commands) {
    observe_refusal(s, out);
    observe_rearm(s, resumed, out);
  }
  observe_faults(s, out);
  observe_vendor(s, out);
}

void DriverEventTracker::observe_bus(const DriverSnapshot& s, std::vector<DriverEvent>& out) {
  if (s.bus_error != bus_error_) {
    bus_error_ = s.bus_error;
    if (!s.bus_error.empty()) {
      emit(out, s.now, EventKind::kBusOpenFailed, Severity::kError,
           BusEvent{config_.bus, config_.socketcan, s.bus_error, config_.reconnect_interval, {}});
    }
  }
  if (s.bus_open && !bus_open_) {
    emit(out, s.now, EventKind::kBusOpened, Severity::kInfo,
         BusEvent{config_.bus, config_.socketcan, {}, {}, {}});
    opened_ = s.now;
    next_reminder_ = s.now + config_.waiting_reminder;
  }
  bus_open_ = s.bus_open;
  if (s.bus_open && s.controller.link == LinkState::kNeverConnected && s.now >= next_reminder_) {
    emit(out, s.now, EventKind::kStillWaiting, Severity::kInfo,
         BusEvent{config_.bus, config_.socketcan, {}, {}, s.now - opened_});
    next_reminder_ = s.now + config_.waiting_reminder;
  }
}

void DriverEventTracker::observe_link(const DriverSnapshot& s, std::vector<DriverEvent>& out) {
  const LinkState now = s.controller.link;
  if (link_ == now) return;
  const LinkState before = link_.value_or(LinkState::kNeverConnected);
  link_ = now;
  const LinkEvent data{config_.bus, before, now, config_.link_timeout};
  if (now == LinkState::kStale) {
    emit(out, s.now, EventKind::kLinkSilent, Severity::kWarn, data);
  } else if (now == LinkState::kConnected) {
    emit(out, s.now,
         before == LinkState::kStale ? EventKind::kLinkHeardAgain : EventKind::kLinkConnected,
         Severity::kInfo, data);
  }
}

void DriverEventTracker::observe_control_mode(const DriverSnapshot& s,
                                              std::vector<DriverEvent>& out) {
  const ControllerState& c = s.controller;
  if (!s.feedback.system_status) return;  // not reported yet
  if (control_mode_known_ && c.control_mode == control_mode_ &&
      c.control_mode_raw == control_mode_raw_) {
    return;
  }
  const ControlModeEvent data{control_mode_, c.control_mode, c.control_mode_raw};
  control_mode_known_ = true;
  control_mode_ = c.control_mode;
  control_mode_raw_ = c.control_mode_raw;
  emit(out, s.now, EventKind::kControlModeChanged, Severity::kInfo, data);
}

void DriverEventTracker::observe_identification(const DriverSnapshot& s,
                                                std::vector<DriverEvent>& out) {
  if (!s.identification || s.identification == identification_) return;
  identification_ = s.identification;
  const IdentificationStatus& id = *s.identification;
  if (!id.done()) {  // going on (again): its end is reported anew
    identification_reported_ = false;
    decisions_reported_ = 0;
    if (phase_ != id.phase) {
      emit(out, s.now, EventKind::kIdentificationPhase, Severity::kInfo,
           IdentificationEvent{id.phase, identification_, {}, {}});
    }
    phase_ = id.phase;
    return;
  }
  phase_ = id.phase;
  if (!identification_reported_) {
    identification_reported_ = true;
    decisions_reported_ = id.decided.size();
    if (id.decided_ok()) {
      emit(out, s.now, EventKind::kIdentified, Severity::kInfo,
           IdentificationEvent{id.phase, identification_, describe(s.profile), {}});
    } else {
      const std::string commission = config_.socketcan
                                         ? " (on this robot: ranger_can commission " + config_.bus +
                                               " --wheels-lifted --output FILE)"
                                         : std::string();
      emit(out, s.now, EventKind::kIdentificationFailed, Severity::kError,
           IdentificationEvent{id.phase, identification_, {}, commission});
    }
  }
  // Settings the identification could not decide at rest, learned while driving (the monitors
  // stopped the robot; the value they named is in use now).
  for (std::size_t i = decisions_reported_; id.decided_ok() && i < id.decided.size(); ++i) {
    emit(out, s.now, EventKind::kSettingLearned, Severity::kWarn,
         SettingLearnedEvent{id.decided[i], describe(s.profile)});
  }
  decisions_reported_ = std::max(decisions_reported_, id.decided.size());
}

void DriverEventTracker::observe_plausibility(const DriverSnapshot& s,
                                              std::vector<DriverEvent>& out) {
  // Each warning once (by what it suggests: its measured detail changes every cycle).
  for (const PlausibilityFinding& w : s.plausibility.warnings) {
    if (!warned_.insert(w.check + "|" + w.setting + "|" + w.try_value).second) continue;
    emit(out, s.now, EventKind::kPlausibilityWarning, Severity::kWarn, PlausibilityEvent{w});
  }
  const auto& stop = s.plausibility.stop;
  if (!stop) {
    stop_reported_.clear();
    return;
  }
  std::string key = stop->check + "|" + stop->setting + "|" + std::to_string(stop->since.count());
  if (key == stop_reported_) return;
  stop_reported_ = std::move(key);
  emit(out, s.now, EventKind::kPlausibilityStop, Severity::kError, PlausibilityEvent{*stop});
}

void DriverEventTracker::observe_refusal(const DriverSnapshot& s, std::vector<DriverEvent>& out) {
  const ControllerState& c = s.controller;
  if (refusal_ == c.refusal) return;
  const MotionRefusal before = refusal_.value_or(MotionRefusal::kLinkLost);
  refusal_ = c.refusal;
  emit(out, s.now, EventKind::kRefusalChanged, refusal_severity(s),
       RefusalEvent{before, c.refusal, describe_refusal(c, s.identification.get())});
}

void DriverEventTracker::observe_rearm(const DriverSnapshot& s, bool resumed,
                                       std::vector<DriverEvent>& out) {
  const StopCauses latched = s.controller.latched_causes;
  const StopCauses added = latched & ~latched_;
  if (added != 0) {
    emit(out, s.now, EventKind::kRearmLatched, Severity::kInfo, RearmEvent{added, false});
  } else if (latched == 0 && latched_ != 0) {
    emit(out, s.now, EventKind::kRearmCleared, Severity::kInfo, RearmEvent{latched_, resumed});
  }
  latched_ = latched;
}

void DriverEventTracker::observe_faults(const DriverSnapshot& s, std::vector<DriverEvent>& out) {
  const std::uint32_t word = s.controller.error_bits;
  const std::uint32_t changed = word ^ error_bits_;
  error_bits_ = word;
  for (int bit = 0; changed != 0 && bit < 32; ++bit) {
    if ((changed & (1u << bit)) == 0) continue;
    const bool raised = (word & (1u << bit)) != 0;
    emit(out, s.now, raised ? EventKind::kFaultRaised : EventKind::kFaultCleared,
         raised ? Severity::kWarn : Severity::kInfo, fault_of(bit, word, s.profile.error_word));
  }
}

void DriverEventTracker::observe_vendor(const DriverSnapshot& s, std::vector<DriverEvent>& out) {
  if (s.firmware.state == FirmwareVersion::State::kAnswered && s.firmware.text != firmware_) {
    firmware_ = s.firmware.text;
    emit(out, s.now, EventKind::kFirmwareVersion, Severity::kInfo, FirmwareEvent{firmware_});
  }
  if (s.controller.parked() != parked_) {
    parked_ = s.controller.parked();
    emit(out, s.now, EventKind::kParkChanged, Severity::kInfo, ParkEvent{parked_});
  }
  if (s.lights && (!lights_ || !same_lights(*s.lights, *lights_))) {
    lights_ = s.lights;
    emit(out, s.now, EventKind::kLightsChanged, Severity::kInfo, LightsEvent{*s.lights});
  }
}

void DriverEventTracker::command_refused(const Error& error, std::uint64_t count, Timestamp now,
                                         std::vector<DriverEvent>& out) {
  const bool not_finite = error.code == Errc::kNotFinite;
  Timestamp& next = not_finite ? next_not_finite_ : next_refused_;
  std::uint64_t& unreported = not_finite ? unreported_not_finite_ : unreported_refused_;
  unreported += count;
  if (now < next) return;
  next = now + (not_finite ? config_.not_finite_interval : config_.refused_interval);
  emit(out, now, EventKind::kCommandRefused, not_finite ? Severity::kError : Severity::kWarn,
       CommandRefusedEvent{error.code, error.message, unreported});
  unreported = 0;
}

void DriverEventTracker::frame_sent(const SentFrame& sent, Timestamp now,
                                    std::vector<DriverEvent>& out) {
  if (!std::holds_alternative<MotionCommand>(sent.message)) return;
  if (sent.shutdown) {
    emit(out, now, EventKind::kShutdownStop, Severity::kInfo,
         ShutdownEvent{true, sent.frame.id, {}});
    return;
  }
  if (!sent.solution || sent.solution->flags == kKinematicsExact || now < next_adjusted_) return;
  next_adjusted_ = now + config_.adjusted_interval;
  emit(out, now, EventKind::kCommandAdjusted, Severity::kWarn,
       CommandAdjustedEvent{sent.solution->flags});
}

void DriverEventTracker::no_stop_sent(std::string why, Timestamp now,
                                      std::vector<DriverEvent>& out) {
  emit(out, now, EventKind::kShutdownStop, Severity::kInfo,
       ShutdownEvent{false, 0, std::move(why)});
}

void DriverEventTracker::request_settled(const RequestOutcome& outcome, Timestamp now,
                                         std::vector<DriverEvent>& out) {
  emit(out, now, EventKind::kRequestSettled,
       outcome.state == RequestOutcome::State::kFailed ? Severity::kWarn : Severity::kInfo,
       RequestEvent{outcome});
}

void DriverEventTracker::motion_mode_requested(std::optional<protocol::MotionMode> mode,
                                               Timestamp now, std::vector<DriverEvent>& out) {
  emit(out, now, EventKind::kMotionModeRequested, Severity::kInfo, MotionModeEvent{mode});
}

void DriverEventTracker::frames_padded(std::uint32_t id, Timestamp now,
                                       std::vector<DriverEvent>& out) {
  emit(out, now, EventKind::kFramesPadded, Severity::kInfo,
       PaddedFramesEvent{id, protocol::frame_name(id)});
}

}  // namespace ranger
