#include "cli_frame_format.hpp"

#include <initializer_list>
#include <utility>
#include <vector>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::cli {

namespace {

namespace proto = ranger::protocol;

constexpr const char* kWheelTags[4] = {"rf", "rr", "lr", "lf"};  // manual order RF, RR, LR, LF

using text::format;

void append_hex_data(std::string& out, const CanFrame& f, char separator) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::size_t n = f.dlc < CanFrame::kMaxDlc ? f.dlc : CanFrame::kMaxDlc;
  for (std::size_t i = 0; i < n; ++i) {
    if (separator != '\0' && i > 0) out += separator;
    out += kHex[f.data[i] >> 4];
    out += kHex[f.data[i] & 0x0F];
  }
}

void write_names(JsonWriter& w, std::string_view key, const std::vector<std::string>& names) {
  w.key(key).strings(names);
}

void append_names(std::string& out, const std::vector<std::string>& names) {
  if (names.empty()) {
    out += "none";
    return;
  }
  out += "[" + text::join(names, ",") + "]";
}

std::string bms_slot(int battery) {
  return battery == 0 ? "pack" : std::to_string(battery);
}

// ---- JSON -------------------------------------------------------------------------------------

// The wire value of a 0x141 mode (the raw byte when decoding found no mode) and its name.
int mode_wire_value(const MotionModeCommand& m, const ProtocolProfile& p) {
  if (!m.mode_known) return m.mode_raw;
  const auto v = proto::motion_mode_to_wire(m.mode, p.mode_numbering);
  return v ? *v : static_cast<int>(m.mode);
}
std::string_view mode_name(proto::MotionMode mode, bool known) {
  return known ? proto::to_string(mode) : std::string_view("unknown");
}

// Whether the agx_v2 fields of 0x111/0x221 (bytes 2-5) are worth a place on a text line.
bool show_v2_fields(const ProtocolProfile& p, std::initializer_list<double> values) {
  if (p.spin_field == SpinField::kYawRate) return true;
  for (double v : values) {
    if (v != 0.0) return true;
  }
  return false;
}

struct JsonFields {
  JsonWriter& w;
  const ProtocolProfile& p;

  void operator()(const MotionCommand& m) const {
    w.key("linear_speed").number(m.linear_speed);
    w.key("yaw_rate").number(m.yaw_rate);
    w.key("spin_speed").number(m.spin_speed);
    w.key("steering_angle").number(m.steering_angle);
  }
  void operator()(const MotionModeCommand& m) const {
    w.key("mode").integer(mode_wire_value(m, p));
    w.key("mode_name").string(mode_name(m.mode, m.mode_known));
  }
  void operator()(const ControlModeCommand& m) const {
    w.key("mode").integer(static_cast<int>(m.mode));
    w.key("mode_name").string(proto::to_string(m.mode));
  }
  void operator()(const ErrorClearCommand& m) const {
    w.key("code").integer(m.code);
    w.key("description").string(proto::error_clear_description(m.code));
  }
  void operator()(const UltrasonicSettingCommand& m) const { w.key("enable").boolean(m.enable); }
  void operator()(const SystemStatus& s) const {
    w.key("vehicle_status").integer(s.vehicle_status_raw);
    w.key("vehicle_status_name").string(proto::to_string(s.vehicle_status));
    w.key("control_mode").integer(s.control_mode_raw);
    w.key("control_mode_name").string(proto::to_string(s.control_mode));
    w.key("battery_voltage").number(s.battery_voltage);
    w.key("error_bits").unsigned_integer(s.error_bits);
    write_names(w, "errors", proto::error_bit_names(s.error_bits, p.error_word));
    w.key("critical").boolean(proto::is_critical_error(s.error_bits, p.error_word));
    if (s.counter) w.key("counter").integer(*s.counter);
  }
  void operator()(const MotionFeedback& m) const {
    w.key("speed").number(m.speed);
    w.key("yaw_rate").number(m.yaw_rate);
    w.key("lateral_speed").number(m.lateral_speed);
    w.key("steering_angle").number(m.steering_angle);
  }
  void operator()(const MotorHighSpeedFeedback& m) const {
    w.key("motor").integer(m.motor);
    w.key("rpm").number(m.rpm);
    w.key("current").number(m.current);
    w.key("position").integer(m.position);
  }
  void operator()(const MotorLowSpeedFeedback& m) const {
    w.key("motor").integer(m.motor);
    w.key("driver_voltage").number(m.driver_voltage);
    w.key("driver_temperature").number(m.driver_temperature);
    w.key("motor_temperature").number(m.motor_temperature);
    w.key("driver_status").integer(m.driver_status);
    write_names(w, "driver_status_names", proto::driver_status_names(m.driver_status));
  }
  void operator()(const SteeringAnglesFeedback& m) const {
    w.key("angles").begin_array();
    for (double a : m.angles)
      w.number(a);
    w.end_array();
  }
  void operator()(const WheelSpeedsFeedback& m) const {
    w.key("speeds").begin_array();
    for (double s : m.speeds)
      w.number(s);
    w.end_array();
  }
  void operator()(const MotionModeFeedback& m) const {
    w.key("mode").integer(m.mode_raw);
    w.key("mode_name").string(mode_name(m.mode, m.mode_known));
    w.key("switching").boolean(m.switching);
  }
  void operator()(const UltrasonicFeedback& m) const {
    w.key("first_sensor").integer(m.first_sensor);
    w.key("raw").begin_array();
    for (auto r : m.raw)
      w.integer(r);
    w.end_array();
    w.key("status").begin_array();
    for (auto r : m.raw)
      w.string(proto::ultrasonic_status_name(r));
    w.end_array();
  }
  void operator()(const UltrasonicSettingFeedback& m) const { w.key("enabled").boolean(m.enabled); }
  void operator()(const BmsData& b) const {
    w.key("battery").integer(b.battery);
    w.key("soc").number(b.soc);
    w.key("soh").number(b.soh);
    w.key("voltage").number(b.voltage);
    w.key("current").number(b.current);
    w.key("temperature").number(b.temperature);
  }
  void operator()(const BmsAlarm& a) const {
    w.key("battery").integer(a.battery);
    w.key("alarm1").integer(a.alarm1);
    w.key("alarm2").integer(a.alarm2);
    w.key("warning1").integer(a.warning1);
    w.key("warning2").integer(a.warning2);
    write_names(w, "alarms", proto::bms_status_names(a.alarm1, a.alarm2));
    write_names(w, "warnings", proto::bms_status_names(a.warning1, a.warning2));
  }
  template <typename Light>
  void light(const Light& l) const {
    w.key("enable").boolean(l.enable);
    w.key("front_mode").integer(static_cast<int>(l.front_mode));
    w.key("front_mode_name").string(proto::to_string(l.front_mode));
    w.key("front_custom").integer(l.front_custom);
    w.key("rear_mode").integer(static_cast<int>(l.rear_mode));
    w.key("rear_mode_name").string(proto::to_string(l.rear_mode));
    w.key("rear_custom").integer(l.rear_custom);
    w.key("counter").integer(l.counter);
  }
  void operator()(const LightCommand& l) const { light(l); }
  void operator()(const LightState& l) const { light(l); }
  void operator()(const RemoteControlState& r) const {
    const std::pair<const char*, proto::RemoteSwitch> switches[] = {
        {"swa", r.swa}, {"swb", r.swb}, {"swc", r.swc}, {"swd", r.swd}};
    for (const auto& [key, position] : switches) {
      w.key(key).integer(static_cast<int>(position));
      w.key(std::string(key) + "_name").string(proto::to_string(position));
    }
    w.key("stick_right_h").integer(r.stick_right_h);
    w.key("stick_right_v").integer(r.stick_right_v);
    w.key("stick_left_v").integer(r.stick_left_v);
    w.key("stick_left_h").integer(r.stick_left_h);
    w.key("var_a").integer(r.var_a);
    w.key("counter").integer(r.counter);
  }
  void operator()(const OdometerFeedback& o) const {
    w.key("left_wheel").integer(o.left_wheel);
    w.key("right_wheel").integer(o.right_wheel);
  }
  void operator()(const VersionRequest&) const { w.key("request").boolean(true); }
  void operator()(const VersionResponse& v) const { w.key("text").string(v.view()); }
};

// ---- Text -------------------------------------------------------------------------------------

struct TextFields {
  std::string& out;
  const ProtocolProfile& p;

  void operator()(const MotionCommand& m) const {
    out += format("linear=%.3f m/s ", m.linear_speed);
    if (show_v2_fields(p, {m.yaw_rate})) out += format("yaw_rate=%.3f rad/s ", m.yaw_rate);
    out += format("spin=%.3f m/s steering=%.2f deg", m.spin_speed, rad_to_deg(m.steering_angle));
  }
  void operator()(const MotionModeCommand& m) const {
    out += format("mode=%d (%s)", mode_wire_value(m, p),
                  std::string(mode_name(m.mode, m.mode_known)).c_str());
  }
  void operator()(const ControlModeCommand& m) const {
    out += format("mode=%d (%s)", static_cast<int>(m.mode), proto::to_string(m.mode).data());
  }
  void operator()(const ErrorClearCommand& m) const {
    out += format("code=0x%02X (%s)", m.code, proto::error_clear_description(m.code).c_str());
  }
  void operator()(const UltrasonicSettingCommand& m) const {
    out += m.enable ? "enable=yes" : "enable=no";
  }
  void operator()(const SystemStatus& s) const {
    out +=
        format("vehicle=%s control=%s battery=%.1f V errors=0x%0*X ",
               proto::to_string(s.vehicle_status).data(), proto::to_string(s.control_mode).data(),
               s.battery_voltage, proto::error_word_bits(p.error_word) / 4, s.error_bits);
    append_names(out, proto::error_bit_names(s.error_bits, p.error_word));
    if (proto::is_critical_error(s.error_bits, p.error_word)) out += " CRITICAL";
    if (s.counter) out += format(" counter=%d", *s.counter);
  }
  void operator()(const MotionFeedback& m) const {
    out += format("speed=%.3f m/s ", m.speed);
    if (show_v2_fields(p, {m.yaw_rate, m.lateral_speed})) {
      out += format("yaw_rate=%.3f rad/s lateral=%.3f m/s ", m.yaw_rate, m.lateral_speed);
    }
    out += format("steering=%.2f deg", rad_to_deg(m.steering_angle));
  }
  void operator()(const MotorHighSpeedFeedback& m) const {
    out += format("motor=%d rpm=%.0f current=%.1f A position=%d", m.motor, m.rpm, m.current,
                  static_cast<int>(m.position));
  }
  void operator()(const MotorLowSpeedFeedback& m) const {
    out += format("motor=%d voltage=%.1f V driver=%.0f degC motor=%.0f degC status=", m.motor,
                  m.driver_voltage, m.driver_temperature, m.motor_temperature);
    append_names(out, proto::driver_status_names(m.driver_status));
  }
  void operator()(const SteeringAnglesFeedback& m) const {
    for (int i = 0; i < 4; ++i)
      out += format("%s=%.2f ", kWheelTags[i], rad_to_deg(m.angles[i]));
    out += "deg";
  }
  void operator()(const WheelSpeedsFeedback& m) const {
    for (int i = 0; i < 4; ++i)
      out += format("%s=%.3f ", kWheelTags[i], m.speeds[i]);
    out += "m/s";
  }
  void operator()(const MotionModeFeedback& m) const {
    out += format("mode=%d (%s) switching=%s", m.mode_raw,
                  std::string(mode_name(m.mode, m.mode_known)).c_str(), m.switching ? "yes" : "no");
  }
  void operator()(const UltrasonicFeedback& m) const {
    for (int i = 0; i < 4; ++i) {
      if (i > 0) out += ' ';
      if (interpretation::ultrasonic_distance_m(m.raw[i])) {  // 0 is no reading, not 0 mm
        out += format("s%d=%d mm", m.first_sensor + i, m.raw[i]);
      } else {
        out += format("s%d=%s", m.first_sensor + i, proto::ultrasonic_status_name(m.raw[i]).data());
      }
    }
  }
  void operator()(const UltrasonicSettingFeedback& m) const {
    out += m.enabled ? "enabled=yes" : "enabled=no";
  }
  void operator()(const BmsData& b) const {
    out += format(
        "battery=%s soc=%.0f%% soh=%.0f%% voltage=%.2f V current=%.1f A temperature=%.1f degC",
        bms_slot(b.battery).c_str(), b.soc, b.soh, b.voltage, b.current, b.temperature);
  }
  void operator()(const BmsAlarm& a) const {
    out += format("battery=%s alarms=", bms_slot(a.battery).c_str());
    append_names(out, proto::bms_status_names(a.alarm1, a.alarm2));
    out += " warnings=";
    append_names(out, proto::bms_status_names(a.warning1, a.warning2));
  }
  template <typename Light>
  void light(const Light& l) const {
    out += format("enable=%s front=%s/%d rear=%s/%d counter=%d", l.enable ? "yes" : "no",
                  proto::to_string(l.front_mode).data(), l.front_custom,
                  proto::to_string(l.rear_mode).data(), l.rear_custom, l.counter);
  }
  void operator()(const LightCommand& l) const { light(l); }
  void operator()(const LightState& l) const { light(l); }
  void operator()(const RemoteControlState& r) const {
    out += format(
        "swa=%s swb=%s swc=%s swd=%s right_h=%d right_v=%d left_v=%d left_h=%d var_a=%d "
        "counter=%d",
        proto::to_string(r.swa).data(), proto::to_string(r.swb).data(),
        proto::to_string(r.swc).data(), proto::to_string(r.swd).data(), r.stick_right_h,
        r.stick_right_v, r.stick_left_v, r.stick_left_h, r.var_a, r.counter);
  }
  void operator()(const OdometerFeedback& o) const {
    out += format("left=%d right=%d (raw)", static_cast<int>(o.left_wheel),
                  static_cast<int>(o.right_wheel));
  }
  void operator()(const VersionRequest&) const { out += "request"; }
  void operator()(const VersionResponse& v) const {
    out += "text=\"";
    for (const char c : v.view()) {
      const auto u = static_cast<unsigned char>(c);
      if (u >= 0x20 && u < 0x7F && c != '"' && c != '\\') {
        out += c;
      } else {
        out += format("\\x%02X", u);
      }
    }
    out += '"';
  }
};

std::string_view name_of(const CanFrame& f) {
  return f.is_error ? std::string_view("error_frame") : proto::frame_name(f.id);
}

}  // namespace

void write_message_json(JsonWriter& w, const Message& message, const ProtocolProfile& profile) {
  std::visit(JsonFields{w, profile}, message);
}

void append_message_text(std::string& out, const Message& message, const ProtocolProfile& profile) {
  std::visit(TextFields{out, profile}, message);
}

void append_frame_json(std::string& out, const CanFrame& frame, std::string_view iface,
                       const ProtocolProfile& profile) {
  JsonWriter w(out);
  w.begin_object();
  w.key("t").seconds(frame.stamp);
  w.key("iface").string(iface);
  w.key("id").unsigned_integer(frame.id);
  w.key("name").string(name_of(frame));
  w.key("dlc").integer(frame.dlc);
  w.key("data");
  std::string hex;
  append_hex_data(hex, frame, '\0');
  w.string(hex);
  if (const int extra = proto::extra_bytes(frame); extra > 0) w.key("extra_bytes").integer(extra);
  const Result<Message> decoded = decode(frame, profile);
  if (decoded) {
    write_message_json(w, *decoded, profile);
  } else {
    w.key("error").string(decoded.error().message);
  }
  w.end_object();
}

void append_frame_text(std::string& out, const CanFrame& frame, std::string_view iface,
                       const ProtocolProfile& profile) {
  append_seconds(out, frame.stamp);
  out += ' ';
  out.append(iface.data(), iface.size());
  if (frame.is_error) {
    out += format(" %08X", frame.id);
  } else {
    out += format(" %03X", frame.id);
  }
  out += format(" %-28s ", std::string(name_of(frame)).c_str());
  const Result<Message> decoded = decode(frame, profile);
  if (decoded) {
    append_message_text(out, *decoded, profile);
    if (const int extra = proto::extra_bytes(frame); extra > 0) {
      out += format("  [+%d byte%s ignored]", extra, extra == 1 ? "" : "s");
    }
  } else {
    out += "error: " + decoded.error().message + "  [";
    out += std::to_string(frame.dlc);
    out += "] ";
    append_hex_data(out, frame, ' ');
  }
}

}  // namespace ranger::cli
