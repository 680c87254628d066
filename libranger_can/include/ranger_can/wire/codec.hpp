// Typed RANGER messages in SI units and their byte-exact CAN encoding, in both directions, for
// any protocol profile (profile.hpp: the manual, the vendor's agx_v2 revision, or any mix).
//
// One convention for every message, whatever the profile: SI units and the manual's signs
// (steering positive = right; driver status bit 6 set = disabled). The profile says how the wire
// carries them (units, signs, the error-word layout, the BMS voltage scale, the motion-mode
// numbering, the DLC of encoded frames); the codec converts. Spin values (MotionCommand's
// spin_speed and yaw_rate, MotionFeedback's speed and yaw_rate in spin mode) are passed as they
// are on the wire: the profile's spin_sign is applied above (interpretation::spin_ccw_from_wire).
// Conversion to ROS conventions (REP-103) happens in kinematics/odometry through
// interpretation.hpp, never here.
//
// Encoding saturates each field to what the protocol can express (never wraps an int16) and
// refuses NaN/inf with Errc::kNotFinite. Decoding reads a frame's leading bytes (its layout): a
// longer frame decodes and its extra bytes are ignored (protocol::extra_bytes counts them), a
// shorter one is refused; it never reads past `dlc`.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// ---- Host -> chassis --------------------------------------------------------------------------

// 0x111. linear_speed acts in Ackermann and oblique modes, the spin input in spin mode only
// (the manual's spin_speed in bytes 4-5, or agx_v2's yaw_rate in bytes 2-3: the profile's
// spin_field says which one the kinematics fills), steering_angle in Ackermann (+-40 deg) and
// oblique (+-90 deg) modes.
struct MotionCommand {
  double linear_speed = 0.0;  // m/s, forward positive (bytes 0-1: int16 mm/s, +-2600)
  // m/s wheel speed, as on the wire (manual: CCW positive) (bytes 4-5: int16 mm/s, +-1000 when
  // the profile's spin_field is wheel_speed; agx_v2 calls these bytes "lateral speed", 0 on a
  // RANGER, and they saturate to int16 only)
  double spin_speed = 0.0;
  // rad, manual sign: positive right (bytes 6-7: int16, 0.01 deg or 0.001 rad, +-90 deg)
  double steering_angle = 0.0;
  // rad/s, as on the wire (agx_v2: CCW positive) (bytes 2-3: int16 0.001 rad/s; manual: reserved)
  double yaw_rate = 0.0;
};
// 0x111's valid ranges in SI units, for code above the codec (the linear speed's range is open
// point 1: interpretation::kMaxLinearSpeedMps).
inline constexpr double kMaxAckermannSteeringRad = deg_to_rad(40.0);  // +-4000 x 0.01 deg
inline constexpr double kMaxObliqueSteeringRad = deg_to_rad(90.0);    // +-9000 x 0.01 deg
inline constexpr double kMaxSpinSpeedMps = 1.0;                       // +-1000 mm/s
struct MotionModeCommand {                                            // 0x141
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  // Decoding only: the wire byte, and whether the profile's numbering defines it (when not,
  // `mode` holds no enumerator and the command must not be obeyed). Encoding writes `mode`.
  std::uint8_t mode_raw = 0;
  bool mode_known = true;
};
struct ControlModeCommand {  // 0x421; the only host-settable modes are standby and CAN
  protocol::ControlMode mode = protocol::ControlMode::kCan;
};
struct ErrorClearCommand {  // 0x441
  std::uint8_t code = 0;    // protocol::ErrorClearCode, 0x00..0x10
};
struct UltrasonicSettingCommand {  // 0x451
  bool enable = false;
};
struct LightCommand {                                          // 0x121 (agx_v2)
  bool enable = false;                                         // byte 0: lights under CAN control
  protocol::LightMode front_mode = protocol::LightMode::kOff;  // byte 1
  std::uint8_t front_custom = 0;                               // byte 2: custom brightness
  protocol::LightMode rear_mode = protocol::LightMode::kOff;   // byte 3
  std::uint8_t rear_custom = 0;                                // byte 4
  std::uint8_t counter = 0;                                    // byte 7
};
struct VersionRequest {};  // 0x4A1 (agx_v2), DLC 1, byte 0 = 0x01

// ---- Chassis -> host --------------------------------------------------------------------------

struct SystemStatus {  // 0x211
  protocol::VehicleStatus vehicle_status = protocol::VehicleStatus::kNormal;
  std::uint8_t vehicle_status_raw = 0;  // as on the wire (an unknown value is kept here)
  protocol::ControlMode control_mode = protocol::ControlMode::kStandby;
  std::uint8_t control_mode_raw = 0;
  double battery_voltage = 0.0;  // V (wire: uint16 0.1 V)
  // The error word of the profile's layout: kManual32 bytes 4-7 (byte 4 most significant),
  // kAgxV2_16 bytes 4-5. Names via protocol::error_bit_names(bits, layout).
  std::uint32_t error_bits = 0;
  std::optional<std::uint8_t> counter;  // byte 7 under kAgxV2_16; none under kManual32
};
struct MotionFeedback {         // 0x221
  double speed = 0.0;           // m/s, reversing negative (bytes 0-1)
  double steering_angle = 0.0;  // rad, manual sign: negative left, positive right (bytes 6-7)
  double yaw_rate = 0.0;        // rad/s, as on the wire (bytes 2-3: 0.001 rad/s; manual: reserved)
  double lateral_speed = 0.0;   // m/s (bytes 4-5: mm/s; manual: reserved)
};
struct MotorHighSpeedFeedback {  // 0x251..0x258
  int motor = 1;                 // 1..8, see protocol.hpp for the numbering
  double rpm = 0.0;              // motor speed, RPM
  double current = 0.0;          // A (wire: int16 0.1 A)
  std::int32_t position = 0;     // encoder pulses
};
struct MotorLowSpeedFeedback {  // 0x261..0x268
  int motor = 1;
  double driver_voltage = 0.0;      // V (wire: uint16 0.1 V)
  double driver_temperature = 0.0;  // degC (wire: int16 1 degC)
  double motor_temperature = 0.0;   // degC (wire: int8 1 degC)
  // bits: protocol::driver_status_bits(), in the manual's meaning (bit 6 = disabled) whatever
  // the profile's driver_status_bit6
  std::uint8_t driver_status = 0;
};
struct SteeringAnglesFeedback {    // 0x271, motors 5,6,7,8 = RF, RR, LR, LF
  std::array<double, 4> angles{};  // rad, manual sign (positive = right; open point 3)
};
struct WheelSpeedsFeedback {       // 0x281, motors 1,2,3,4 = RF, RR, LR, LF
  std::array<double, 4> speeds{};  // m/s
};
struct MotionModeFeedback {  // 0x291
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  std::uint8_t mode_raw = 0;  // as on the wire
  // false when the profile's numbering does not define mode_raw: `mode` is then kAckermann and
  // must not be acted on (the switching flag is still valid). Encoding writes mode_raw then.
  bool mode_known = true;
  bool switching = false;
};
struct UltrasonicFeedback {  // 0x342 (sensors 1-4) / 0x343 (sensors 5-8)
  int first_sensor = 1;      // 1 or 5
  // > 0: distance in mm; 0: no reading; < 0: protocol::UltrasonicCode (interpretation.hpp)
  std::array<std::int16_t, 4> raw{};
};
struct UltrasonicSettingFeedback {  // 0x45A
  bool enabled = false;
};
struct BmsData {         // 0x361 / 0x363 / 0x365 / 0x367 / 0x369
  int battery = 0;       // 0 = whole pack, 1..4 = battery slot
  double soc = 0.0;      // % 0..100
  double soh = 0.0;      // % 0..100
  double voltage = 0.0;  // V (wire: uint16, the profile's bms_voltage_scale: 0.01 V or 0.1 V)
  // A, as on the wire (int16 0.1 A); which way it counts is the profile's bms_current_sign
  // (interpretation::bms_discharge_current)
  double current = 0.0;
  double temperature = 0.0;  // degC (wire: int16 0.1 degC)
};
struct BmsAlarm {  // 0x362 / 0x364 / 0x366 / 0x368 / 0x36A
  int battery = 0;
  std::uint8_t alarm1 = 0;  // protocol::bms_status1_bits()
  std::uint8_t alarm2 = 0;  // protocol::bms_status2_bits()
  std::uint8_t warning1 = 0;
  std::uint8_t warning2 = 0;
};

struct LightState {  // 0x231 (agx_v2): the layout of 0x121
  bool enable = false;
  protocol::LightMode front_mode = protocol::LightMode::kOff;
  std::uint8_t front_custom = 0;
  protocol::LightMode rear_mode = protocol::LightMode::kOff;
  std::uint8_t rear_custom = 0;
  std::uint8_t counter = 0;
};
struct RemoteControlState {  // 0x241 (agx_v2)
  // Byte 0: SWA bits 1:0, SWB 3:2, SWC 5:4, SWD 7:6.
  protocol::RemoteSwitch swa = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swb = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swc = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swd = protocol::RemoteSwitch::kUndefined;
  // Bytes 1-5, int8 stick and knob positions (names and order of the vendor's SDK).
  std::int8_t stick_right_h = 0;
  std::int8_t stick_right_v = 0;
  std::int8_t stick_left_v = 0;
  std::int8_t stick_left_h = 0;
  std::int8_t var_a = 0;
  std::uint8_t counter = 0;  // byte 7
};
struct OdometerFeedback {        // 0x311 (agx_v2): two int32, unit not stated by any source: raw
  std::int32_t left_wheel = 0;   // bytes 0-3
  std::int32_t right_wheel = 0;  // bytes 4-7
};
struct VersionResponse {  // 0x4A1 (agx_v2): a chassis's answer, up to 8 ASCII characters a frame
  std::array<char, 8> text{};
  std::uint8_t length = 0;  // bytes of `text` in use (the frame's DLC when decoded)
  // The text without trailing NUL bytes (padding).
  std::string_view view() const {
    std::size_t n = length < text.size() ? length : text.size();
    while (n > 0 && text[n - 1] == '\0')
      --n;
    return std::string_view(text.data(), n);
  }
};

// Any RANGER message (either revision).
using Message =
    std::variant<MotionCommand, MotionModeCommand, ControlModeCommand, ErrorClearCommand,
                 UltrasonicSettingCommand, SystemStatus, MotionFeedback, MotorHighSpeedFeedback,
                 MotorLowSpeedFeedback, SteeringAnglesFeedback, WheelSpeedsFeedback,
                 MotionModeFeedback, UltrasonicFeedback, UltrasonicSettingFeedback, BmsData,
                 BmsAlarm, LightCommand, LightState, RemoteControlState, OdometerFeedback,
                 VersionRequest, VersionResponse>;

// Decodes a frame of any ID of either revision, under `profile`. A frame longer than its layout
// decodes from its leading bytes. Errors: kUnknownId; kBadDlc for a frame shorter than its
// layout, or a DLC above 8 (the message names ID and DLCs); kOutOfRange for content no RANGER
// model can send under this profile: a 0x221 or 0x271 steering angle beyond
// interpretation::kMaxPlausibleSteeringRad (the message names ID and value); kInvalidArgument for
// an error frame. Unknown enum values decode (raw kept), they are not errors: an undefined vehicle
// status reads as kAbnormal, never kNormal; a motion mode the profile's numbering does not define
// decodes with mode_known = false; a boolean byte (0x451, 0x45A, 0x291 byte 1, 0x121/0x231 byte
// 0) is true when non-zero. Does not allocate on success.
Result<Message> decode(const CanFrame& frame, const ProtocolProfile& profile);
// The same under the manual's preset (manual_profile()).
Result<Message> decode(const CanFrame& frame);

// Encodes a message under `profile`; the frame's DLC is its layout's (protocol::layout_dlc), or 8
// (zero-padded) when the profile's tx_dlc is 8. Values outside the protocol's range saturate
// (never wrap): 0x111 to its valid ranges (+-interpretation::kMaxLinearSpeedMps, spin +-1 m/s,
// steering +-90 deg), BMS SOC/SOH to 0..100 %, everything else to its wire type. NaN/inf give
// kNotFinite naming the field ("motion_command.linear_speed is NaN ..."); out-of-range indices
// (motor 9, battery 5, sensor group 3) and values a host may not send or the profile cannot carry
// (0x441 code 0x11, a motion mode the numbering lacks, control mode remote, a light mode above 3,
// an error word wider than the layout's) give kInvalidArgument. Feedback enums are written as
// they are, SystemStatus writes vehicle_status_raw when it decodes to vehicle_status (else the
// enum's value), MotionModeFeedback writes mode_raw when mode_known is false, so decoding then
// encoding any valid frame under the same profile is byte-exact up to reserved and padding bytes.
// The frame has stamp 0.
Result<CanFrame> encode(const Message& message, const ProtocolProfile& profile);
// The same under the manual's preset (manual_profile()).
Result<CanFrame> encode(const Message& message);

// The frame ID a message encodes to (for a valid message).
std::uint32_t id_of(const Message& message);

// ---- Wire-level helpers (exposed for tests and the DBC cross-check) --------------------------
namespace wire {
// Round to nearest, then saturate into the int16 range; callers check finiteness first.
std::int16_t saturate_i16(double scaled);
std::uint16_t saturate_u16(double scaled);
std::int8_t saturate_i8(double scaled);
std::uint8_t saturate_u8(double scaled);
}  // namespace wire

}  // namespace ranger
