// Byte-exact encoding and decoding of every RANGER frame of either revision (manual 3.2,
// PROTOCOL.md; the vendor's agx_v2, PROTOCOL_AGX_V2.md), driven by a protocol profile.
//
// Decoding is one switch on the ID after one length check: a frame shorter than its layout is
// refused, a longer one is read from its leading bytes, so no path reads past `dlc`; nothing on
// the success path allocates (Message is a variant of PODs). Encoding checks finiteness (naming
// the field), then saturates each value into the range the protocol allows for it: the stated
// valid range for commands, the wire type's range otherwise. Every difference between revisions
// is a profile field read here; nothing branches on a revision's name.
#include "ranger_can/wire/codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>

#include "ranger_can/text.hpp"
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
constexpr double kMillis = 1000.0;  // mm/s per m/s, mrad per rad
constexpr double kDeci = 10.0;      // 0.1 V, 0.1 A, 0.1 degC
constexpr double kCenti = 100.0;    // 0.01 V, 0.01 deg
constexpr double kRadPerCentideg = M_PI / 18000.0;
constexpr double kCentidegPerRad = 18000.0 / M_PI;

// Valid ranges of the 0x111 fields (manual 3.2; open point 1 for the linear speed).
constexpr double kMaxLinearSpeedMmps = interpretation::kMaxLinearSpeedMps * kMillis;
constexpr double kMaxSpinSpeedMmps = 1000.0;

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

// ---- Steering angles: the profile's unit and sign <-> rad, the manual's sign (right positive) --
struct AngleFormat {
  AngleUnit unit;
  SteeringSign sign;
};

inline double angle_from_wire(std::int16_t raw, AngleFormat fmt) {
  const double rad = fmt.unit == AngleUnit::kMilliradian ? raw / kMillis : raw * kRadPerCentideg;
  // 0.0 - x rather than -x: a zero angle stays +0.0 (it prints as 0.0, not -0.0).
  return fmt.sign == SteeringSign::kLeftPositive ? 0.0 - rad : rad;
}
inline double wire_units_per_rad(AngleUnit unit) {
  return unit == AngleUnit::kMilliradian ? kMillis : kCentidegPerRad;
}
// `limit_rad` (if finite) is the valid range of a command: the value saturates to it, rounded to
// the wire's unit (90 deg: 9000 x 0.01 deg, 1571 x 0.001 rad).
inline std::int16_t angle_to_wire(double rad, AngleFormat fmt,
                                  double limit_rad = std::numeric_limits<double>::infinity()) {
  const double per_rad = wire_units_per_rad(fmt.unit);
  double scaled = (fmt.sign == SteeringSign::kLeftPositive ? -rad : rad) * per_rad;
  if (std::isfinite(limit_rad)) {
    const double limit = std::round(limit_rad * per_rad);
    scaled = std::clamp(scaled, -limit, limit);
  }
  return wire::saturate_i16(scaled);
}

AngleFormat format_111(const ProtocolProfile& p) {
  return {p.steering_unit_111, p.steering_sign_111};
}
AngleFormat format_221(const ProtocolProfile& p) {
  return {p.steering_unit_221, p.steering_sign_221};
}
AngleFormat format_271(const ProtocolProfile& p) {
  return {p.steering_unit_271, p.steering_sign_271};
}

// ---- Other profile-driven scales --------------------------------------------------------------
// Wire units per volt of the 0x361 voltage (profile.validate() allows 0.01 and 0.1 V only).
inline double bms_units_per_volt(const ProtocolProfile& p) {
  return p.bms_voltage_scale == 0.1 ? kDeci : kCenti;
}
// The bits of the driver status byte that differ between the wire and the manual's meaning.
inline std::uint8_t driver_status_flip(const ProtocolProfile& p) {
  return p.driver_status_bit6 == DriverStatusBit6::kEnabled
             ? protocol::driver_status::kDriverDisabled
             : std::uint8_t{0};
}

// ---- Wire value <-> enum --------------------------------------------------------------------
// Several wire values map to one VehicleStatus (every undefined non-zero value is "abnormal": the
// safe reading), so SystemStatus keeps the raw byte as well.
VehicleStatus vehicle_status_from_wire(std::uint8_t raw, const ProtocolProfile& p) {
  if (raw == 0x00) return VehicleStatus::kNormal;
  if (raw == 0x01 && p.vehicle_status_1_is_estop) return VehicleStatus::kEmergencyStop;
  return VehicleStatus::kAbnormal;
}

// A MotionMode that is no enumerator: the `mode` of a command whose wire value the numbering
// does not define (never obeyed, to_string says "unknown").
constexpr auto kNoMotionMode = static_cast<MotionMode>(0xFF);

// ---- Error messages (only built on failure paths) ---------------------------------------------
using text::hex;

std::string id_text(std::uint32_t id) {
  return hex(id) + " (" + std::string(protocol::frame_name(id)) + ")";
}

Error too_short(const CanFrame& f, int layout) {
  return Error{Errc::kBadDlc, id_text(f.id) + ": DLC " + std::to_string(f.dlc) + ", expected " +
                                  std::to_string(layout) + " or more"};
}

Error dlc_above_8(const CanFrame& f) {
  return Error{Errc::kBadDlc, id_text(f.id) + ": DLC " + std::to_string(f.dlc) +
                                  " exceeds the 8 bytes of a classic CAN frame"};
}

Error implausible_angle(std::uint32_t id, const char* what, std::int16_t raw, AngleUnit unit,
                        double rad) {
  return Error{
      Errc::kOutOfRange,
      id_text(id) + text::format(": %s %d x %s = %.1f deg is beyond any model's reach "
                                 "(%.0f deg): impossible under this profile",
                                 what, static_cast<int>(raw),
                                 unit == AngleUnit::kMilliradian ? "0.001 rad" : "0.01 deg",
                                 rad_to_deg(rad),
                                 rad_to_deg(interpretation::kMaxPlausibleSteeringRad))};
}

// ---- Decoding ---------------------------------------------------------------------------------

constexpr std::uint32_t kHighSpeedFirst = protocol::kMotorHighSpeedBaseId + 1;
constexpr std::uint32_t kLowSpeedFirst = protocol::kMotorLowSpeedBaseId + 1;

bool plausible(double rad) {
  return std::fabs(rad) <= interpretation::kMaxPlausibleSteeringRad;
}

Message decode_motion_command(const std::uint8_t* d, const ProtocolProfile& p) {
  MotionCommand m;
  m.linear_speed = get_i16(d) / kMillis;
  m.yaw_rate = get_i16(d + 2) / kMillis;
  m.spin_speed = get_i16(d + 4) / kMillis;
  m.steering_angle = angle_from_wire(get_i16(d + 6), format_111(p));
  return m;
}

Message decode_system_status(const std::uint8_t* d, const ProtocolProfile& p) {
  SystemStatus s;
  s.vehicle_status_raw = d[0];
  s.vehicle_status = vehicle_status_from_wire(d[0], p);
  s.control_mode_raw = d[1];
  s.control_mode = static_cast<ControlMode>(d[1]);
  s.battery_voltage = get_u16(d + 2) / kDeci;
  if (p.error_word == ErrorWordLayout::kAgxV2_16) {
    s.error_bits = get_u16(d + 4);  // byte 6 reserved
    s.counter = d[7];
  } else {
    s.error_bits = get_u32(d + 4);
  }
  return s;
}

Result<Message> decode_motion_feedback(std::uint32_t id, const std::uint8_t* d,
                                       const ProtocolProfile& p) {
  MotionFeedback m;
  m.speed = get_i16(d) / kMillis;
  m.yaw_rate = get_i16(d + 2) / kMillis;
  m.lateral_speed = get_i16(d + 4) / kMillis;
  const std::int16_t raw = get_i16(d + 6);
  m.steering_angle = angle_from_wire(raw, format_221(p));
  if (!plausible(m.steering_angle)) {
    return implausible_angle(id, "steering angle", raw, p.steering_unit_221, m.steering_angle);
  }
  return Message{m};
}

Message decode_high_speed(int motor, const std::uint8_t* d) {
  MotorHighSpeedFeedback m;
  m.motor = motor;
  m.rpm = get_i16(d);
  m.current = get_i16(d + 2) / kDeci;
  m.position = get_i32(d + 4);
  return m;
}

Message decode_low_speed(int motor, const std::uint8_t* d, const ProtocolProfile& p) {
  MotorLowSpeedFeedback m;
  m.motor = motor;
  m.driver_voltage = get_u16(d) / kDeci;
  m.driver_temperature = get_i16(d + 2);
  m.motor_temperature = static_cast<std::int8_t>(d[4]);
  m.driver_status = static_cast<std::uint8_t>(d[5] ^ driver_status_flip(p));
  return m;
}

Result<Message> decode_steering_angles(std::uint32_t id, const std::uint8_t* d,
                                       const ProtocolProfile& p) {
  static constexpr const char* kWhat[4] = {"angle of motor 5", "angle of motor 6",
                                           "angle of motor 7", "angle of motor 8"};
  SteeringAnglesFeedback m;
  for (int i = 0; i < 4; ++i) {
    const std::int16_t raw = get_i16(d + 2 * i);
    m.angles[i] = angle_from_wire(raw, format_271(p));
    if (!plausible(m.angles[i])) {
      return implausible_angle(id, kWhat[i], raw, p.steering_unit_271, m.angles[i]);
    }
  }
  return Message{m};
}

Message decode_wheel_speeds(const std::uint8_t* d) {
  WheelSpeedsFeedback m;
  for (int i = 0; i < 4; ++i)
    m.speeds[i] = get_i16(d + 2 * i) / kMillis;
  return m;
}

Message decode_motion_mode_command(const std::uint8_t* d, const ProtocolProfile& p) {
  MotionModeCommand m;
  m.mode_raw = d[0];
  const auto mode = protocol::motion_mode_from_wire(d[0], p.mode_numbering);
  m.mode_known = mode.has_value();
  m.mode = mode.value_or(kNoMotionMode);
  return m;
}

Message decode_motion_mode_feedback(const std::uint8_t* d, const ProtocolProfile& p) {
  MotionModeFeedback m;
  m.mode_raw = d[0];
  const auto mode = protocol::motion_mode_from_wire(d[0], p.mode_numbering);
  m.mode_known = mode.has_value();
  m.mode = mode.value_or(MotionMode::kAckermann);
  m.switching = d[1] != 0;  // anything but "switch complete" is treated as still switching
  return m;
}

Message decode_ultrasonic(int first_sensor, const std::uint8_t* d) {
  UltrasonicFeedback m;
  m.first_sensor = first_sensor;
  for (int i = 0; i < 4; ++i)
    m.raw[i] = get_i16(d + 2 * i);
  return m;
}

Message decode_bms(std::uint32_t id, const std::uint8_t* d, const ProtocolProfile& p) {
  const int offset = static_cast<int>(id - protocol::kBmsBaseId);
  if (offset % 2 == 0) {
    BmsData b;
    b.battery = offset / 2;
    b.soc = d[0];
    b.soh = d[1];
    b.voltage = get_u16(d + 2) / bms_units_per_volt(p);
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

template <typename Light>
Message decode_light(const std::uint8_t* d) {
  Light l;
  l.enable = d[0] != 0;
  l.front_mode = static_cast<protocol::LightMode>(d[1]);
  l.front_custom = d[2];
  l.rear_mode = static_cast<protocol::LightMode>(d[3]);
  l.rear_custom = d[4];
  l.counter = d[7];
  return l;
}

Message decode_remote_control(const std::uint8_t* d) {
  RemoteControlState r;
  auto sw = [&](int shift) { return static_cast<protocol::RemoteSwitch>(d[0] >> shift & 0x03); };
  r.swa = sw(0);
  r.swb = sw(2);
  r.swc = sw(4);
  r.swd = sw(6);
  r.stick_right_h = static_cast<std::int8_t>(d[1]);
  r.stick_right_v = static_cast<std::int8_t>(d[2]);
  r.stick_left_v = static_cast<std::int8_t>(d[3]);
  r.stick_left_h = static_cast<std::int8_t>(d[4]);
  r.var_a = static_cast<std::int8_t>(d[5]);
  r.counter = d[7];
  return r;
}

Message decode_version(const CanFrame& f) {
  if (protocol::is_version_request(f)) return VersionRequest{};
  VersionResponse v;
  v.length = f.dlc;  // 1..8 here
  for (std::size_t i = 0; i < v.length; ++i)
    v.text[i] = static_cast<char>(f.data[i]);
  return v;
}

// Whether `f` is a RANGER frame its decoder can read: not an error frame, a known ID, at least its
// layout's length (the one length check: every decoder reads its layout's leading bytes only).
std::optional<Error> check_decodable(const CanFrame& f) {
  if (f.is_error) {
    return Error{Errc::kInvalidArgument,
                 "error frame (class " + hex(f.id, 8) + ") carries no RANGER message"};
  }
  const int layout = protocol::layout_dlc(f.id);
  if (layout < 0) {
    return Error{Errc::kUnknownId, "ID " + hex(f.id) + " is not part of the RANGER protocol (DLC " +
                                       std::to_string(f.dlc) + ")"};
  }
  if (f.dlc > CanFrame::kMaxDlc) return dlc_above_8(f);
  if (f.dlc < layout) return too_short(f, layout);
  return std::nullopt;
}

}  // namespace

Result<Message> decode(const CanFrame& f, const ProtocolProfile& p) {
  if (auto error = check_decodable(f)) return std::move(*error);
  const std::uint8_t* d = f.data.data();
  // The motors' frames: one layout each for the eight motors.
  if (f.id >= kHighSpeedFirst && f.id < kHighSpeedFirst + protocol::kMotorCount) {
    return decode_high_speed(static_cast<int>(f.id - protocol::kMotorHighSpeedBaseId), d);
  }
  if (f.id >= kLowSpeedFirst && f.id < kLowSpeedFirst + protocol::kMotorCount) {
    return decode_low_speed(static_cast<int>(f.id - protocol::kMotorLowSpeedBaseId), d, p);
  }
  switch (f.id) {
    case protocol::kMotionCommandId:
      return decode_motion_command(d, p);
    case protocol::kLightCommandId:
      return decode_light<LightCommand>(d);
    case protocol::kMotionModeCommandId:
      return decode_motion_mode_command(d, p);
    case protocol::kControlModeCommandId:
      return Message{ControlModeCommand{static_cast<ControlMode>(d[0])}};
    case protocol::kErrorClearCommandId:
      return Message{ErrorClearCommand{d[0]}};
    case protocol::kUltrasonicSettingId:
      return Message{UltrasonicSettingCommand{d[0] != 0}};
    case protocol::kVersionId:
      return decode_version(f);
    case protocol::kSystemStatusId:
      return decode_system_status(d, p);
    case protocol::kMotionFeedbackId:
      return decode_motion_feedback(f.id, d, p);
    case protocol::kLightStateId:
      return decode_light<LightState>(d);
    case protocol::kRemoteControlStateId:
      return decode_remote_control(d);
    case protocol::kSteeringAnglesId:
      return decode_steering_angles(f.id, d, p);
    case protocol::kWheelSpeedsId:
      return decode_wheel_speeds(d);
    case protocol::kMotionModeFeedbackId:
      return decode_motion_mode_feedback(d, p);
    case protocol::kOdometerId:
      return Message{OdometerFeedback{get_i32(d), get_i32(d + 4)}};
    case protocol::kUltrasonic1to4Id:
      return decode_ultrasonic(1, d);
    case protocol::kUltrasonic5to8Id:
      return decode_ultrasonic(5, d);
    case protocol::kUltrasonicSettingFeedbackId:
      return Message{UltrasonicSettingFeedback{d[0] != 0}};
    default:
      break;
  }
  // Every other known ID is a BMS frame (0x361-0x36A).
  return decode_bms(f.id, d, p);
}

Result<Message> decode(const CanFrame& frame) {
  return decode(frame, manual_profile());
}

// ---- Encoding ---------------------------------------------------------------------------------

namespace {

// The error for a NaN or infinite `message.field` (built only on that path).
Error not_finite(const char* message, const char* field, double value) {
  return Error{Errc::kNotFinite, std::string(message) + "." + field + " is " +
                                     (std::isnan(value) ? "NaN" : "infinite") +
                                     ": refusing to encode it"};
}

Error invalid(const char* message, const char* field, long value, const std::string& valid) {
  return Error{Errc::kInvalidArgument, std::string(message) + "." + field + " = " +
                                           std::to_string(value) + " is invalid (valid: " + valid +
                                           ")"};
}

// The modes a numbering defines, as "0 ackermann, 1 oblique, 2 spin".
std::string numbering_text(ModeNumbering numbering) {
  std::string out;
  int i = 0;
  for (const MotionMode m : protocol::motion_modes(numbering)) {
    out += (i ? ", " : "") + std::to_string(i) + " " + std::string(protocol::to_string(m));
    ++i;
  }
  return out + " under mode numbering " + std::string(to_string(numbering));
}

#define RANGER_REQUIRE_FINITE(msg, obj, field)                                    \
  do {                                                                            \
    if (!std::isfinite((obj).field)) return not_finite(msg, #field, (obj).field); \
  } while (0)

// One encoder per message: its frame is the one of `Encoder::frame_for`.
class Encoder {
 public:
  explicit Encoder(const ProtocolProfile& p) : p_(p) {}

  // A zeroed frame for `id` with the DLC of its layout, or 8 under tx_dlc 8.
  CanFrame frame_for(std::uint32_t id, int length = -1) const {
    CanFrame f;
    f.id = id;
    const int layout = length >= 0 ? length : protocol::layout_dlc(id);
    f.dlc = static_cast<std::uint8_t>(p_.tx_dlc == 8 ? 8 : layout);
    return f;
  }

  Result<CanFrame> operator()(const MotionCommand& m) const {
    RANGER_REQUIRE_FINITE("motion_command", m, linear_speed);
    RANGER_REQUIRE_FINITE("motion_command", m, spin_speed);
    RANGER_REQUIRE_FINITE("motion_command", m, steering_angle);
    RANGER_REQUIRE_FINITE("motion_command", m, yaw_rate);
    CanFrame f = frame_for(protocol::kMotionCommandId);
    put_i16(&f.data[0], wire::saturate_i16(std::clamp(m.linear_speed * kMillis,
                                                      -kMaxLinearSpeedMmps, kMaxLinearSpeedMmps)));
    put_i16(&f.data[2], wire::saturate_i16(m.yaw_rate * kMillis));
    // Bytes 4-5 carry the manual's spin speed, valid +-1000 mm/s, when the spin goes there;
    // otherwise (agx_v2's "lateral speed") only the wire type limits them.
    const double spin_mmps = m.spin_speed * kMillis;
    put_i16(&f.data[4],
            wire::saturate_i16(p_.spin_field == SpinField::kWheelSpeed
                                   ? std::clamp(spin_mmps, -kMaxSpinSpeedMmps, kMaxSpinSpeedMmps)
                                   : spin_mmps));
    put_i16(&f.data[6], angle_to_wire(m.steering_angle, format_111(p_), kMaxObliqueSteeringRad));
    return f;
  }

  Result<CanFrame> operator()(const MotionModeCommand& m) const {
    const auto wire_value = protocol::motion_mode_to_wire(m.mode, p_.mode_numbering);
    if (!wire_value) {
      return invalid("motion_mode_command", "mode", static_cast<long>(m.mode),
                     numbering_text(p_.mode_numbering));
    }
    CanFrame f = frame_for(protocol::kMotionModeCommandId);
    f.data[0] = *wire_value;
    return f;
  }

  Result<CanFrame> operator()(const ControlModeCommand& m) const {
    if (m.mode != ControlMode::kStandby && m.mode != ControlMode::kCan) {
      return invalid("control_mode_command", "mode", static_cast<long>(m.mode),
                     "0 standby, 1 CAN; the host cannot select remote or UART mode");
    }
    CanFrame f = frame_for(protocol::kControlModeCommandId);
    f.data[0] = static_cast<std::uint8_t>(m.mode);
    return f;
  }

  Result<CanFrame> operator()(const ErrorClearCommand& m) const {
    if (m.code > protocol::kMaxErrorClearCode) {
      return invalid("error_clear_command", "code", m.code, "0x00..0x10");
    }
    CanFrame f = frame_for(protocol::kErrorClearCommandId);
    f.data[0] = m.code;
    return f;
  }

  Result<CanFrame> operator()(const UltrasonicSettingCommand& m) const {
    CanFrame f = frame_for(protocol::kUltrasonicSettingId);
    f.data[0] = m.enable ? 0x01 : 0x00;
    return f;
  }

  Result<CanFrame> operator()(const LightCommand& m) const {
    const auto max_mode = static_cast<long>(protocol::LightMode::kCustom);
    if (static_cast<long>(m.front_mode) > max_mode) {
      return invalid("light_command", "front_mode", static_cast<long>(m.front_mode),
                     "0 off, 1 on, 2 breathing, 3 custom");
    }
    if (static_cast<long>(m.rear_mode) > max_mode) {
      return invalid("light_command", "rear_mode", static_cast<long>(m.rear_mode),
                     "0 off, 1 on, 2 breathing, 3 custom");
    }
    return light(protocol::kLightCommandId, m);
  }

  Result<CanFrame> operator()(const VersionRequest&) const {
    CanFrame f = frame_for(protocol::kVersionId);
    f.data[0] = protocol::kVersionRequestValue;
    return f;
  }

  Result<CanFrame> operator()(const SystemStatus& s) const {
    RANGER_REQUIRE_FINITE("system_status", s, battery_voltage);
    const auto status = static_cast<std::uint8_t>(s.vehicle_status);
    if (status > static_cast<std::uint8_t>(VehicleStatus::kAbnormal)) {
      return invalid("system_status", "vehicle_status", status, "0 normal, 1 e-stop, 2 abnormal");
    }
    const bool agx16 = p_.error_word == ErrorWordLayout::kAgxV2_16;
    if (agx16 && s.error_bits > 0xFFFFu) {
      return invalid("system_status", "error_bits", static_cast<long>(s.error_bits),
                     "a 16-bit word under the error-word layout agx16");
    }
    CanFrame f = frame_for(protocol::kSystemStatusId);
    // The raw byte wins when it is one of the wire values that decode to `vehicle_status`, so a
    // decoded frame re-encodes byte-exact; otherwise the enum's own value is sent.
    f.data[0] = vehicle_status_from_wire(s.vehicle_status_raw, p_) == s.vehicle_status
                    ? s.vehicle_status_raw
                    : status;
    f.data[1] = static_cast<std::uint8_t>(s.control_mode);
    put_u16(&f.data[2], wire::saturate_u16(s.battery_voltage * kDeci));
    if (agx16) {
      put_u16(&f.data[4], static_cast<std::uint16_t>(s.error_bits));
      f.data[7] = s.counter.value_or(0);
    } else {
      put_u32(&f.data[4], s.error_bits);  // the manual's layout has no counter: not sent
    }
    return f;
  }

  Result<CanFrame> operator()(const MotionFeedback& m) const {
    RANGER_REQUIRE_FINITE("motion_feedback", m, speed);
    RANGER_REQUIRE_FINITE("motion_feedback", m, steering_angle);
    RANGER_REQUIRE_FINITE("motion_feedback", m, yaw_rate);
    RANGER_REQUIRE_FINITE("motion_feedback", m, lateral_speed);
    CanFrame f = frame_for(protocol::kMotionFeedbackId);
    put_i16(&f.data[0], wire::saturate_i16(m.speed * kMillis));
    put_i16(&f.data[2], wire::saturate_i16(m.yaw_rate * kMillis));
    put_i16(&f.data[4], wire::saturate_i16(m.lateral_speed * kMillis));
    put_i16(&f.data[6], angle_to_wire(m.steering_angle, format_221(p_)));
    return f;
  }

  Result<CanFrame> operator()(const MotorHighSpeedFeedback& m) const {
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

  Result<CanFrame> operator()(const MotorLowSpeedFeedback& m) const {
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
    f.data[5] = static_cast<std::uint8_t>(m.driver_status ^ driver_status_flip(p_));
    return f;
  }

  Result<CanFrame> operator()(const SteeringAnglesFeedback& m) const {
    static constexpr const char* kNames[4] = {"angles[0]", "angles[1]", "angles[2]", "angles[3]"};
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(m.angles[i])) return not_finite("steering_angles", kNames[i], m.angles[i]);
    }
    CanFrame f = frame_for(protocol::kSteeringAnglesId);
    for (int i = 0; i < 4; ++i)
      put_i16(&f.data[2 * i], angle_to_wire(m.angles[i], format_271(p_)));
    return f;
  }

  Result<CanFrame> operator()(const WheelSpeedsFeedback& m) const {
    static constexpr const char* kNames[4] = {"speeds[0]", "speeds[1]", "speeds[2]", "speeds[3]"};
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(m.speeds[i])) return not_finite("wheel_speeds", kNames[i], m.speeds[i]);
    }
    CanFrame f = frame_for(protocol::kWheelSpeedsId);
    for (int i = 0; i < 4; ++i)
      put_i16(&f.data[2 * i], wire::saturate_i16(m.speeds[i] * kMillis));
    return f;
  }

  Result<CanFrame> operator()(const MotionModeFeedback& m) const {
    // Feedback may carry any mode byte (the simulator injects faults with it): an unknown mode is
    // sent as its raw byte. A known mode must exist in the numbering.
    std::uint8_t value = m.mode_raw;
    if (m.mode_known) {
      const auto wire_value = protocol::motion_mode_to_wire(m.mode, p_.mode_numbering);
      if (!wire_value) {
        return invalid("motion_mode", "mode", static_cast<long>(m.mode),
                       numbering_text(p_.mode_numbering) + ", or mode_known = false");
      }
      value = *wire_value;
    }
    CanFrame f = frame_for(protocol::kMotionModeFeedbackId);
    f.data[0] = value;
    f.data[1] = m.switching ? 0x01 : 0x00;
    return f;
  }

  Result<CanFrame> operator()(const UltrasonicFeedback& m) const {
    if (m.first_sensor != 1 && m.first_sensor != 5) {
      return invalid("ultrasonic", "first_sensor", m.first_sensor, "1 (0x342) or 5 (0x343)");
    }
    CanFrame f =
        frame_for(m.first_sensor == 1 ? protocol::kUltrasonic1to4Id : protocol::kUltrasonic5to8Id);
    for (int i = 0; i < 4; ++i)
      put_i16(&f.data[2 * i], m.raw[i]);
    return f;
  }

  Result<CanFrame> operator()(const UltrasonicSettingFeedback& m) const {
    CanFrame f = frame_for(protocol::kUltrasonicSettingFeedbackId);
    f.data[0] = m.enabled ? 0x01 : 0x00;
    return f;
  }

  Result<CanFrame> operator()(const BmsData& b) const {
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
    put_u16(&f.data[2], wire::saturate_u16(b.voltage * bms_units_per_volt(p_)));
    put_i16(&f.data[4], wire::saturate_i16(b.current * kDeci));
    put_i16(&f.data[6], wire::saturate_i16(b.temperature * kDeci));
    return f;
  }

  Result<CanFrame> operator()(const BmsAlarm& a) const {
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

  Result<CanFrame> operator()(const LightState& m) const {
    return light(protocol::kLightStateId, m);
  }

  Result<CanFrame> operator()(const RemoteControlState& r) const {
    CanFrame f = frame_for(protocol::kRemoteControlStateId);
    auto sw = [](protocol::RemoteSwitch s, int shift) {
      return static_cast<std::uint8_t>((static_cast<unsigned>(s) & 0x03u) << shift);
    };
    f.data[0] =
        static_cast<std::uint8_t>(sw(r.swa, 0) | sw(r.swb, 2) | sw(r.swc, 4) | sw(r.swd, 6));
    f.data[1] = static_cast<std::uint8_t>(r.stick_right_h);
    f.data[2] = static_cast<std::uint8_t>(r.stick_right_v);
    f.data[3] = static_cast<std::uint8_t>(r.stick_left_v);
    f.data[4] = static_cast<std::uint8_t>(r.stick_left_h);
    f.data[5] = static_cast<std::uint8_t>(r.var_a);
    f.data[7] = r.counter;
    return f;
  }

  Result<CanFrame> operator()(const OdometerFeedback& o) const {
    CanFrame f = frame_for(protocol::kOdometerId);
    put_u32(&f.data[0], static_cast<std::uint32_t>(o.left_wheel));
    put_u32(&f.data[4], static_cast<std::uint32_t>(o.right_wheel));
    return f;
  }

  Result<CanFrame> operator()(const VersionResponse& v) const {
    if (v.length < 1 || v.length > v.text.size()) {
      return invalid("version_response", "length", v.length, "1..8 characters");
    }
    CanFrame f = frame_for(protocol::kVersionId, v.length);
    for (std::size_t i = 0; i < v.length; ++i)
      f.data[i] = static_cast<std::uint8_t>(v.text[i]);
    if (protocol::is_version_request(f)) {
      return Error{Errc::kInvalidArgument,
                   "version_response: the text \\x01 would read as a version request"};
    }
    return f;
  }

 private:
  template <typename Light>
  CanFrame light(std::uint32_t id, const Light& m) const {
    CanFrame f = frame_for(id);
    f.data[0] = m.enable ? 0x01 : 0x00;
    f.data[1] = static_cast<std::uint8_t>(m.front_mode);
    f.data[2] = m.front_custom;
    f.data[3] = static_cast<std::uint8_t>(m.rear_mode);
    f.data[4] = m.rear_custom;
    f.data[7] = m.counter;
    return f;
  }

  const ProtocolProfile& p_;
};

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
  std::uint32_t operator()(const LightCommand&) const { return protocol::kLightCommandId; }
  std::uint32_t operator()(const LightState&) const { return protocol::kLightStateId; }
  std::uint32_t operator()(const RemoteControlState&) const {
    return protocol::kRemoteControlStateId;
  }
  std::uint32_t operator()(const OdometerFeedback&) const { return protocol::kOdometerId; }
  std::uint32_t operator()(const VersionRequest&) const { return protocol::kVersionId; }
  std::uint32_t operator()(const VersionResponse&) const { return protocol::kVersionId; }
};

}  // namespace

Result<CanFrame> encode(const Message& message, const ProtocolProfile& profile) {
  return std::visit(Encoder(profile), message);
}

Result<CanFrame> encode(const Message& message) {
  return encode(message, manual_profile());
}

std::uint32_t id_of(const Message& message) {
  return std::visit(IdOf{}, message);
}

}  // namespace ranger
