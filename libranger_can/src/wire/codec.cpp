// Byte-exact encoding and decoding of every RANGER frame (manual 3.2, PROTOCOL.md).
//
// Decoding is one switch on the ID; each case checks the DLC before touching a byte, so no path
// reads past `dlc`, and nothing on the success path allocates (Message is a variant of PODs).
// Encoding checks finiteness (naming the field), then saturates each value into the range the
// protocol allows for it: the stated valid range for commands, the wire type's range otherwise.
#include "ranger_can/wire/codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {

namespace wire {
namespace {

template <typename Int>
Int saturate(double scaled) {
  constexpr Int kMin = std::numeric_limits<Int>::min();
  constexpr Int kMax = std::numeric_limits<Int>::max();
  if (std::isnan(scaled)) return 0;  // callers refuse NaN earlier; never UB here
  if (scaled <= static_cast<double>(kMin)) return kMin;
  if (scaled >= static_cast<double>(kMax)) return kMax;
  return static_cast<Int>(std::lround(scaled));  // inside (kMin, kMax): cannot overflow
}

}  // namespace

std::int16_t saturate_i16(double scaled) {
  return saturate<std::int16_t>(scaled);
}
std::uint16_t saturate_u16(double scaled) {
  return saturate<std::uint16_t>(scaled);
}
std::int8_t saturate_i8(double scaled) {
  return saturate<std::int8_t>(scaled);
}
std::uint8_t saturate_u8(double scaled) {
  return saturate<std::uint8_t>(scaled);
}

}  // namespace wire

namespace {

using protocol::ControlMode;
using protocol::MotionMode;
using protocol::VehicleStatus;

// ---- Units --------------------------------------------------------------------------------------
// Decimal scales divide (raw / 1000.0) rather than multiply by 0.001, so a decoded value is the
// double nearest to the wire's decimal value and prints as such (150 -> 0.15, not
// 0.15000000000000002).
constexpr double kMillis = 1000.0;  // mm/s per m/s
constexpr double kDeci = 10.0;      // 0.1 V, 0.1 A, 0.1 degC
constexpr double kCenti = 100.0;    // 0.01 V, 0.01 deg
constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerCentideg = kPi / 18000.0;
constexpr double kCentidegPerRad = 18000.0 / kPi;

// Valid ranges of the 0x111 fields (manual 3.2; open point 1 for the linear speed).
constexpr double kMaxLinearSpeedMmps = interpretation::kMaxLinearSpeedMps * kMillis;
constexpr double kMaxSpinSpeedMmps = 1000.0;
constexpr double kMaxSteeringCentideg = 9000.0;  // oblique mode; Ackermann mode allows 4000

// ---- Big-endian ("MOTOROLA") field access ------------------------------------------------------
inline std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] << 8 | p[1]);
}
inline std::int16_t get_i16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(get_u16(p));
}
inline std::int32_t get_i32(const std::uint8_t* p) {
  return static_cast<std::int32_t>(std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 |
                                   std::uint32_t{p[2]} << 8 | std::uint32_t{p[3]});
}
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(get_i32(p));
}

inline void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
inline void put_i16(std::uint8_t* p, std::int16_t v) {
  put_u16(p, static_cast<std::uint16_t>(v));
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

inline double angle_from_wire(std::int16_t centideg) {
  return centideg * kRadPerCentideg;
}
inline std::int16_t angle_to_wire(double rad, double limit_centideg) {
  return wire::saturate_i16(std::clamp(rad * kCentidegPerRad, -limit_centideg, limit_centideg));
}
inline std::int16_t angle_to_wire(double rad) {
  return wire::saturate_i16(rad * kCentidegPerRad);
}

// ---- Wire value <-> enum --------------------------------------------------------------------
// Several wire values map to one VehicleStatus (every undefined non-zero value is "abnormal": the
// safe reading), so SystemStatus keeps the raw byte as well.
VehicleStatus vehicle_status_from_wire(std::uint8_t raw) {
  if (raw == 0x00) return VehicleStatus::kNormal;
  if (raw == 0x01 && interpretation::kVehicleStatus1IsEmergencyStop) {
    return VehicleStatus::kEmergencyStop;
  }
  return VehicleStatus::kAbnormal;
}

// ---- Error messages (only built on failure paths) ---------------------------------------------
std::string hex(std::uint32_t v, int width = 3) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", width, v);
  return buf;
}

Error bad_dlc(const CanFrame& f, int expected) {
  return Error{Errc::kBadDlc, hex(f.id) + " (" + std::string(protocol::frame_name(f.id)) +
                                  "): DLC " + std::to_string(f.dlc) + ", expected " +
                                  std::to_string(expected)};
}

// ---- Decoding ---------------------------------------------------------------------------------

constexpr std::uint32_t kHighSpeedFirst = protocol::kMotorHighSpeedBaseId + 1;
constexpr std::uint32_t kLowSpeedFirst = protocol::kMotorLowSpeedBaseId + 1;

Message decode_motion_command(const std::uint8_t* d) {
  MotionCommand m;
  m.linear_speed = get_i16(d) / kMillis;
  m.spin_speed = get_i16(d + 4) / kMillis;
  m.steering_angle = angle_from_wire(get_i16(d + 6));
  return m;
}

Message decode_system_status(const std::uint8_t* d) {
  SystemStatus s;
  s.vehicle_status_raw = d[0];
  s.vehicle_status = vehicle_status_from_wire(d[0]);
  s.control_mode_raw = d[1];
  s.control_mode = static_cast<ControlMode>(d[1]);
  s.battery_voltage = get_u16(d + 2) / kDeci;
  s.error_bits = get_u32(d + 4);
  return s;
}

Message decode_motion_feedback(const std::uint8_t* d) {
  MotionFeedback m;
  m.speed = get_i16(d) / kMillis;
  m.steering_angle = angle_from_wire(get_i16(d + 6));
  return m;
}

Message decode_high_speed(int motor, const std::uint8_t* d) {
  MotorHighSpeedFeedback m;
  m.motor = motor;
  m.rpm = get_i16(d);
  m.current = get_i16(d + 2) / kDeci;
  m.position = get_i32(d + 4);
  return m;
}

Message decode_low_speed(int motor, const std::uint8_t* d) {
  MotorLowSpeedFeedback m;
  m.motor = motor;
  m.driver_voltage = get_u16(d) / kDeci;
  m.driver_temperature = get_i16(d + 2);
  m.motor_temperature = static_cast<std::int8_t>(d[4]);
  m.driver_status = d[5];
  return m;
}

Message decode_steering_angles(const std::uint8_t* d) {
  SteeringAnglesFeedback m;
  for (int i = 0; i < 4; ++i)
    m.angles[i] = angle_from_wire(get_i16(d + 2 * i));
  return m;
}

Message decode_wheel_speeds(const std::uint8_t* d) {
  WheelSpeedsFeedback m;
  for (int i = 0; i < 4; ++i)
    m.speeds[i] = get_i16(d + 2 * i) / kMillis;
  return m;
}

Message decode_ultrasonic(int first_sensor, const std::uint8_t* d) {
  UltrasonicFeedback m;
  m.first_sensor = first_sensor;
  for (int i = 0; i < 4; ++i)
    m.raw[i] = get_i16(d + 2 * i);
  return m;
}

Message decode_bms(std::uint32_t id, const std::uint8_t* d) {
  const int offset = static_cast<int>(id - protocol::kBmsBaseId);
  if (offset % 2 == 0) {
    BmsData b;
    b.battery = offset / 2;
    b.soc = d[0];
    b.soh = d[1];
    b.voltage = get_u16(d + 2) / kCenti;
    b.current = get_i16(d + 4) / kDeci;
    b.temperature = get_i16(d + 6) / kDeci;
    return b;
  }
  BmsAlarm a;
  a.battery = offset / 2;
  a.alarm1 = d[0];
  a.alarm2 = d[1];
  a.warning1 = d[2];
  a.warning2 = d[3];
  return a;
}

}  // namespace

Result<Message> decode(const CanFrame& f) {
  if (f.is_error) {
    return Error{Errc::kInvalidArgument,
                 "error frame (class " + hex(f.id, 8) + ") carries no RANGER message"};
  }
  const std::uint8_t* d = f.data.data();
  // Each case: the DLC the protocol defines, then the decoder for that layout.
#define RANGER_EXPECT_DLC(n) \
  if (f.dlc != (n)) return bad_dlc(f, (n))
  switch (f.id) {
    case protocol::kMotionCommandId:
      RANGER_EXPECT_DLC(8);
      return decode_motion_command(d);
    case protocol::kMotionModeCommandId:
      RANGER_EXPECT_DLC(1);
      return Message{MotionModeCommand{static_cast<MotionMode>(d[0])}};
    case protocol::kControlModeCommandId:
      RANGER_EXPECT_DLC(1);
      return Message{ControlModeCommand{static_cast<ControlMode>(d[0])}};
    case protocol::kErrorClearCommandId:
      RANGER_EXPECT_DLC(1);
      return Message{ErrorClearCommand{d[0]}};
    case protocol::kUltrasonicSettingId:
      RANGER_EXPECT_DLC(1);
      return Message{UltrasonicSettingCommand{d[0] != 0}};
    case protocol::kSystemStatusId:
      RANGER_EXPECT_DLC(8);
      return decode_system_status(d);
    case protocol::kMotionFeedbackId:
      RANGER_EXPECT_DLC(8);
      return decode_motion_feedback(d);
    case kHighSpeedFirst + 0:
    case kHighSpeedFirst + 1:
    case kHighSpeedFirst + 2:
    case kHighSpeedFirst + 3:
    case kHighSpeedFirst + 4:
    case kHighSpeedFirst + 5:
    case kHighSpeedFirst + 6:
    case kHighSpeedFirst + 7:
      RANGER_EXPECT_DLC(8);
      return decode_high_speed(static_cast<int>(f.id - protocol::kMotorHighSpeedBaseId), d);
    case kLowSpeedFirst + 0:
    case kLowSpeedFirst + 1:
    case kLowSpeedFirst + 2:
    case kLowSpeedFirst + 3:
    case kLowSpeedFirst + 4:
    case kLowSpeedFirst + 5:
    case kLowSpeedFirst + 6:
    case kLowSpeedFirst + 7:
      RANGER_EXPECT_DLC(8);
      return decode_low_speed(static_cast<int>(f.id - protocol::kMotorLowSpeedBaseId), d);
    case protocol::kSteeringAnglesId:
      RANGER_EXPECT_DLC(8);
      return decode_steering_angles(d);
    case protocol::kWheelSpeedsId:
      RANGER_EXPECT_DLC(8);
      return decode_wheel_speeds(d);
    case protocol::kMotionModeFeedbackId: {
      RANGER_EXPECT_DLC(2);
      MotionModeFeedback m;
      m.mode_raw = d[0];
      m.mode = static_cast<MotionMode>(d[0]);
      m.switching = d[1] != 0;  // anything but "switch complete" is treated as still switching
      return Message{m};
    }
    case protocol::kUltrasonic1to4Id:
      RANGER_EXPECT_DLC(8);
      return decode_ultrasonic(1, d);
    case protocol::kUltrasonic5to8Id:
      RANGER_EXPECT_DLC(8);
      return decode_ultrasonic(5, d);
    case protocol::kUltrasonicSettingFeedbackId:
      RANGER_EXPECT_DLC(1);
      return Message{UltrasonicSettingFeedback{d[0] != 0}};
    case protocol::kBmsBaseId + 0:
    case protocol::kBmsBaseId + 2:
    case protocol::kBmsBaseId + 4:
    case protocol::kBmsBaseId + 6:
    case protocol::kBmsBaseId + 8:
      RANGER_EXPECT_DLC(8);
      return decode_bms(f.id, d);
    case protocol::kBmsBaseId + 1:
    case protocol::kBmsBaseId + 3:
    case protocol::kBmsBaseId + 5:
    case protocol::kBmsBaseId + 7:
    case protocol::kBmsBaseId + 9:
      RANGER_EXPECT_DLC(4);
      return decode_bms(f.id, d);
    default:
      break;
  }
#undef RANGER_EXPECT_DLC
  return Error{Errc::kUnknownId, "ID " + hex(f.id) + " is not part of the RANGER protocol (DLC " +
                                     std::to_string(f.dlc) + ")"};
}

// ---- Encoding ---------------------------------------------------------------------------------

namespace {

// The error for a NaN or infinite `message.field` (built only on that path).
Error not_finite(const char* message, const char* field, double value) {
  return Error{Errc::kNotFinite, std::string(message) + "." + field + " is " +
                                     (std::isnan(value) ? "NaN" : "infinite") +
                                     ": refusing to encode it"};
}

Error invalid(const char* message, const char* field, long value, const char* valid) {
  return Error{Errc::kInvalidArgument, std::string(message) + "." + field + " = " +
                                           std::to_string(value) + " is invalid (valid: " + valid +
                                           ")"};
}

CanFrame frame_for(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(protocol::expected_dlc(id));
  return f;
}

#define RANGER_REQUIRE_FINITE(msg, obj, field)                                    \
  do {                                                                            \
    if (!std::isfinite((obj).field)) return not_finite(msg, #field, (obj).field); \
  } while (0)

Result<CanFrame> encode_one(const MotionCommand& m) {
  RANGER_REQUIRE_FINITE("motion_command", m, linear_speed);
  RANGER_REQUIRE_FINITE("motion_command", m, spin_speed);
  RANGER_REQUIRE_FINITE("motion_command", m, steering_angle);
  CanFrame f = frame_for(protocol::kMotionCommandId);
  put_i16(&f.data[0], wire::saturate_i16(std::clamp(m.linear_speed * kMillis, -kMaxLinearSpeedMmps,
                                                    kMaxLinearSpeedMmps)));
  put_i16(&f.data[4], wire::saturate_i16(std::clamp(m.spin_speed * kMillis, -kMaxSpinSpeedMmps,
                                                    kMaxSpinSpeedMmps)));
  put_i16(&f.data[6], angle_to_wire(m.steering_angle, kMaxSteeringCentideg));
  return f;
}

Result<CanFrame> encode_one(const MotionModeCommand& m) {
  const auto v = static_cast<std::uint8_t>(m.mode);
  if (v > static_cast<std::uint8_t>(MotionMode::kSpin)) {
    return invalid("motion_mode_command", "mode", v, "0 ackermann, 1 oblique, 2 spin");
  }
  CanFrame f = frame_for(protocol::kMotionModeCommandId);
  f.data[0] = v;
  return f;
}

Result<CanFrame> encode_one(const ControlModeCommand& m) {
  if (m.mode != ControlMode::kStandby && m.mode != ControlMode::kCan) {
    return invalid("control_mode_command", "mode", static_cast<long>(m.mode),
                   "0 standby, 1 CAN; the host cannot select remote mode");
  }
  CanFrame f = frame_for(protocol::kControlModeCommandId);
  f.data[0] = static_cast<std::uint8_t>(m.mode);
  return f;
}

Result<CanFrame> encode_one(const ErrorClearCommand& m) {
  if (m.code > protocol::kMaxErrorClearCode) {
    return invalid("error_clear_command", "code", m.code, "0x00..0x10");
  }
  CanFrame f = frame_for(protocol::kErrorClearCommandId);
  f.data[0] = m.code;
  return f;
}

Result<CanFrame> encode_one(const UltrasonicSettingCommand& m) {
  CanFrame f = frame_for(protocol::kUltrasonicSettingId);
  f.data[0] = m.enable ? 0x01 : 0x00;
  return f;
}

Result<CanFrame> encode_one(const SystemStatus& s) {
  RANGER_REQUIRE_FINITE("system_status", s, battery_voltage);
  const auto status = static_cast<std::uint8_t>(s.vehicle_status);
  if (status > static_cast<std::uint8_t>(VehicleStatus::kAbnormal)) {
    return invalid("system_status", "vehicle_status", status, "0 normal, 1 e-stop, 2 abnormal");
  }
  CanFrame f = frame_for(protocol::kSystemStatusId);
  // The raw byte wins when it is one of the wire values that decode to `vehicle_status`, so a
  // decoded frame re-encodes byte-exact; otherwise the enum's own value is sent.
  f.data[0] = vehicle_status_from_wire(s.vehicle_status_raw) == s.vehicle_status
                  ? s.vehicle_status_raw
                  : status;
  f.data[1] = static_cast<std::uint8_t>(s.control_mode);
  put_u16(&f.data[2], wire::saturate_u16(s.battery_voltage * kDeci));
  put_u32(&f.data[4], s.error_bits);
  return f;
}

Result<CanFrame> encode_one(const MotionFeedback& m) {
  RANGER_REQUIRE_FINITE("motion_feedback", m, speed);
  RANGER_REQUIRE_FINITE("motion_feedback", m, steering_angle);
  CanFrame f = frame_for(protocol::kMotionFeedbackId);
  put_i16(&f.data[0], wire::saturate_i16(m.speed * kMillis));
  put_i16(&f.data[6], angle_to_wire(m.steering_angle));
  return f;
}

Result<CanFrame> encode_one(const MotorHighSpeedFeedback& m) {
  if (m.motor < 1 || m.motor > protocol::kMotorCount) {
    return invalid("motor_high_speed", "motor", m.motor, "1..8");
  }
  RANGER_REQUIRE_FINITE("motor_high_speed", m, rpm);
  RANGER_REQUIRE_FINITE("motor_high_speed", m, current);
  CanFrame f = frame_for(protocol::kMotorHighSpeedBaseId + static_cast<std::uint32_t>(m.motor));
  put_i16(&f.data[0], wire::saturate_i16(m.rpm));
  put_i16(&f.data[2], wire::saturate_i16(m.current * kDeci));
  put_u32(&f.data[4], static_cast<std::uint32_t>(m.position));
  return f;
}

Result<CanFrame> encode_one(const MotorLowSpeedFeedback& m) {
  if (m.motor < 1 || m.motor > protocol::kMotorCount) {
    return invalid("motor_low_speed", "motor", m.motor, "1..8");
  }
  RANGER_REQUIRE_FINITE("motor_low_speed", m, driver_voltage);
  RANGER_REQUIRE_FINITE("motor_low_speed", m, driver_temperature);
  RANGER_REQUIRE_FINITE("motor_low_speed", m, motor_temperature);
  CanFrame f = frame_for(protocol::kMotorLowSpeedBaseId + static_cast<std::uint32_t>(m.motor));
  put_u16(&f.data[0], wire::saturate_u16(m.driver_voltage * kDeci));
  put_i16(&f.data[2], wire::saturate_i16(m.driver_temperature));
  f.data[4] = static_cast<std::uint8_t>(wire::saturate_i8(m.motor_temperature));
  f.data[5] = m.driver_status;
  return f;
}

Result<CanFrame> encode_one(const SteeringAnglesFeedback& m) {
  static constexpr const char* kNames[4] = {"angles[0]", "angles[1]", "angles[2]", "angles[3]"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(m.angles[i])) return not_finite("steering_angles", kNames[i], m.angles[i]);
  }
  CanFrame f = frame_for(protocol::kSteeringAnglesId);
  for (int i = 0; i < 4; ++i)
    put_i16(&f.data[2 * i], angle_to_wire(m.angles[i]));
  return f;
}

Result<CanFrame> encode_one(const WheelSpeedsFeedback& m) {
  static constexpr const char* kNames[4] = {"speeds[0]", "speeds[1]", "speeds[2]", "speeds[3]"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(m.speeds[i])) return not_finite("wheel_speeds", kNames[i], m.speeds[i]);
  }
  CanFrame f = frame_for(protocol::kWheelSpeedsId);
  for (int i = 0; i < 4; ++i)
    put_i16(&f.data[2 * i], wire::saturate_i16(m.speeds[i] * kMillis));
  return f;
}

Result<CanFrame> encode_one(const MotionModeFeedback& m) {
  // Feedback may carry any mode byte (the simulator injects faults with it); commands may not.
  CanFrame f = frame_for(protocol::kMotionModeFeedbackId);
  f.data[0] = static_cast<std::uint8_t>(m.mode);
  f.data[1] = m.switching ? 0x01 : 0x00;
  return f;
}

Result<CanFrame> encode_one(const UltrasonicFeedback& m) {
  if (m.first_sensor != 1 && m.first_sensor != 5) {
    return invalid("ultrasonic", "first_sensor", m.first_sensor, "1 (0x342) or 5 (0x343)");
  }
  CanFrame f =
      frame_for(m.first_sensor == 1 ? protocol::kUltrasonic1to4Id : protocol::kUltrasonic5to8Id);
  for (int i = 0; i < 4; ++i)
    put_i16(&f.data[2 * i], m.raw[i]);
  return f;
}

Result<CanFrame> encode_one(const UltrasonicSettingFeedback& m) {
  CanFrame f = frame_for(protocol::kUltrasonicSettingFeedbackId);
  f.data[0] = m.enabled ? 0x01 : 0x00;
  return f;
}

Result<CanFrame> encode_one(const BmsData& b) {
  if (b.battery < 0 || b.battery > protocol::kBatteryCount) {
    return invalid("bms", "battery", b.battery, "0 pack, 1..4");
  }
  RANGER_REQUIRE_FINITE("bms", b, soc);
  RANGER_REQUIRE_FINITE("bms", b, soh);
  RANGER_REQUIRE_FINITE("bms", b, voltage);
  RANGER_REQUIRE_FINITE("bms", b, current);
  RANGER_REQUIRE_FINITE("bms", b, temperature);
  CanFrame f = frame_for(protocol::kBmsBaseId + 2 * static_cast<std::uint32_t>(b.battery));
  f.data[0] = wire::saturate_u8(std::clamp(b.soc, 0.0, 100.0));
  f.data[1] = wire::saturate_u8(std::clamp(b.soh, 0.0, 100.0));
  put_u16(&f.data[2], wire::saturate_u16(b.voltage * kCenti));
  put_i16(&f.data[4], wire::saturate_i16(b.current * kDeci));
  put_i16(&f.data[6], wire::saturate_i16(b.temperature * kDeci));
  return f;
}

Result<CanFrame> encode_one(const BmsAlarm& a) {
  if (a.battery < 0 || a.battery > protocol::kBatteryCount) {
    return invalid("bms_alarm", "battery", a.battery, "0 pack, 1..4");
  }
  CanFrame f = frame_for(protocol::kBmsBaseId + 2 * static_cast<std::uint32_t>(a.battery) + 1);
  f.data[0] = a.alarm1;
  f.data[1] = a.alarm2;
  f.data[2] = a.warning1;
  f.data[3] = a.warning2;
  return f;
}

#undef RANGER_REQUIRE_FINITE

struct IdOf {
  std::uint32_t operator()(const MotionCommand&) const { return protocol::kMotionCommandId; }
  std::uint32_t operator()(const MotionModeCommand&) const {
    return protocol::kMotionModeCommandId;
  }
  std::uint32_t operator()(const ControlModeCommand&) const {
    return protocol::kControlModeCommandId;
  }
  std::uint32_t operator()(const ErrorClearCommand&) const {
    return protocol::kErrorClearCommandId;
  }
  std::uint32_t operator()(const UltrasonicSettingCommand&) const {
    return protocol::kUltrasonicSettingId;
  }
  std::uint32_t operator()(const SystemStatus&) const { return protocol::kSystemStatusId; }
  std::uint32_t operator()(const MotionFeedback&) const { return protocol::kMotionFeedbackId; }
  std::uint32_t operator()(const MotorHighSpeedFeedback& m) const {
    return protocol::kMotorHighSpeedBaseId + static_cast<std::uint32_t>(m.motor);
  }
  std::uint32_t operator()(const MotorLowSpeedFeedback& m) const {
    return protocol::kMotorLowSpeedBaseId + static_cast<std::uint32_t>(m.motor);
  }
  std::uint32_t operator()(const SteeringAnglesFeedback&) const {
    return protocol::kSteeringAnglesId;
  }
  std::uint32_t operator()(const WheelSpeedsFeedback&) const { return protocol::kWheelSpeedsId; }
  std::uint32_t operator()(const MotionModeFeedback&) const {
    return protocol::kMotionModeFeedbackId;
  }
  std::uint32_t operator()(const UltrasonicFeedback& m) const {
    return m.first_sensor == 5 ? protocol::kUltrasonic5to8Id : protocol::kUltrasonic1to4Id;
  }
  std::uint32_t operator()(const UltrasonicSettingFeedback&) const {
    return protocol::kUltrasonicSettingFeedbackId;
  }
  std::uint32_t operator()(const BmsData& b) const {
    return protocol::kBmsBaseId + 2 * static_cast<std::uint32_t>(b.battery);
  }
  std::uint32_t operator()(const BmsAlarm& a) const {
    return protocol::kBmsBaseId + 2 * static_cast<std::uint32_t>(a.battery) + 1;
  }
};

}  // namespace

Result<CanFrame> encode(const Message& message) {
  return std::visit([](const auto& m) { return encode_one(m); }, message);
}

std::uint32_t id_of(const Message& message) {
  return std::visit(IdOf{}, message);
}

}  // namespace ranger
