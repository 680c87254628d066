#include "cli_monitor_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>
#include <vector>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/json.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::cli {

namespace {

using text::format;

struct Style {
  bool color;
  std::string red(const std::string& s) const { return color ? "\x1b[31m" + s + "\x1b[0m" : s; }
  std::string yellow(const std::string& s) const { return color ? "\x1b[33m" + s + "\x1b[0m" : s; }
  std::string green(const std::string& s) const { return color ? "\x1b[32m" + s + "\x1b[0m" : s; }
  std::string bold(const std::string& s) const { return color ? "\x1b[1m" + s + "\x1b[0m" : s; }
};

// A REP-103 angle shown unambiguously: "12.50 deg left".
std::string rep103_steering_text(double rep103_rad) {
  const double rep = rad_to_deg(rep103_rad);
  if (std::abs(rep) < 0.005) return "  0.00 deg straight";
  return format("%6.2f deg ", std::abs(rep)) + (rep > 0 ? "left " : "right");
}
// 0x221's and 0x111's angles in the manual's signs; each frame has its own reading.
std::string steering_text(double manual_rad) {
  return rep103_steering_text(interpretation::rep103_from_manual_steering(manual_rad));
}
std::string command_steering_text(double manual_rad) {
  return rep103_steering_text(interpretation::rep103_from_manual_command_steering(manual_rad));
}
std::string wheel_angle_text(double manual_rad) {
  const double rep = rad_to_deg(interpretation::rep103_from_manual_wheel_angle(manual_rad));
  if (std::abs(rep) < 0.005) return "  0.00 deg      ";
  return format("%6.2f deg ", std::abs(rep)) + (rep > 0 ? "left " : "right");
}

std::string age_text(Timestamp received, Timestamp now) {
  const double ms = std::chrono::duration<double, std::milli>(now - received).count();
  if (ms < 1000) return format("%.0f ms ago", ms);
  return format("%.1f s ago", ms / 1000);
}

// Nominal frames per second of a feedback ID (0 for commands and on-change frames): the frame
// table's period.
double nominal_rate(std::uint32_t id) {
  const protocol::FrameInfo* f = protocol::find_frame(id);
  if (f == nullptr || f->direction != protocol::Direction::kFromChassis || f->period_ms == 0) {
    return 0.0;
  }
  return 1000.0 / f->period_ms;
}

std::string ultrasonic_text(std::int16_t raw) {
  if (raw >= 0) return std::to_string(raw) + " mm";
  return std::string(protocol::ultrasonic_status_name(raw));
}

// The names of the bits set in one BMS status pair, "none" for none.
std::string bms_names(std::uint8_t s1, std::uint8_t s2) {
  std::vector<std::string_view> out;
  for (const auto& bit : protocol::bms_status1_bits()) {
    if (s1 & (1u << bit.index)) out.push_back(bit.name);
  }
  for (const auto& bit : protocol::bms_status2_bits()) {
    if (s2 & (1u << bit.index)) out.push_back(bit.name);
  }
  return out.empty() ? std::string("none") : text::join(out, ",");
}

}  // namespace

void ChassisMonitor::on_frame(const CanFrame& frame, Timestamp now) {
  if (frame.is_error) {
    ++error_frames_;
    return;
  }
  auto decoded = decode(frame, profile_);
  stats_.record(frame.id, now, decoded.ok(), protocol::extra_bytes(frame));
  if (!decoded) {
    ++decode_errors_;
    return;
  }
  // The chassis's feedback goes to the store the driver uses; the host's commands (other nodes
  // driving this chassis) are kept here.
  if (fb_.record(*decoded, frame.stamp, now)) return;
  if (const auto* m = std::get_if<MotionCommand>(&*decoded)) {
    motion_command_ = Seen<MotionCommand>{*m, now};
  } else if (const auto* mm = std::get_if<MotionModeCommand>(&*decoded)) {
    motion_mode_command_ = Seen<MotionModeCommand>{*mm, now};
  } else if (const auto* cm = std::get_if<ControlModeCommand>(&*decoded)) {
    control_mode_command_ = Seen<ControlModeCommand>{*cm, now};
  } else if (const auto* ec = std::get_if<ErrorClearCommand>(&*decoded)) {
    error_clear_command_ = Seen<ErrorClearCommand>{*ec, now};
  }
}

double ChassisMonitor::rate(std::uint32_t id, Timestamp now) const {
  return stats_.rate(id, now);
}

std::string ChassisMonitor::render_text(std::string_view iface, const BusStatus& bus, Timestamp now,
                                        bool color) const {
  return text_header(iface, bus, now, color) + text_chassis(now, color) + text_motion(color) +
         text_host(now, color) + text_wheels(color) + text_batteries(color) + text_ultrasonic() +
         text_vendor() + text_rates(now, color);
}

std::string ChassisMonitor::text_header(std::string_view iface, const BusStatus& bus, Timestamp now,
                                        bool color) const {
  const Style st{color};
  std::string bus_state(to_string(bus.state));
  bus_state = bus.state == BusState::kActive ? st.green(bus_state) : st.red(bus_state);
  double total_rate = 0;
  for (const FrameIdCounts& c : stats_.counts())
    total_rate += rate(c.id, now);
  return st.bold("RANGER monitor  " + std::string(iface)) + "   bus " + bus_state +
         (bus.detail.empty() ? "" : " (" + bus.detail + ")") + "   frames " +
         std::to_string(stats_.total()) + format("  %.0f/s", total_rate) + "   undecodable " +
         std::to_string(decode_errors_) + "   error frames " +
         std::to_string(error_frames_ + bus.stats.error_frames) + "   dropped rx/tx " +
         std::to_string(bus.stats.rx_dropped) + "/" + std::to_string(bus.stats.tx_dropped) + "\n";
}

std::string ChassisMonitor::text_chassis(Timestamp now, bool color) const {
  const Style st{color};
  if (!fb_.system_status) {
    return st.red(stats_.total() == 0 ? "no frames received yet: is the chassis on and the bus up?"
                                      : "no 0x211 system status received yet") +
           "\n";
  }
  const auto& s = fb_.system_status->value;
  const bool stale = now - fb_.system_status->received > std::chrono::milliseconds(500);
  std::string control(protocol::to_string(s.control_mode));
  if (s.control_mode != protocol::ControlMode::kCan) control = st.yellow(control);
  std::string vehicle(protocol::to_string(s.vehicle_status));
  if (s.vehicle_status != protocol::VehicleStatus::kNormal) vehicle = st.red(vehicle);
  std::string age = "last 0x211 " + age_text(fb_.system_status->received, now);
  if (stale) age = st.red(age + "  CHASSIS SILENT");
  std::string out = "Chassis   control " + control + "   vehicle " + vehicle +
                    format("   battery %.1f V", s.battery_voltage) + "   " + age + "\n";
  const auto names = protocol::error_bit_names(s.error_bits, profile_.error_word);
  if (names.empty()) return out + "Errors    " + st.green("none") + "\n";
  return out + "Errors    " + st.red(text::join(names)) + "  (" + text::hex(s.error_bits, 8) +
         ")\n";
}

std::string ChassisMonitor::text_motion(bool color) const {
  const Style st{color};
  std::string motion = "Motion    mode ";
  if (fb_.motion_mode) {
    const auto& m = fb_.motion_mode->value;
    motion += std::string(protocol::to_string(m.mode));
    motion += m.switching ? "   " + st.yellow("SWITCHING") : "   switching no";
  } else {
    motion += "?";
  }
  if (fb_.motion) {
    const auto& m = fb_.motion->value;
    motion +=
        format("   speed %+.3f m/s", m.speed) + "   steering " + steering_text(m.steering_angle);
  }
  return motion + "\n";
}

std::string ChassisMonitor::text_host(Timestamp now, bool color) const {
  const Style st{color};
  std::string host = "Host      ";
  if (motion_command_) {
    const auto& c = motion_command_->value;
    host += format("0x111 speed %+.3f m/s", c.linear_speed) + "  steer " +
            command_steering_text(c.steering_angle) + format("  spin %+.3f m/s", c.spin_speed) +
            "  (" + age_text(motion_command_->received, now) +
            format(", %.1f/s)", rate(protocol::kMotionCommandId, now));
  } else {
    host += st.yellow("no 0x111 seen");
  }
  if (control_mode_command_) {
    host += "   0x421 " + std::string(protocol::to_string(control_mode_command_->value.mode));
  }
  if (motion_mode_command_) {
    host += "   0x141 " + std::string(protocol::to_string(motion_mode_command_->value.mode));
  }
  if (error_clear_command_) {
    host += format("   0x441 %.0f", static_cast<double>(error_clear_command_->value.code));
  }
  return host + "\n";
}

std::string ChassisMonitor::text_wheels(bool color) const {
  std::string out =
      "Wheels         steering           speed      drive rpm      A   steer rpm      A   drv/mot "
      "degC  driver status\n";
  for (int i = 0; i < kWheelCount; ++i)
    out += text_wheel(i, color) + "\n";
  return out;
}

std::string ChassisMonitor::text_wheel(int i, bool color) const {
  const Style st{color};
  std::string row = "  " + std::string(kWheelNames[i]);
  row.resize(14, ' ');
  row += fb_.steering_angles ? wheel_angle_text(fb_.steering_angles->value.angles[i])
                             : std::string("      ?         ");
  row += fb_.wheel_speeds ? format("  %+7.3f m/s", fb_.wheel_speeds->value.speeds[i])
                          : "        ?    ";
  for (const auto& motor : {fb_.motor_high_speed[i], fb_.motor_high_speed[i + kWheelCount]}) {
    row += motor ? format("  %+9.1f", motor->value.rpm) + format(" %+6.1f", motor->value.current)
                 : "          ?      ?";
  }
  const auto& low = fb_.motor_low_speed[i];
  if (!low) return row;
  row += format("   %3.0f", low->value.driver_temperature) +
         format("/%-3.0f", low->value.motor_temperature);
  std::string status;
  for (int m : {i, i + kWheelCount}) {
    const auto& l = fb_.motor_low_speed[m];
    if (!l) continue;
    for (const auto& n : protocol::driver_status_names(l->value.driver_status)) {
      status += (status.empty() ? "" : ",") + n + "(m" + std::to_string(m + 1) + ")";
    }
  }
  return row + "      " + (status.empty() ? st.green("ok") : st.red(status));
}

std::string ChassisMonitor::text_batteries(bool color) const {
  const Style st{color};
  std::string out;
  for (int b = 0; b <= protocol::kBatteryCount; ++b) {
    if (!fb_.bms[b]) continue;
    const auto& d = fb_.bms[b]->value;
    std::string row = b == 0 ? "Battery   pack  " : "          bat " + std::to_string(b) + " ";
    std::string soc = format("SOC %5.1f%%", d.soc);
    if (d.soc < 10) {
      soc = st.red(soc);
    } else if (d.soc < 15) {
      soc = st.yellow(soc);
    }
    row += soc + format("  SOH %5.1f%%", d.soh) + format("  %6.2f V", d.voltage) +
           format("  %+6.1f A", d.current) + format("  %5.1f degC", d.temperature);
    if (fb_.bms_alarm[b]) {
      const auto& a = fb_.bms_alarm[b]->value;
      const std::string alarms = bms_names(a.alarm1, a.alarm2);
      const std::string warnings = bms_names(a.warning1, a.warning2);
      row += "  alarms " + (alarms == "none" ? alarms : st.red(alarms)) + "  warnings " +
             (warnings == "none" ? warnings : st.yellow(warnings));
    }
    out += row + "\n";
  }
  return out;
}

std::string ChassisMonitor::text_ultrasonic() const {
  std::string us = "Ultrasonic avoidance ";
  us += fb_.ultrasonic_setting ? (fb_.ultrasonic_setting->value.enabled ? "enabled" : "disabled")
                               : "? (no 0x45A yet)";
  for (int k = 0; k < 2; ++k) {
    if (!fb_.ultrasonic[k]) continue;
    for (int i = 0; i < 4; ++i) {
      us += "  " + std::to_string(fb_.ultrasonic[k]->value.first_sensor + i) + ":" +
            ultrasonic_text(fb_.ultrasonic[k]->value.raw[i]);
    }
  }
  return us + "\n";
}

// The vendor's additions (agx_v2): the remote control, the lights, the firmware version.
std::string ChassisMonitor::text_vendor() const {
  std::string out;
  if (fb_.remote_control_state) {
    const RemoteState r =
        remote_state_from(fb_.remote_control_state->value, fb_.remote_control_state->received);
    out += "Remote   SWA " + std::string(protocol::to_string(r.swa)) + "  SWB " +
           std::string(protocol::to_string(r.swb)) + "  SWC " +
           std::string(protocol::to_string(r.swc)) + "  SWD " +
           std::string(protocol::to_string(r.swd)) +
           format("   left stick (%+.2f fwd,", r.left_vertical) +
           format(" %+.2f right)", r.left_horizontal) +
           format("  right stick (%+.2f fwd,", r.right_vertical) +
           format(" %+.2f right)", r.right_horizontal) + format("  knob %+.2f", r.knob) + "\n";
  }
  if (fb_.light_state) {
    const LightState& l = fb_.light_state->value;
    out += "Lights   " + describe(l.front_mode, l.front_custom, l.rear_mode, l.rear_custom) +
           (l.enable ? "  (under CAN control)" : "  (the chassis's own)") + "\n";
  }
  if (!fb_.version.empty()) out += "Firmware " + fb_.version + "\n";
  return out;
}

// Frame rates: every ID seen, plus the periodic feedback IDs that are missing.
std::string ChassisMonitor::text_rates(Timestamp now, bool color) const {
  const Style st{color};
  std::string out = "Rates /s  (expected in brackets; " + st.red("red") + " = more than 20% off)\n";
  std::vector<std::uint32_t> ids;
  for (const FrameIdCounts& c : stats_.counts())
    ids.push_back(c.id);
  for (auto id : protocol::all_ids()) {
    const bool optional_battery = id >= protocol::kBmsBaseId + 2 && id < protocol::kBmsBaseId + 10;
    const bool seen = std::find(ids.begin(), ids.end(), id) != ids.end();
    if (nominal_rate(id) > 0 && !optional_battery && !seen) ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  std::string row;
  int in_row = 0;
  for (auto id : ids) {
    const double r = rate(id, now);
    const double nominal = nominal_rate(id);
    std::string cell = text::hex(id) + format(" %5.1f", r);
    cell += nominal > 0 ? format(" (%2.0f)", nominal) : "     ";
    if (nominal > 0 && std::abs(r - nominal) > 0.2 * nominal) cell = st.red(cell);
    row += "  " + cell;
    if (++in_row == 6) {
      out += row + "\n";
      row.clear();
      in_row = 0;
    }
  }
  if (!row.empty()) out += row + "\n";
  return out;
}

std::string ChassisMonitor::render_json(std::string_view iface, const BusStatus& bus,
                                        Timestamp now) const {
  std::string out;
  JsonWriter w(out);
  w.begin_object();
  w.key("iface").string(iface);
  w.key("bus").begin_object();
  w.key("state").string(to_string(bus.state));
  w.key("rx_dropped").unsigned_integer(bus.stats.rx_dropped);
  w.key("tx_dropped").unsigned_integer(bus.stats.tx_dropped);
  w.key("error_frames").unsigned_integer(bus.stats.error_frames + error_frames_);
  w.end_object();
  w.key("frames").unsigned_integer(stats_.total());
  w.key("undecodable").unsigned_integer(decode_errors_);
  if (fb_.system_status) {
    const auto& s = fb_.system_status->value;
    w.key("control_mode").string(protocol::to_string(s.control_mode));
    w.key("vehicle_status").string(protocol::to_string(s.vehicle_status));
    w.key("battery_voltage").number(s.battery_voltage);
    w.key("error_bits").unsigned_integer(s.error_bits);
    w.key("errors").begin_array();
    for (const auto& n : protocol::error_bit_names(s.error_bits, profile_.error_word))
      w.string(n);
    w.end_array();
    w.key("status_age")
        .number(std::chrono::duration<double>(now - fb_.system_status->received).count());
  }
  if (fb_.motion_mode) {
    w.key("motion_mode").string(protocol::to_string(fb_.motion_mode->value.mode));
    w.key("switching").boolean(fb_.motion_mode->value.switching);
  }
  if (fb_.motion) {
    w.key("speed").number(fb_.motion->value.speed);
    w.key("steering_angle").number(fb_.motion->value.steering_angle);
  }
  if (fb_.steering_angles && fb_.wheel_speeds) {
    w.key("wheels").begin_array();
    for (int i = 0; i < kWheelCount; ++i) {
      w.begin_object()
          .key("name")
          .string(kWheelNames[i])
          .key("angle")
          .number(fb_.steering_angles->value.angles[i])
          .key("speed")
          .number(fb_.wheel_speeds->value.speeds[i])
          .end_object();
    }
    w.end_array();
  }
  if (fb_.bms[0]) {
    const auto& b = fb_.bms[0]->value;
    w.key("battery").begin_object();
    w.key("soc").number(b.soc).key("soh").number(b.soh).key("voltage").number(b.voltage);
    w.key("current").number(b.current).key("temperature").number(b.temperature);
    w.end_object();
  }
  if (fb_.ultrasonic_setting)
    w.key("ultrasonic_enabled").boolean(fb_.ultrasonic_setting->value.enabled);
  if (fb_.remote_control_state) {
    const RemoteState r =
        remote_state_from(fb_.remote_control_state->value, fb_.remote_control_state->received);
    w.key("remote").begin_object();
    w.key("swa").string(protocol::to_string(r.swa)).key("swb").string(protocol::to_string(r.swb));
    w.key("swc").string(protocol::to_string(r.swc)).key("swd").string(protocol::to_string(r.swd));
    w.key("left_vertical").number(r.left_vertical).key("left_horizontal").number(r.left_horizontal);
    w.key("right_vertical").number(r.right_vertical);
    w.key("right_horizontal").number(r.right_horizontal).key("knob").number(r.knob);
    w.end_object();
  }
  if (fb_.light_state) {
    const LightState& l = fb_.light_state->value;
    w.key("lights").begin_object();
    w.key("can_control").boolean(l.enable);
    w.key("front").string(protocol::to_string(l.front_mode));
    w.key("front_brightness").unsigned_integer(l.front_custom);
    w.key("rear").string(protocol::to_string(l.rear_mode));
    w.key("rear_brightness").unsigned_integer(l.rear_custom);
    w.end_object();
  }
  if (!fb_.version.empty()) w.key("firmware_version").string(fb_.version);
  if (motion_command_) {
    w.key("host_motion_command").begin_object();
    w.key("linear_speed").number(motion_command_->value.linear_speed);
    w.key("spin_speed").number(motion_command_->value.spin_speed);
    w.key("steering_angle").number(motion_command_->value.steering_angle);
    w.key("age").number(std::chrono::duration<double>(now - motion_command_->received).count());
    w.end_object();
  }
  w.key("rates").begin_object();
  for (const FrameIdCounts& c : stats_.counts())
    w.key(text::hex(c.id)).number(rate(c.id, now));
  w.end_object();
  w.end_object();
  return out;
}

}  // namespace ranger::cli
