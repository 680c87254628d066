#include "ranger_base/diagnostics.hpp"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include <ranger_can/wire/protocol.hpp>

namespace ranger_base {
namespace {

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;
namespace protocol = ranger::protocol;

std::string hex(std::uint32_t v, int width) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", width, v);
  return buf;
}

// A fault that stops the chassis is an ERROR; anything else it reports is a WARN.
bool stops_chassis(const ranger::ControllerState& c) {
  return c.estop || c.critical_error || c.low_battery;
}

}  // namespace

void diagnose_link(const LinkSnapshot& s, DiagnosticStatusWrapper& out) {
  out.add("Port", s.port_name);
  if (!s.bus_open) {
    out.summary(DiagnosticStatus::ERROR, "CAN interface " + s.port_name + " not open: " +
                                             (s.bus_error.empty() ? "opening" : s.bus_error));
    return;
  }
  out.add("Bus state", std::string(ranger::to_string(s.bus.state)));
  out.add("Bus detail", s.bus.detail);
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
  out.add("Undecodable frames", c.counters.decode_errors);
  out.add("Send failures", c.counters.send_failures);
  if (!c.last_error.empty()) out.add("Last error", c.last_error);

  switch (s.bus.state) {
    case ranger::BusState::kDown:
      out.summary(DiagnosticStatus::ERROR,
                  "CAN interface " + s.port_name + " down (reconnecting): " + s.bus.detail);
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
      out.mergeSummary(DiagnosticStatus::ERROR,
                       "no system status (0x211) from the chassis yet: is it powered on?");
      break;
    case ranger::LinkState::kStale:
      out.mergeSummary(DiagnosticStatus::ERROR, "chassis silent: no system status (0x211)");
      break;
  }
}

void diagnose_control(const LinkSnapshot& s, DiagnosticStatusWrapper& out) {
  const auto& c = s.controller;
  out.add("Control mode",
          c.control_mode ? std::string(protocol::to_string(*c.control_mode)) : "unknown");
  out.add("Motion mode",
          c.motion_mode ? std::string(protocol::to_string(*c.motion_mode)) : "unknown");
  out.add("Motion mode pinned",
          c.mode_override ? std::string(protocol::to_string(*c.mode_override)) : "automatic");
  out.add("Mode switch", std::string(ranger::to_string(c.mode_switch_phase)));
  out.add("Motion refused because", std::string(ranger::to_string(c.refusal)));
  out.add("cmd_vel timeouts", c.counters.cmd_timeouts);
  out.add("Motion commands sent", c.counters.motion_commands_sent);
  out.add("Control mode requests", c.counters.control_mode_requests);
  out.add("Mode switch requests", c.counters.mode_switch_requests);
  if (c.last_solution) {
    out.add("Last command limits", ranger::kinematics_flags_to_string(c.last_solution->flags));
  }

  if (!s.has_controller || c.link != ranger::LinkState::kConnected) {
    out.summary(DiagnosticStatus::ERROR, "no chassis");
  } else if (c.control_mode == protocol::ControlMode::kRemote) {
    out.summary(DiagnosticStatus::WARN, "remote control has the chassis: cmd_vel not applied");
  } else if (c.control_mode != protocol::ControlMode::kCan) {
    out.summary(DiagnosticStatus::WARN, c.awaiting_command_mode
                                            ? "standby: requesting CAN command mode"
                                            : "standby (auto_command_mode is off)");
  } else if (c.mode_switch_failed) {
    out.summary(DiagnosticStatus::ERROR, "motion-mode switch not confirmed by the chassis");
  } else if (c.refusal == ranger::MotionRefusal::kCmdTimeout) {
    out.summary(DiagnosticStatus::OK, "CAN command mode, idle (no recent cmd_vel)");
  } else if (c.refusal != ranger::MotionRefusal::kNone) {
    out.summary(DiagnosticStatus::WARN,
                "CAN command mode, motion refused: " + std::string(ranger::to_string(c.refusal)));
  } else {
    out.summary(DiagnosticStatus::OK, "CAN command mode");
  }
}

void diagnose_errors(const LinkSnapshot& s, DiagnosticStatusWrapper& out) {
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
  std::string list;
  for (const auto& fault : c.faults)
    list += (list.empty() ? "" : ", ") + fault;
  out.summary(stops_chassis(c) ? DiagnosticStatus::ERROR : DiagnosticStatus::WARN, list);
}

void diagnose_battery(const LinkSnapshot& s, DiagnosticStatusWrapper& out) {
  const auto& fb = s.controller.feedback;
  if (fb.system_status) out.add("Voltage (0x211)", fb.system_status->value.battery_voltage);
  const auto& pack = fb.bms[0];
  if (!pack) {
    out.summary(DiagnosticStatus::WARN, "no BMS report (0x361) yet");
    return;
  }
  const auto& d = pack->value;
  out.add("State of charge (%)", d.soc);
  out.add("State of health (%)", d.soh);
  out.add("Voltage (V)", d.voltage);
  out.add("Current (A)", d.current);
  out.add("Temperature (degC)", d.temperature);
  if (s.controller.low_battery) {
    out.summary(DiagnosticStatus::ERROR, "battery below the cut-off: the chassis refuses motion");
  } else if (d.soc < 15.0) {  // manual: the lights flash below 15 %
    out.summary(DiagnosticStatus::WARN, "battery low");
  } else {
    out.summary(DiagnosticStatus::OK, "battery ok");
  }
  if (const auto& alarm = fb.bms_alarm[0]) {
    const auto& a = alarm->value;
    if (a.alarm1 != 0 || a.alarm2 != 0) {
      out.mergeSummary(DiagnosticStatus::ERROR,
                       "BMS alarm " + hex(a.alarm1, 2) + " " + hex(a.alarm2, 2));
    } else if (a.warning1 != 0 || a.warning2 != 0) {
      out.mergeSummary(DiagnosticStatus::WARN,
                       "BMS warning " + hex(a.warning1, 2) + " " + hex(a.warning2, 2));
    }
  }
}

void FrameRateMonitor::diagnose(const LinkSnapshot& s, DiagnosticStatusWrapper& out) {
  out.add("Frames received", s.frames_received);
  if (!previous_time_ || s.now <= *previous_time_) {
    previous_time_ = s.now;
    previous_counts_ = s.frames_by_id;
    out.summary(DiagnosticStatus::OK, "measuring");
    return;
  }
  const double dt = ranger::seconds(s.now - *previous_time_);
  double total = 0.0;
  for (const auto& [id, count] : s.frames_by_id) {
    const auto before = previous_counts_.count(id) ? previous_counts_.at(id) : 0;
    const double rate = static_cast<double>(count - before) / dt;
    total += rate;
    char key[48];
    std::snprintf(key, sizeof key, "0x%03X %s (Hz)", id,
                  std::string(protocol::frame_name(id)).c_str());
    out.add(key, rate);
  }
  out.add("Total (frames/s)", total);
  // The system status arrives every 20 ms; well under half of that means frames are lost.
  const auto it = s.frames_by_id.find(protocol::kSystemStatusId);
  const auto before = previous_counts_.count(protocol::kSystemStatusId)
                          ? previous_counts_.at(protocol::kSystemStatusId)
                          : 0;
  const double status_rate =
      it == s.frames_by_id.end() ? 0.0 : static_cast<double>(it->second - before) / dt;
  const double nominal = 1000.0 / protocol::kFastPeriodMs;
  if (status_rate < 0.5 * nominal) {
    out.summary(DiagnosticStatus::WARN,
                "system status (0x211) at " + std::to_string(static_cast<int>(status_rate)) +
                    " Hz, expected " + std::to_string(static_cast<int>(nominal)));
  } else {
    out.summary(DiagnosticStatus::OK, std::to_string(static_cast<int>(total)) + " frames/s");
  }
  previous_time_ = s.now;
  previous_counts_ = s.frames_by_id;
}

ChassisDiagnostics::ChassisDiagnostics(diagnostic_updater::Updater& updater,
                                       const ChassisLink& link)
    : link_(link) {
  updater.add(kDiagLink, [this](DiagnosticStatusWrapper& out) { diagnose_link(current_, out); });
  updater.add(kDiagControl,
              [this](DiagnosticStatusWrapper& out) { diagnose_control(current_, out); });
  updater.add(kDiagErrors,
              [this](DiagnosticStatusWrapper& out) { diagnose_errors(current_, out); });
  updater.add(kDiagBattery,
              [this](DiagnosticStatusWrapper& out) { diagnose_battery(current_, out); });
  updater.add(kDiagFrameRates,
              [this](DiagnosticStatusWrapper& out) { rates_.diagnose(current_, out); });
}

void ChassisDiagnostics::refresh() {
  current_ = link_.snapshot();
}

}  // namespace ranger_base
