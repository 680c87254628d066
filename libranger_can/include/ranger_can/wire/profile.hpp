// A protocol profile: every interpretation of the RANGER protocol as one run-time value.
//
// The user manual (revision `manual`) and the vendor's later revision (`agx_v2`,
// shared/reference/PROTOCOL_AGX_V2.md) use the same identifiers but differ in units, signs, fields
// and lengths; the manual itself leaves several points open (PROTOCOL.md). Each such point is a
// field below, with a named setting (parse/print by name, validated) and a default per revision
// and model. A revision is a preset of these fields, never a copy of the codec: nothing outside
// profile.cpp branches on a revision's name.
//
// The codec (codec.hpp) takes a profile for everything on the wire: units, signs, which bytes
// carry what, frame lengths, the error-word layout, the BMS scale and the motion-mode numbering.
// Decoded messages are always in one convention, whatever the profile: SI units and the manual's
// signs (steering positive = right, spin counter-clockwise positive), so the layers above never
// look at the profile for units or signs. The geometric readings (which angle 0x111 steers in
// Ackermann mode, which speed 0x111/0x221 carry) are profile fields too, applied by the control
// layer's kinematics and odometry and by the virtual chassis.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/result.hpp"

namespace ranger {

// Unit of a steering-angle field (0x111 bytes 6-7, 0x221 bytes 6-7, 0x271).
enum class AngleUnit {
  kCentidegree,  // 0.01 deg: the manual, and the vendor's software before firmware v5.7 (2023)
  kMilliradian,  // 0.001 rad: the vendor's software since firmware v5.7
};
// Which direction a positive steering value on the wire turns.
enum class SteeringSign {
  kRightPositive,  // the manual's 0x221 ("negative = left, positive = right")
  kLeftPositive,   // the vendor's drivers (REP-103 like)
};
// Which angle 0x111 steers and 0x221 reports in Ackermann mode (PROTOCOL.md open point 6).
enum class SteeringReference {
  kMeanFront,   // (alpha + beta) / 2 of the two front wheels: the manual's prose
  kInnerFront,  // the inner front wheel: the manual's 0x221 table, the vendor's drivers
};
// Where the spin speed goes in 0x111 (and comes back in 0x221).
enum class SpinField {
  kWheelSpeed,  // 0x111 bytes 4-5 / 0x221 bytes 0-1: wheel tangential speed, mm/s (manual)
  kYawRate,     // 0x111 bytes 2-3 / 0x221 bytes 2-3: body yaw rate, 0.001 rad/s (agx_v2)
};
// What 0x221's speed is in Ackermann mode (open point 7; 0x111's speed is the body centre's).
enum class FeedbackSpeed {
  kMeanWheel,   // the mean of the four wheel speeds ("the average value of the four wheels")
  kBodyCentre,  // the speed of the body centre ("that is, the linear speed of the chassis")
};
// Layout of 0x211 bytes 4-7.
enum class ErrorWordLayout {
  kManual32,    // bytes 4-7 one big-endian 32-bit error word (manual)
  kAgxV2_16,    // bytes 4-5 a 16-bit error word, byte 6 reserved, byte 7 a counter (agx_v2)
};
// Wire values of the motion modes (0x141, 0x291).
enum class ModeNumbering {
  kManual,  // 0 Ackermann, 1 oblique, 2 spin
  kAgxV2,   // + 3 park, 4 side slip
  kMiniV1,  // + 3 side slip (no park)
};

struct ProtocolProfile {
  // The preset this profile started from ("manual", "agx_v2"), for logs; changing a field below
  // does not change it.
  std::string revision = "manual";

  AngleUnit steering_unit_111 = AngleUnit::kCentidegree;
  AngleUnit steering_unit_221 = AngleUnit::kCentidegree;
  AngleUnit steering_unit_271 = AngleUnit::kCentidegree;
  SteeringSign steering_sign_111 = SteeringSign::kRightPositive;
  SteeringSign steering_sign_221 = SteeringSign::kRightPositive;
  SteeringSign steering_sign_271 = SteeringSign::kRightPositive;
  SteeringReference steering_reference = SteeringReference::kMeanFront;
  SpinField spin_field = SpinField::kWheelSpeed;
  // +1: a positive spin value on the wire turns counter-clockwise (the manual); -1: clockwise.
  int spin_sign = +1;
  FeedbackSpeed feedback_speed = FeedbackSpeed::kMeanWheel;
  ErrorWordLayout error_word = ErrorWordLayout::kManual32;
  bool vehicle_status_1_is_estop = true;  // 0x211 byte 0 = 0x01 (open point 4)
  double bms_voltage_scale = 0.01;        // V per unit of 0x361 bytes 2-3: 0.01 or 0.1
  // +1: a positive 0x361 current is a discharge (the pack supplies the chassis); -1: a charge.
  int bms_current_sign = +1;
  ModeNumbering mode_numbering = ModeNumbering::kManual;
  // DLC of every frame the host sends: 0 = each frame's own layout length, 8 = padded to 8.
  int tx_dlc = 0;

  // Every field in range; the message names the setting (e.g. "tx_dlc = 5: valid 0 or 8").
  Status validate() const;
};

// The preset of a revision: "manual" or "agx_v2". kInvalidArgument lists the valid names.
Result<ProtocolProfile> protocol_preset(std::string_view revision);
const std::vector<std::string>& protocol_revision_names();  // {"manual", "agx_v2"}

// ---- Settings by name -------------------------------------------------------------------------
// Every field of ProtocolProfile (except `revision`) as a named setting, the one table the node's
// parameters, the CLI's --set option, commissioning files and docs/PROTOCOL_INTERPRETATIONS.md
// are checked against.
struct ProfileSetting {
  std::string_view name;         // "steering_unit_111", ...
  std::string_view description;  // one line
  std::vector<std::string_view> values;  // the valid values, as text ("centideg", "millirad")
};
const std::vector<ProfileSetting>& profile_settings();
// The value of setting `name` in `profile`, as text.
Result<std::string> get_setting(const ProtocolProfile& profile, std::string_view name);
// Sets `name` to `value` (text, as listed in profile_settings()). Errors name the setting and list
// the valid values.
Status set_setting(ProtocolProfile& profile, std::string_view name, std::string_view value);

// Text names of the enumerations (as used by the settings).
std::string_view to_string(AngleUnit v);
std::string_view to_string(SteeringSign v);
std::string_view to_string(SteeringReference v);
std::string_view to_string(SpinField v);
std::string_view to_string(FeedbackSpeed v);
std::string_view to_string(ErrorWordLayout v);
std::string_view to_string(ModeNumbering v);

}  // namespace ranger
