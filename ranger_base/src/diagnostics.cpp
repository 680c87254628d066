#include "ranger_base/diagnostics.hpp"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <ranger_can/text.hpp>
#include <ranger_can/transport/bus_source.hpp>

#include <algorithm>
#include <cstdio>
#include <string>

#include "ranger_base/conversions.hpp"

namespace ranger_base {
namespace {

using diagnostic_msgs::DiagnosticStatus;
namespace protocol = ranger::protocol;

using ranger::text::hex;

std::string join(const std::vector<std::string>& names) {
  return names.empty() ? "none" : ranger::text::join(names);
}

// A fault that stops the chassis is an ERROR; anything else it reports is a WARN.
bool stops_chassis(const ranger::ControllerState& c) {
  return c.estop() || c.critical_error() || c.low_battery();
}

}  // namespace

void diagnose_link(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  out.add("Port", s.bus_name);
  if (!s.bus_open) {
    out.summary(DiagnosticStatus::ERROR, "CAN interface " + s.bus_name + " not open: " +
                                             (s.bus_error.empty() ? "opening" : s.bus_error));
    return;
  }
  out.add("Bus state", std::string(ranger::to_string(s.bus.state)));
  out.add("Bus detail", s.bus.detail);
  out.add("Read only (replayed log)", s.read_only ? "yes" : "no");
  out.add("Frames received", s.bus.stats.rx_frames);
  out.add("Frames sent", s.bus.stats.tx_frames);
  out.add("Receive drops", s.bus.stats.rx_dropped);
  out.add("Transmit drops", s.bus.stats.tx_dropped);
  out.add("Error frames", s.bus.stats.error_frames);
  out.add("Bus-off restarts", s.bus.stats.restarts);
  out.add("Interface reopens", s.bus.stats.reopens);
  const auto& c = s.controller;
  out.add("Chassis link", std::string(ranger::to_string(c.link)));
  out.add("Chassis link losses", c.counters.link_losses);
  out.add("Firmware version",
          s.firmware.state == ranger::FirmwareVersion::State::kAnswered
              ? s.firmware.text
              : "unknown (" + std::string(ranger::to_string(s.firmware.state)) + ")");
  out.add("Vendor frames (0x231, 0x241)", std::string(ranger::to_string(s.vendor_frames)));
  out.add("Odometry published", s.motion_known ? "yes" : "no (chassis not heard)");
  out.add("Undecodable frames", c.counters.decode_errors);
  out.add("Send failures", c.counters.send_failures);
  if (!c.last_error.empty()) out.add("Last error", c.last_error);

  switch (s.bus.state) {
    case ranger::BusState::kDown:
      out.summary(DiagnosticStatus::ERROR,
                  "CAN interface " + s.bus_name + " down (reconnecting): " + s.bus.detail);
      return;
    case ranger::BusState::kBusOff:
      out.summary(DiagnosticStatus::ERROR, "CAN controller bus-off: " + s.bus.detail);
      return;
    case ranger::BusState::kErrorPassive:
    case ranger::BusState::kErrorWarning:
      out.summary(DiagnosticStatus::WARN, "CAN bus errors: " + s.bus.detail);
      break;
    case ranger::BusState::kActive:
      out.summary(DiagnosticStatus::OK, "CAN bus active");
      break;
  }
  switch (c.link) {
    case ranger::LinkState::kConnected:
      out.mergeSummary(DiagnosticStatus::OK, "chassis connected");
      break;
    case ranger::LinkState::kNeverConnected:
      if (listening(c) && s.frames.total() > 0) {
        // The identification listens before anything is sent: the chassis is heard, the
        // controller is kept out of it until the settings are proposed.
        out.summary(out.level, out.message + "; chassis heard (" +
                                   std::to_string(s.frames.total()) +
                                   " frames): listening before sending anything (identification)");
        break;
      }
      out.mergeSummary(DiagnosticStatus::ERROR,
                       "waiting for the chassis on " + s.bus_name +
                           ": nothing heard from it yet (is it powered on?)");
      break;
    case ranger::LinkState::kStale:
      out.mergeSummary(DiagnosticStatus::ERROR,
                       "chassis silent: no system status; odometry paused until it returns");
      break;
  }
}

namespace {
// The drive mode and the wheels' own odometers, where the chassis reports them (the RANGER MINI
// 3.0's 0x291 byte 2, 0x311/0x312 in metres).
void add_drive_mode_and_odometers(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  if (s.drive_mode) out.add("Drive mode", std::string(protocol::to_string(*s.drive_mode)));
  for (const auto* o : {&s.feedback.odometer, &s.feedback.rear_odometer}) {
    if (!*o || !(*o)->value.left_distance || !(*o)->value.right_distance) continue;
    const auto& v = (*o)->value;
    out.add(v.rear ? "Odometer rear left / right (m)" : "Odometer front left / right (m)",
            ranger::text::fixed(*v.left_distance, 3) + " / " +
                ranger::text::fixed(*v.right_distance, 3));
  }
}
}  // namespace

void diagnose_control(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  const auto& c = s.controller;
  out.add("Control mode",
          c.control_mode ? std::string(protocol::to_string(*c.control_mode)) : "unknown");
  out.add("Motion mode",
          c.motion_mode ? std::string(protocol::to_string(*c.motion_mode)) : "unknown");
  out.add("Motion mode pinned",
          c.mode_override ? std::string(protocol::to_string(*c.mode_override)) : "automatic");
  out.add("Mode switch", std::string(ranger::to_string(c.mode_switch.phase)));
  out.add("Park", c.park_requested ? (c.parked() ? "parked" : "parking") : "released");
  add_drive_mode_and_odometers(s, out);
  if (s.lights) {
    out.add("Lights", ranger::describe(s.lights->front, s.lights->front_brightness, s.lights->rear,
                                       s.lights->rear_brightness) +
                          (s.lights->can_control ? " (CAN)" : " (the chassis's own)"));
  }
  out.add("Motion refused because", std::string(ranger::to_string(c.refusal)));
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
    out.add("Last command limits", ranger::kinematics_flags_to_string(c.last_solution->flags));
  }
  const std::string detail = describe_refusal(s);
  const bool identification_failed =
      s.identification && s.identification->phase == ranger::IdentificationPhase::kFailed;

  if (s.bus_open && listening(c)) {
    out.summary(DiagnosticStatus::OK, "identifying the chassis: listening (nothing sent yet)");
  } else if (!s.bus_open || c.link != ranger::LinkState::kConnected) {
    out.summary(DiagnosticStatus::ERROR, "no chassis");
  } else if (c.control_mode == protocol::ControlMode::kRemote) {
    out.summary(DiagnosticStatus::WARN, "remote control has the chassis: cmd_vel not applied");
  } else if (c.control_mode != protocol::ControlMode::kCan) {
    out.summary(DiagnosticStatus::WARN, detail.empty() ? "standby" : detail);
  } else if (c.mode_switch.failed) {
    out.summary(DiagnosticStatus::ERROR, "motion-mode switch not confirmed by the chassis");
  } else if (c.refusal == ranger::MotionRefusal::kIdentifying) {
    if (identification_failed) {
      out.summary(DiagnosticStatus::ERROR,
                  "CAN command mode, motion refused: the chassis could not be identified (see "
                  "Protocol for what to set)");
    } else {
      out.summary(DiagnosticStatus::OK, "CAN command mode, " + detail);
    }
  } else if (c.refusal == ranger::MotionRefusal::kCmdTimeout) {
    out.summary(DiagnosticStatus::OK, "CAN command mode, idle (no recent cmd_vel)");
  } else if (c.refusal != ranger::MotionRefusal::kNone) {
    out.summary(DiagnosticStatus::WARN, "CAN command mode, motion refused: " + detail);
  } else if (!detail.empty()) {
    out.summary(DiagnosticStatus::OK, "CAN command mode, " + detail);
  } else {
    out.summary(DiagnosticStatus::OK, "CAN command mode");
  }
}

void diagnose_protocol(const DriverSnapshot& s, const ProtocolContext& context,
                       DiagnosticStatusWrapper& out) {
  out.add("Settings from",
          context.source.empty() ? std::string(ranger::to_string(s.protocol)) : context.source);
  out.add("Settings in use", ranger::describe(s.profile));
  for (const ranger::ProfileSetting& setting : ranger::profile_settings()) {
    const auto value = ranger::get_setting(s.profile, setting.name);
    out.add(std::string(setting.name), value ? *value : value.error().message);
  }

  std::string ok_summary = "settings " + ranger::describe(s.profile) + " (forced)";
  std::optional<std::string> failed;
  if (s.identification) {
    const ranger::IdentificationStatus& id = *s.identification;
    out.add("Identification", std::string(ranger::to_string(id.phase)));
    out.add("Identification message", id.message);
    out.add("Started from", id.revision);
    if (id.done()) out.add("Identification time (s)", ranger::seconds(id.elapsed()));
    if (id.decided_ok()) out.add("Confidence", id.confidence);
    for (std::size_t i = 0; i < id.evidence.size(); ++i)
      out.add("Evidence " + std::to_string(i + 1), id.evidence[i]);
    for (const ranger::IdentifiedSetting& d : id.decided)
      out.add("Decided " + d.name, d.value + " (" + d.evidence + ")");
    out.add("Undecided (the preset's value, checked while driving)", join(id.undecided));
    switch (id.phase) {
      case ranger::IdentificationPhase::kDecided:
        ok_summary = "identified: " + ranger::describe(s.profile);
        break;
      case ranger::IdentificationPhase::kFailed: {
        std::string message = id.message;
        const auto kind = ranger::bus_kind(context.port_name);
        if (kind && *kind == ranger::BusKind::kSocketCan) {
          message += " (on this robot: ranger_can commission " + context.port_name +
                     " --wheels-lifted --output FILE)";
        }
        failed = message;
        break;
      }
      case ranger::IdentificationPhase::kListening:
      case ranger::IdentificationPhase::kAwaitingControl:
      case ranger::IdentificationPhase::kSpinCheck:
      case ranger::IdentificationPhase::kSteerProbe:
      case ranger::IdentificationPhase::kReturning:
        ok_summary = "identifying the chassis (" + std::string(ranger::to_string(id.phase)) +
                     "): nothing is driven until it is decided";
        break;
    }
  }

  const ranger::PlausibilityStatus& plausibility = s.plausibility;
  out.add("Plausibility checks", plausibility.checks);
  for (std::size_t i = 0; i < plausibility.warnings.size(); ++i)
    out.add("Plausibility warning " + std::to_string(i + 1), plausibility.warnings[i].text());
  if (plausibility.stop) out.add("Plausibility stop", plausibility.stop->text());

  if (plausibility.stop) {
    out.summary(
        DiagnosticStatus::ERROR,
        "stopped: the chassis contradicts the protocol settings: " + plausibility.stop->text() +
            ". Set that parameter (or load a commissioning file); resume tries again");
  } else if (failed) {
    out.summary(DiagnosticStatus::ERROR, *failed);
  } else {
    out.summary(DiagnosticStatus::OK, ok_summary);
  }
  for (const ranger::PlausibilityFinding& w : plausibility.warnings) {
    if (plausibility.stop && w.text() == plausibility.stop->text()) continue;
    out.mergeSummary(DiagnosticStatus::WARN, "check the setting: " + w.text());
  }
}

void diagnose_errors(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  const auto& c = s.controller;
  out.add("Error word", hex(c.error_bits, 8));
  out.add("Vehicle status",
          c.vehicle_status ? std::string(protocol::to_string(*c.vehicle_status)) : "unknown");
  for (const auto& fault : c.faults)
    out.add(fault, "active");
  if (c.faults.empty()) {
    out.summary(DiagnosticStatus::OK, "no faults");
    return;
  }
  out.summary(stops_chassis(c) ? DiagnosticStatus::ERROR : DiagnosticStatus::WARN, join(c.faults));
}

void diagnose_battery(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  const auto& fb = s.feedback;
  namespace spec = ranger::vehicle_spec;
  out.add("Technology", std::string(spec::kBatteryChemistry));
  out.add("Nominal voltage (V)", spec::kBatteryNominalVoltage);
  out.add("Normal voltage range (V)",
          std::to_string(static_cast<int>(spec::kBatteryNormalMinVoltage)) + "-" +
              std::to_string(static_cast<int>(spec::kBatteryNormalMaxVoltage)));
  if (fb.system_status) out.add("Voltage (system status)", fb.system_status->value.battery_voltage);
  const auto& pack = fb.bms[0];
  if (!pack) {
    out.summary(DiagnosticStatus::WARN, "no BMS report yet");
    return;
  }
  const auto& d = pack->value;
  out.add("State of charge (%)", d.soc);
  out.add("State of health (%)", d.soh);
  out.add("Voltage (V)", d.voltage);
  out.add("Current (A)", d.current);
  out.add("Temperature (degC)", d.temperature);
  if (s.controller.low_battery()) {
    out.summary(DiagnosticStatus::ERROR, "battery below the cut-off: the chassis refuses motion");
  } else if (d.soc < ranger::vehicle_spec::kLowBatteryWarningSoc) {  // the lights flash
    out.summary(DiagnosticStatus::WARN, "battery low");
  } else {
    out.summary(DiagnosticStatus::OK, "battery ok");
  }
  if (const auto& alarm = fb.bms_alarm[0]) {
    const auto& a = alarm->value;
    out.add("BMS alarms", join(protocol::bms_status_names(a.alarm1, a.alarm2)));
    out.add("BMS warnings", join(protocol::bms_status_names(a.warning1, a.warning2)));
    if (a.alarm1 != 0 || a.alarm2 != 0) {
      out.mergeSummary(DiagnosticStatus::ERROR,
                       "BMS alarm " + hex(a.alarm1, 2) + " " + hex(a.alarm2, 2));
    } else if (a.warning1 != 0 || a.warning2 != 0) {
      out.mergeSummary(DiagnosticStatus::WARN,
                       "BMS warning " + hex(a.warning1, 2) + " " + hex(a.warning2, 2));
    }
  }
}

void FrameRateMonitor::diagnose(const DriverSnapshot& s, DiagnosticStatusWrapper& out) {
  out.add("Frames received", s.frames.total());
  out.add("Rate window (s)", ranger::seconds(s.frames.window()));
  double total = 0.0;
  std::uint64_t new_rejects = 0, padded = 0;
  std::map<std::uint32_t, std::uint64_t> rejected;
  for (const auto& id : s.frames.counts()) {
    const double rate = s.frames.rate(id.id, s.now);
    total += rate;
    char key[64];
    std::snprintf(key, sizeof key, "0x%03X %s (Hz)", id.id,
                  std::string(protocol::frame_name(id.id)).c_str());
    out.add(key, rate);
    if (id.rejected > 0) {
      std::snprintf(key, sizeof key, "0x%03X rejected", id.id);
      out.add(key, id.rejected);
    }
    if (id.padded > 0) {
      std::snprintf(key, sizeof key, "0x%03X longer than its layout", id.id);
      out.add(key, id.padded);
    }
    padded += id.padded;
    rejected[id.id] = id.rejected;
    const auto it = previous_rejected_.find(id.id);
    new_rejects += id.rejected - (it == previous_rejected_.end() ? 0 : it->second);
  }
  out.add("Total (frames/s)", total);
  out.add("Padded frames", padded);
  previous_rejected_ = std::move(rejected);
  if (s.frames.total() == 0) {
    out.summary(DiagnosticStatus::WARN, "no frames received");
  } else if (new_rejects > 0) {
    out.summary(DiagnosticStatus::WARN, std::to_string(new_rejects) +
                                            " frame(s) rejected since the last report (content "
                                            "the protocol settings cannot decode)");
  } else {
    out.summary(DiagnosticStatus::OK, std::to_string(static_cast<int>(total)) + " frames/s");
  }
}

ChassisDiagnostics::ChassisDiagnostics(diagnostic_updater::Updater& updater, SnapshotSource source,
                                       ProtocolContext protocol)
    : source_(std::move(source)),
      protocol_(std::move(protocol)),
      current_(std::make_shared<DriverSnapshot>()) {
  updater.add(kDiagLink, [this](DiagnosticStatusWrapper& out) { diagnose_link(*current_, out); });
  updater.add(kDiagControl,
              [this](DiagnosticStatusWrapper& out) { diagnose_control(*current_, out); });
  updater.add(kDiagProtocol, [this](DiagnosticStatusWrapper& out) {
    diagnose_protocol(*current_, protocol_, out);
  });
  updater.add(kDiagErrors,
              [this](DiagnosticStatusWrapper& out) { diagnose_errors(*current_, out); });
  updater.add(kDiagBattery,
              [this](DiagnosticStatusWrapper& out) { diagnose_battery(*current_, out); });
  updater.add(kDiagFrameRates,
              [this](DiagnosticStatusWrapper& out) { rates_.diagnose(*current_, out); });
}

void ChassisDiagnostics::refresh() {
  current_ = source_();
}

}  // namespace ranger_base
