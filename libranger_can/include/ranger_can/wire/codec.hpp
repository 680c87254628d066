// Typed RANGER messages in SI units and their byte-exact CAN encoding, in both directions.
//
// Every struct carries the manual's own sign conventions (e.g. steering positive = right): the
// codec is a faithful picture of the wire. Conversion to ROS conventions (REP-103) happens in
// kinematics/odometry through interpretation.hpp, never here.
//
// Encoding saturates each field to what the protocol can express (never wraps an int16) and
// refuses NaN/inf with Errc::kNotFinite. Decoding checks ID and DLC and never reads past `dlc`.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <variant>

#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/result.hpp"

namespace ranger {

// ---- Host -> chassis --------------------------------------------------------------------------

// 0x111. linear_speed acts in Ackermann and oblique modes, spin_speed in spin mode only,
// steering_angle in Ackermann (+-40 deg) and oblique (+-90 deg) modes.
struct MotionCommand {
  double linear_speed = 0.0;    // m/s, forward positive           (wire: int16 mm/s)
  double spin_speed = 0.0;      // m/s wheel speed, CCW positive    (wire: int16 mm/s, +-1000)
  double steering_angle = 0.0;  // rad, manual sign: positive right (wire: int16 0.01 deg, +-9000)
};
// 0x111's valid ranges in SI units, for code above the codec (the linear speed's range is open
// point 1: interpretation::kMaxLinearSpeedMps).
inline constexpr double kMaxAckermannSteeringRad = 40.0 * M_PI / 180.0;  // +-4000 x 0.01 deg
inline constexpr double kMaxObliqueSteeringRad = 90.0 * M_PI / 180.0;    // +-9000 x 0.01 deg
inline constexpr double kMaxSpinSpeedMps = 1.0;                          // +-1000 mm/s
struct MotionModeCommand {                                               // 0x141
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
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

// ---- Chassis -> host --------------------------------------------------------------------------

struct SystemStatus {  // 0x211
  protocol::VehicleStatus vehicle_status = protocol::VehicleStatus::kNormal;
  std::uint8_t vehicle_status_raw = 0;  // as on the wire (an unknown value is kept here)
  protocol::ControlMode control_mode = protocol::ControlMode::kStandby;
  std::uint8_t control_mode_raw = 0;
  double battery_voltage = 0.0;  // V (wire: uint16 0.1 V)
  std::uint32_t error_bits = 0;  // byte 4 most significant; names via protocol::error_bit_names
};
struct MotionFeedback {         // 0x221
  double speed = 0.0;           // m/s, reversing negative
  double steering_angle = 0.0;  // rad, manual sign: negative left, positive right
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
  std::uint8_t driver_status = 0;   // bits: protocol::driver_status_bits()
};
struct SteeringAnglesFeedback {    // 0x271, motors 5,6,7,8 = RF, RR, LR, LF
  std::array<double, 4> angles{};  // rad, manual sign (interpretation.hpp, open point 3)
};
struct WheelSpeedsFeedback {       // 0x281, motors 1,2,3,4 = RF, RR, LR, LF
  std::array<double, 4> speeds{};  // m/s
};
struct MotionModeFeedback {  // 0x291
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  std::uint8_t mode_raw = 0;
  bool switching = false;
};
struct UltrasonicFeedback {           // 0x342 (sensors 1-4) / 0x343 (sensors 5-8)
  int first_sensor = 1;               // 1 or 5
  std::array<std::int16_t, 4> raw{};  // >= 0: distance in mm; < 0: protocol::UltrasonicCode
};
struct UltrasonicSettingFeedback {  // 0x45A
  bool enabled = false;
};
struct BmsData {             // 0x361 / 0x363 / 0x365 / 0x367 / 0x369
  int battery = 0;           // 0 = whole pack, 1..4 = battery slot
  double soc = 0.0;          // % 0..100
  double soh = 0.0;          // % 0..100
  double voltage = 0.0;      // V (wire: uint16 0.01 V)
  double current = 0.0;      // A (wire: int16 0.1 A)
  double temperature = 0.0;  // degC (wire: int16 0.1 degC)
};
struct BmsAlarm {  // 0x362 / 0x364 / 0x366 / 0x368 / 0x36A
  int battery = 0;
  std::uint8_t alarm1 = 0;  // protocol::bms_status1_bits()
  std::uint8_t alarm2 = 0;  // protocol::bms_status2_bits()
  std::uint8_t warning1 = 0;
  std::uint8_t warning2 = 0;
};

// Any RANGER message.
using Message = std::variant<MotionCommand, MotionModeCommand, ControlModeCommand,
                             ErrorClearCommand, UltrasonicSettingCommand, SystemStatus,
                             MotionFeedback, MotorHighSpeedFeedback, MotorLowSpeedFeedback,
                             SteeringAnglesFeedback, WheelSpeedsFeedback, MotionModeFeedback,
                             UltrasonicFeedback, UltrasonicSettingFeedback, BmsData, BmsAlarm>;

// Decodes a frame of any RANGER ID. Errors: kUnknownId, kBadDlc (message names ID and DLCs),
// kInvalidArgument for an error frame. Unknown enum values decode (raw kept), they are not errors:
// an undefined vehicle status reads as kAbnormal, never kNormal; a boolean byte (0x451, 0x45A,
// 0x291 byte 1) is true when non-zero. Does not allocate on success.
Result<Message> decode(const CanFrame& frame);

// Encodes a message. Values outside the protocol's range saturate (never wrap): 0x111 to its
// valid ranges (+-interpretation::kMaxLinearSpeedMps, spin +-1 m/s, steering +-90 deg), BMS
// SOC/SOH to 0..100 %, everything else to its wire type. NaN/inf give kNotFinite naming the field
// ("motion_command.linear_speed is NaN ..."); out-of-range indices (motor 9, battery 5, sensor
// group 3) and command values a host may not send (0x441 code 0x11, motion mode 3, control mode
// remote) give kInvalidArgument. Feedback enums are written as they are, and SystemStatus writes
// vehicle_status_raw when it decodes to vehicle_status (else the enum's value), so decoding then
// encoding any valid feedback frame is byte-exact up to reserved bytes. The frame has stamp 0.
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
