// A protocol profile: every interpretation of the RANGER protocol as one run-time value.
//
// The user manual (revision `manual`) and the vendor's later revision (`agx_v2`,
// shared/reference/PROTOCOL_AGX_V2.md) use the same identifiers but differ in units, signs, fields
// and lengths; the manual itself leaves several points open (PROTOCOL.md). Each such point is a
// field below, with a named setting (parse/print by name, validated) and a default per revision
// and model. A revision is a preset of these fields, never a copy of the codec: nothing outside
// profile.cpp branches on a revision's name. docs/PROTOCOL_INTERPRETATIONS.md lists every setting
// with its values, its default per revision and the evidence for it.
//
// Who applies which field:
//  * The codec (codec.hpp) applies everything about the wire: steering units and signs per frame,
//    the error-word layout, the BMS voltage scale, the driver-status enable bit, the meaning of
//    vehicle status 0x01, the motion-mode numbering and the DLC of the frames it encodes. Decoded
//    messages are always in one convention, whatever the profile: SI units and the manual's signs
//    (steering positive = right; driver status bit 6 set = disabled).
//  * Not the codec: `spin_sign` (0x111 bytes 2-5 and 0x221 bytes 0-3 carry spin only in spin
//    mode, so the codec passes spin values as they are on the wire and the kinematics, odometry
//    and virtual chassis apply the sign), `spin_field` (which field the kinematics fills),
//    `steering_reference` and `feedback_speed` (geometric readings: interpretation.hpp's
//    ackermann_front_angle / ackermann_body_speed_from_feedback_speed take them), and
//    `bms_current_sign` (interpretation::bms_discharge_current).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"

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
  kManual32,  // bytes 4-7 one big-endian 32-bit error word (manual)
  kAgxV2_16,  // bytes 4-5 a 16-bit error word, byte 6 reserved, byte 7 a counter (agx_v2)
};
// Wire values of the motion modes (0x141, 0x291).
enum class ModeNumbering {
  kManual,  // 0 Ackermann, 1 oblique, 2 spin
  kAgxV2,   // + 3 park, 4 side slip
  kMiniV1,  // + 3 side slip (no park)
};
// Meaning of bit 6 of the motor drivers' status byte (0x261-0x268 byte 5).
enum class DriverStatusBit6 {
  kDisabled,  // 1 = driver disabled (the manual)
  kEnabled,   // 1 = driver enabled (the vendor's software)
};

// The values' names, as the settings spell them.
inline constexpr auto kAngleUnitNames = text::enum_names<AngleUnit>({
    {AngleUnit::kCentidegree, "centideg"},
    {AngleUnit::kMilliradian, "millirad"},
});
inline constexpr auto kSteeringSignNames = text::enum_names<SteeringSign>({
    {SteeringSign::kRightPositive, "right_positive"},
    {SteeringSign::kLeftPositive, "left_positive"},
});
inline constexpr auto kSteeringReferenceNames = text::enum_names<SteeringReference>({
    {SteeringReference::kMeanFront, "mean_front"},
    {SteeringReference::kInnerFront, "inner_front"},
});
inline constexpr auto kSpinFieldNames = text::enum_names<SpinField>({
    {SpinField::kWheelSpeed, "wheel_speed"},
    {SpinField::kYawRate, "yaw_rate"},
});
inline constexpr auto kFeedbackSpeedNames = text::enum_names<FeedbackSpeed>({
    {FeedbackSpeed::kMeanWheel, "mean_wheel"},
    {FeedbackSpeed::kBodyCentre, "body_centre"},
});
inline constexpr auto kErrorWordLayoutNames = text::enum_names<ErrorWordLayout>({
    {ErrorWordLayout::kManual32, "manual32"},
    {ErrorWordLayout::kAgxV2_16, "agx16"},
});
inline constexpr auto kModeNumberingNames = text::enum_names<ModeNumbering>({
    {ModeNumbering::kManual, "manual"},
    {ModeNumbering::kAgxV2, "agx_v2"},
    {ModeNumbering::kMiniV1, "mini_v1"},
});
inline constexpr auto kDriverStatusBit6Names = text::enum_names<DriverStatusBit6>({
    {DriverStatusBit6::kDisabled, "disabled"},
    {DriverStatusBit6::kEnabled, "enabled"},
});

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
  // Applied above the codec (see the top of this file).
  int spin_sign = +1;
  FeedbackSpeed feedback_speed = FeedbackSpeed::kMeanWheel;
  ErrorWordLayout error_word = ErrorWordLayout::kManual32;
  bool vehicle_status_1_is_estop = true;  // 0x211 byte 0 = 0x01 (open point 4)
  double bms_voltage_scale = 0.01;        // V per unit of 0x361 bytes 2-3: 0.01 or 0.1
  // +1: a positive 0x361 current is a discharge (the pack supplies the chassis); -1: a charge.
  // -1 is what the code base has always assumed (sensor_msgs/BatteryState's convention, the
  // virtual chassis); the manual does not say. Applied by interpretation::bms_discharge_current.
  int bms_current_sign = -1;
  ModeNumbering mode_numbering = ModeNumbering::kManual;
  DriverStatusBit6 driver_status_bit6 = DriverStatusBit6::kDisabled;
  // DLC of every frame the codec encodes (commands, and the virtual chassis's feedback): 0 = each
  // frame's own layout length (protocol::layout_dlc), 8 = padded with zero bytes to 8.
  int tx_dlc = 0;

  // Every field in range; the message names the setting (e.g. "tx_dlc = 5: valid 0 or 8").
  Status validate() const;
};
// Same revision and the same value in every setting.
bool operator==(const ProtocolProfile& a, const ProtocolProfile& b);
inline bool operator!=(const ProtocolProfile& a, const ProtocolProfile& b) {
  return !(a == b);
}

// The preset of a revision: "manual" or "agx_v2". kInvalidArgument lists the valid names.
Result<ProtocolProfile> protocol_preset(std::string_view revision);
const std::vector<std::string>& protocol_revision_names();  // {"manual", "agx_v2"}
// The manual's preset, without a Result (the codec's overloads without a profile use it).
const ProtocolProfile& manual_profile();

// ---- Settings by name -------------------------------------------------------------------------
// Every field of ProtocolProfile (except `revision`) as a named setting, the one table the node's
// parameters, the CLI's --set option, commissioning files and docs/PROTOCOL_INTERPRETATIONS.md
// are checked against. Code names a setting by its enumerator; people by its name.
enum class ProtocolSetting {
  kSteeringUnit111,
  kSteeringUnit221,
  kSteeringUnit271,
  kSteeringSign111,
  kSteeringSign221,
  kSteeringSign271,
  kSteeringReference,
  kSpinField,
  kSpinSign,
  kFeedbackSpeed,
  kErrorWord,
  kVehicleStatus1IsEstop,
  kBmsVoltageScale,
  kBmsCurrentSign,
  kModeNumbering,
  kDriverStatusBit6,
  kTxDlc,
};
// The settings' names, in the table's order (that of profile_settings()).
inline constexpr auto kProtocolSettingNames = text::enum_names<ProtocolSetting>({
    {ProtocolSetting::kSteeringUnit111, "steering_unit_111"},
    {ProtocolSetting::kSteeringUnit221, "steering_unit_221"},
    {ProtocolSetting::kSteeringUnit271, "steering_unit_271"},
    {ProtocolSetting::kSteeringSign111, "steering_sign_111"},
    {ProtocolSetting::kSteeringSign221, "steering_sign_221"},
    {ProtocolSetting::kSteeringSign271, "steering_sign_271"},
    {ProtocolSetting::kSteeringReference, "steering_reference"},
    {ProtocolSetting::kSpinField, "spin_field"},
    {ProtocolSetting::kSpinSign, "spin_sign"},
    {ProtocolSetting::kFeedbackSpeed, "feedback_speed"},
    {ProtocolSetting::kErrorWord, "error_word"},
    {ProtocolSetting::kVehicleStatus1IsEstop, "vehicle_status_1_is_estop"},
    {ProtocolSetting::kBmsVoltageScale, "bms_voltage_scale"},
    {ProtocolSetting::kBmsCurrentSign, "bms_current_sign"},
    {ProtocolSetting::kModeNumbering, "mode_numbering"},
    {ProtocolSetting::kDriverStatusBit6, "driver_status_bit6"},
    {ProtocolSetting::kTxDlc, "tx_dlc"},
});
inline std::string_view to_string(ProtocolSetting s) {
  return kProtocolSettingNames.name(s);
}

struct ProfileSetting {
  std::string_view name;                 // "steering_unit_111", ...
  std::string_view description;          // one line
  std::vector<std::string_view> values;  // the valid values, as text ("centideg", "millirad")
  ProtocolSetting id;
};
const std::vector<ProfileSetting>& profile_settings();
const ProfileSetting& profile_setting(ProtocolSetting id);
// The value of setting `name` in `profile`, as text.
Result<std::string> get_setting(const ProtocolProfile& profile, std::string_view name);
Result<std::string> get_setting(const ProtocolProfile& profile, ProtocolSetting id);
// Sets `name` to `value` (text, as listed in profile_settings()). Errors (kInvalidArgument) name
// the setting and list the valid values; an unknown name lists the valid names.
Status set_setting(ProtocolProfile& profile, std::string_view name, std::string_view value);
Status set_setting(ProtocolProfile& profile, ProtocolSetting id, std::string_view value);
// The same for one "NAME=VALUE" text (the CLI's --set, commissioning files).
Status apply_setting(ProtocolProfile& profile, std::string_view assignment);
// "agx_v2", or "agx_v2 with steering_unit_271=centideg,tx_dlc=0": the revision and every
// setting that differs from its preset (for logs and diagnostics).
std::string describe(const ProtocolProfile& profile);

// Text names of the enumerations (as used by the settings).
inline std::string_view to_string(AngleUnit v) {
  return kAngleUnitNames.name(v);
}
inline std::string_view to_string(SteeringSign v) {
  return kSteeringSignNames.name(v);
}
inline std::string_view to_string(SteeringReference v) {
  return kSteeringReferenceNames.name(v);
}
inline std::string_view to_string(SpinField v) {
  return kSpinFieldNames.name(v);
}
inline std::string_view to_string(FeedbackSpeed v) {
  return kFeedbackSpeedNames.name(v);
}
inline std::string_view to_string(ErrorWordLayout v) {
  return kErrorWordLayoutNames.name(v);
}
inline std::string_view to_string(ModeNumbering v) {
  return kModeNumberingNames.name(v);
}
inline std::string_view to_string(DriverStatusBit6 v) {
  return kDriverStatusBit6Names.name(v);
}

}  // namespace ranger
