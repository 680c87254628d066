#include "ranger_can/control/diagnostics.hpp"

#include <cmath>
#include <optional>

#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/text.hpp"

namespace ranger {
namespace {

using L = DiagnosticLevel;
using text::hex;

std::string join(const std::vector<std::string>& names) {
  return names.empty() ? "none" : text::join(names);
}

DiagnosticGroup named(std::string_view name) {
  DiagnosticGroup g;
  g.name = std::string(name);
  return g;
}

// A fault that stops the chassis is an ERROR; anything else it reports is a WARN.
bool stops_chassis(const ControllerState& c) {
  return c.estop() || c.critical_error() || c.low_battery();
}

template <typename Enum>
std::string name_or_unknown(const std::optional<Enum>& v, const char* unknown = "unknown") {
  return v ? std::string(to_string(*v)) : std::string(unknown);
}

// The link group's summary from the bus state and the chassis link (the values are added).
void summarise_link(const DriverSnapshot& s, DiagnosticGroup& out) {
  switch (s.bus.state) {
    case BusState::kDown:
      out.summary(L::kError,
                  "CAN interface " + s.bus_name + " down (reconnecting): " + s.bus.detail);
      return;
    case BusState::kBusOff:
      out.summary(L::kError, "CAN controller bus-off: " + s.bus.detail);
      return;
    case BusState::kErrorPassive:
    case BusState::kErrorWarning:
      out.summary(L::kWarn, "CAN bus errors: " + s.bus.detail);
      break;
    case BusState::kActive:
      out.summary(L::kOk, "CAN bus active");
      break;
  }
  const ControllerState& c = s.controller;
  switch (c.link) {
    case LinkState::kConnected:
      out.merge_summary(L::kOk, "chassis connected");
      break;
    case LinkState::kNeverConnected:
      if (listening(c) && s.frames.total() > 0) {
        // The identification listens before anything is sent: the chassis is heard, the
        // controller is kept out of it until the settings are proposed.
        out.summary(out.level, out.message + "; chassis heard (" +
                                   std::to_string(s.frames.total()) +
                                   " frames): listening before sending anything (identification)");
        break;
      }
      out.merge_summary(L::kError, "waiting for the chassis on " + s.bus_name +
                                       ": nothing heard from it yet (is it powered on?)");
      break;
    case LinkState::kStale:
      out.merge_summary(L::kError,
                        "chassis silent: no system status; odometry paused until it returns");
      break;
  }
}

// The control group's summary: who has the chassis and why motion is refused, if it is.
void summarise_control(const DriverSnapshot& s, DiagnosticGroup& out) {
  const ControllerState& c = s.controller;
  const std::string detail = describe_refusal(s);
  const bool identification_failed =
      s.identification && s.identification->phase == IdentificationPhase::kFailed;
  if (s.bus_open && listening(c)) {
    out.summary(L::kOk, "identifying the chassis: listening (nothing sent yet)");
  } else if (!s.bus_open || c.link != LinkState::kConnected) {
    out.summary(L::kError, "no chassis");
  } else if (c.control_mode == ControlMode::kRemote) {
    out.summary(L::kWarn, "remote control has the chassis: cmd_vel not applied");
  } else if (c.control_mode != ControlMode::kCan) {
    out.summary(L::kWarn, detail.empty() ? "standby" : detail);
  } else if (c.mode_switch.failed) {
    out.summary(L::kError, "motion-mode switch not confirmed by the chassis");
  } else if (c.refusal == MotionRefusal::kIdentifying && identification_failed) {
    out.summary(L::kError,
                "CAN command mode, motion refused: the chassis could not be identified (see "
                "Protocol for what to set)");
  } else if (c.refusal == MotionRefusal::kCmdTimeout) {
    out.summary(L::kOk, "CAN command mode, idle (no recent cmd_vel)");
  } else if (c.refusal != MotionRefusal::kNone && c.refusal != MotionRefusal::kIdentifying) {
    out.summary(L::kWarn, "CAN command mode, motion refused: " + detail);
  } else {
    out.summary(L::kOk, detail.empty() ? "CAN command mode" : "CAN command mode, " + detail);
  }
}

// The identification's values; what the Protocol group says while it runs or once it ended
// (`failed` set when it failed).
std::string add_identification(const IdentificationStatus& id, const DriverSnapshot& s,
                               const DiagnosticContext& context, DiagnosticGroup& out,
                               std::optional<std::string>& failed) {
  out.add("Identification", std::string(to_string(id.phase)));
  out.add("Identification message", id.message);
  out.add("Started from", id.revision);
  if (id.done()) out.add("Identification time (s)", seconds(id.elapsed()));
  if (id.decided_ok()) out.add("Confidence", id.confidence);
  for (std::size_t i = 0; i < id.evidence.size(); ++i)
    out.add("Evidence " + std::to_string(i + 1), id.evidence[i]);
  for (const IdentifiedSetting& d : id.decided)
    out.add("Decided " + d.name, d.value + " (" + d.evidence + ")");
  out.add("Undecided (the preset's value, checked while driving)", join(id.undecided));
  switch (id.phase) {
    case IdentificationPhase::kDecided:
      return "identified: " + describe(s.profile);
    case IdentificationPhase::kFailed: {
      std::string message = id.message;
      const auto kind = bus_kind(context.port_name);
      if (kind && *kind == BusKind::kSocketCan) {
        message += " (on this robot: ranger_can commission " + context.port_name +
                   " --wheels-lifted --output FILE)";
      }
      failed = message;
      return "";
    }
    case IdentificationPhase::kListening:
    case IdentificationPhase::kAwaitingControl:
    case IdentificationPhase::kSpinCheck:
    case IdentificationPhase::kSteerProbe:
    case IdentificationPhase::kReturning:
      break;
  }
  return "identifying the chassis (" + std::string(to_string(id.phase)) +
         "): nothing is driven until it is decided";
}

}  // namespace

void DiagnosticGroup::merge_summary(DiagnosticLevel l, const std::string& m) {
  if (l != L::kOk && level != L::kOk) {
    if (!message.empty()) message += "; ";
    message += m;
  } else if (l > level) {
    message = m;
  }
  if (l > level) level = l;
}

const std::string* DiagnosticGroup::value(std::string_view key) const {
  for (const auto& [k, v] : values) {
    if (k == key) return &v;
  }
  return nullptr;
}

std::string to_text(const DiagnosticGroup& group) {
  std::string out =
      group.name + ": " + std::string(to_string(group.level)) + ": " + group.message + "\n";
  for (const auto& [key, value] : group.values)
    out += "  " + key + ": " + value + "\n";
  return out;
}

std::string hardware_id(const std::string& ns, const std::string& port_name) {
  return "ranger:" + (ns.empty() ? std::string("/") : ns) + ":" + port_name;
}

DiagnosticGroup diagnose_link(const DriverSnapshot& s) {
  DiagnosticGroup out = named(kDiagLink);
  out.add("Port", s.bus_name);
  if (!s.bus_open) {
    out.summary(L::kError, "CAN interface " + s.bus_name +
                               " not open: " + (s.bus_error.empty() ? "opening" : s.bus_error));
    return out;
  }
  out.add("Bus state", std::string(to_string(s.bus.state)));
  out.add("Bus detail", s.bus.detail);
  out.add("Read only (replayed log)", s.read_only ? "yes" : "no");
  out.add("Frames received", s.bus.stats.rx_frames);
  out.add("Frames sent", s.bus.stats.tx_frames);
  out.add("Receive drops", s.bus.stats.rx_dropped);
  out.add("Transmit drops", s.bus.stats.tx_dropped);
  out.add("Error frames", s.bus.stats.error_frames);
  out.add("Bus-off restarts", s.bus.stats.restarts);
  out.add("Interface reopens", s.bus.stats.reopens);
  const ControllerState& c = s.controller;
  out.add("Chassis link", std::string(to_string(c.link)));
  out.add("Chassis link losses", c.counters.link_losses);
  out.add("Firmware version", s.firmware.state == FirmwareVersion::State::kAnswered
                                  ? s.firmware.text
                                  : "unknown (" + std::string(to_string(s.firmware.state)) + ")");
  out.add("Vendor frames (0x231, 0x241)", std::string(to_string(s.vendor_frames)));
  out.add("Odometry published", s.motion_known ? "yes" : "no (chassis not heard)");
  out.add("Undecodable frames", c.counters.decode_errors);
  out.add("Send failures", c.counters.send_failures);
  if (!c.last_error.empty()) out.add("Last error", c.last_error);
  summarise_link(s, out);
  return out;
}

DiagnosticGroup diagnose_control(const DriverSnapshot& s) {
  DiagnosticGroup out = named(kDiagControl);
  const ControllerState& c = s.controller;
  out.add("Control mode", name_or_unknown(c.control_mode));
  out.add("Motion mode", name_or_unknown(c.motion_mode));
  out.add("Motion mode pinned", name_or_unknown(c.mode_override, "automatic"));
  out.add("Mode switch", std::string(to_string(c.mode_switch.phase)));
  out.add("Park", c.park_requested ? (c.parked() ? "parked" : "parking") : "released");
  if (s.lights) {
    out.add("Lights", describe(s.lights->front, s.lights->front_brightness, s.lights->rear,
                               s.lights->rear_brightness) +
                          (s.lights->can_control ? " (CAN)" : " (the chassis's own)"));
  }
  out.add("Motion refused because", std::string(to_string(c.refusal)));
  out.add("Re-arm required", c.rearm_required() ? "yes" : "no");
  out.add("Latched stop causes", join(cause_names(c.latched_causes)));
  out.add("Active stop causes", join(cause_names(c.active_causes)));
  out.add("CAN control blocked after remote", c.reclaim_blocked ? "yes (call resume)" : "no");
  out.add("Steer-first speed factor", c.steer_first_factor);
  out.add("cmd_vel timeouts", c.counters.cmd_timeouts);
  out.add("Re-arms", c.counters.rearms);
  out.add("Motion commands sent", c.counters.motion_commands_sent);
  out.add("Control mode requests", c.counters.control_mode_requests);
  out.add("Mode switch requests", c.counters.mode_switch_requests);
  if (c.last_solution) {
    out.add("Last command limits", kinematics_flags_to_string(c.last_solution->flags));
  }
  summarise_control(s, out);
  return out;
}

DiagnosticGroup diagnose_protocol(const DriverSnapshot& s, const DiagnosticContext& context) {
  DiagnosticGroup out = named(kDiagProtocol);
  out.add("Settings from", context.settings_source.empty() ? std::string(to_string(s.protocol))
                                                           : context.settings_source);
  out.add("Settings in use", describe(s.profile));
  for (const ProfileSetting& setting : profile_settings()) {
    const auto value = get_setting(s.profile, setting.name);
    out.add(std::string(setting.name), value ? *value : value.error().message);
  }
  std::string ok_summary = "settings " + describe(s.profile) + " (forced)";
  std::optional<std::string> failed;
  if (s.identification) ok_summary = add_identification(*s.identification, s, context, out, failed);

  const PlausibilityStatus& plausibility = s.plausibility;
  out.add("Plausibility checks", plausibility.checks);
  for (std::size_t i = 0; i < plausibility.warnings.size(); ++i)
    out.add("Plausibility warning " + std::to_string(i + 1), plausibility.warnings[i].text());
  if (plausibility.stop) out.add("Plausibility stop", plausibility.stop->text());

  if (plausibility.stop) {
    out.summary(L::kError, "stopped: the chassis contradicts the protocol settings: " +
                               plausibility.stop->text() +
                               ". Set that parameter (or load a commissioning file); resume "
                               "tries again");
  } else if (failed) {
    out.summary(L::kError, *failed);
  } else {
    out.summary(L::kOk, ok_summary);
  }
  for (const PlausibilityFinding& w : plausibility.warnings) {
    if (plausibility.stop && w.text() == plausibility.stop->text()) continue;
    out.merge_summary(L::kWarn, "check the setting: " + w.text());
  }
  return out;
}

DiagnosticGroup diagnose_errors(const DriverSnapshot& s) {
  DiagnosticGroup out = named(kDiagErrors);
  const ControllerState& c = s.controller;
  out.add("Error word", hex(c.error_bits, 8));
  out.add("Vehicle status", name_or_unknown(c.vehicle_status));
  for (const auto& fault : c.faults)
    out.add(fault, "active");
  if (c.faults.empty()) {
    out.summary(L::kOk, "no faults");
  } else {
    out.summary(stops_chassis(c) ? L::kError : L::kWarn, join(c.faults));
  }
  return out;
}

DiagnosticGroup diagnose_battery(const DriverSnapshot& s) {
  DiagnosticGroup out = named(kDiagBattery);
  const ChassisFeedback& fb = s.feedback;
  namespace spec = vehicle_spec;
  out.add("Technology", std::string(spec::kBatteryChemistry));
  out.add("Nominal voltage (V)", spec::kBatteryNominalVoltage);
  out.add("Normal voltage range (V)",
          std::to_string(static_cast<int>(spec::kBatteryNormalMinVoltage)) + "-" +
              std::to_string(static_cast<int>(spec::kBatteryNormalMaxVoltage)));
  if (fb.system_status) out.add("Voltage (system status)", fb.system_status->value.battery_voltage);
  const auto& pack = fb.bms[0];
  if (!pack) {
    out.summary(L::kWarn, "no BMS report yet");
    return out;
  }
  const BmsData& d = pack->value;
  out.add("State of charge (%)", d.soc);
  out.add("State of health (%)", d.soh);
  out.add("Voltage (V)", d.voltage);
  out.add("Current (A)", d.current);
  out.add("Temperature (degC)", d.temperature);
  if (s.controller.low_battery()) {
    out.summary(L::kError, "battery below the cut-off: the chassis refuses motion");
  } else if (d.soc < spec::kLowBatteryWarningSoc) {  // the lights flash
    out.summary(L::kWarn, "battery low");
  } else {
    out.summary(L::kOk, "battery ok");
  }
  if (const auto& alarm = fb.bms_alarm[0]) {
    const auto& a = alarm->value;
    if (a.alarm1 != 0 || a.alarm2 != 0) {
      out.merge_summary(L::kError, "BMS alarm " + hex(a.alarm1, 2) + " " + hex(a.alarm2, 2));
    } else if (a.warning1 != 0 || a.warning2 != 0) {
      out.merge_summary(L::kWarn, "BMS warning " + hex(a.warning1, 2) + " " + hex(a.warning2, 2));
    }
  }
  return out;
}

DiagnosticGroup FrameRateMonitor::diagnose(const DriverSnapshot& s) {
  DiagnosticGroup out = named(kDiagFrameRates);
  out.add("Frames received", s.frames.total());
  out.add("Rate window (s)", seconds(s.frames.window()));
  double total = 0.0;
  std::uint64_t new_rejects = 0, padded = 0;
  std::map<std::uint32_t, std::uint64_t> rejected;
  for (const auto& id : s.frames.counts()) {
    const double rate = s.frames.rate(id.id, s.now);
    total += rate;
    out.add(hex(id.id) + " " + std::string(frame_name(id.id)) + " (Hz)", rate);
    if (id.rejected > 0) out.add(hex(id.id) + " rejected", id.rejected);
    if (id.padded > 0) out.add(hex(id.id) + " longer than its layout", id.padded);
    padded += id.padded;
    rejected[id.id] = id.rejected;
    const auto it = previous_rejected_.find(id.id);
    new_rejects += id.rejected - (it == previous_rejected_.end() ? 0 : it->second);
  }
  out.add("Total (frames/s)", total);
  out.add("Padded frames", padded);
  previous_rejected_ = std::move(rejected);
  if (s.frames.total() == 0) {
    out.summary(L::kWarn, "no frames received");
  } else if (new_rejects > 0) {
    out.summary(L::kWarn, std::to_string(new_rejects) +
                              " frame(s) rejected since the last report (content the protocol "
                              "settings cannot decode)");
  } else {
    out.summary(L::kOk, std::to_string(static_cast<int>(total)) + " frames/s");
  }
  return out;
}

DiagnosticGroup ChassisDiagnostics::group(std::size_t index, const DriverSnapshot& s) {
  switch (index) {
    case 0:
      return diagnose_link(s);
    case 1:
      return diagnose_control(s);
    case 2:
      return diagnose_protocol(s, context_);
    case 3:
      return diagnose_errors(s);
    case 4:
      return diagnose_battery(s);
    default:
      return rates_.diagnose(s);
  }
}

std::vector<DiagnosticGroup> ChassisDiagnostics::report(const DriverSnapshot& s) {
  std::vector<DiagnosticGroup> out;
  for (std::size_t i = 0; i < kDiagnosticGroups.size(); ++i)
    out.push_back(group(i, s));
  return out;
}

bool listening(const ControllerState& c) {
  return c.quiet && c.identifying.has_value();
}

std::string refusal_name(const ControllerState& c) {
  if (c.refusal == MotionRefusal::kNone) return "";
  return std::string(to_string(c.refusal));
}

std::string describe_refusal(const DriverSnapshot& snapshot) {
  return describe_refusal(snapshot.controller, snapshot.identification.get());
}

std::vector<std::string> cause_names(StopCauses causes) {
  std::vector<std::string> out;
  const std::string all = describe(causes);  // "emergency_stop,remote"
  std::size_t start = 0;
  while (start < all.size()) {
    const std::size_t comma = all.find(',', start);
    const std::size_t end = comma == std::string::npos ? all.size() : comma;
    out.push_back(all.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

}  // namespace ranger
