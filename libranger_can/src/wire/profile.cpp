// The protocol profile: presets, the settings table and validation.
//
// Every setting is one row of kRows below: its name, a line of description, its valid values as
// text (the index of a value is what the row's get/set functions exchange) and two functions
// reading and writing the field. The enumerations' names are the same texts, so a value is
// spelled in one place only. This file is the only one that knows a revision by its name.
#include "ranger_can/wire/profile.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

namespace ranger {

namespace {

// ---- Names of the values (index = the enumerator's value) --------------------------------------
constexpr std::array<std::string_view, 2> kAngleUnitNames = {"centideg", "millirad"};
constexpr std::array<std::string_view, 2> kSteeringSignNames = {"right_positive", "left_positive"};
constexpr std::array<std::string_view, 2> kSteeringReferenceNames = {"mean_front", "inner_front"};
constexpr std::array<std::string_view, 2> kSpinFieldNames = {"wheel_speed", "yaw_rate"};
constexpr std::array<std::string_view, 2> kFeedbackSpeedNames = {"mean_wheel", "body_centre"};
constexpr std::array<std::string_view, 2> kErrorWordNames = {"manual32", "agx16"};
constexpr std::array<std::string_view, 3> kModeNumberingNames = {"manual", "agx_v2", "mini_v1"};
constexpr std::array<std::string_view, 2> kDriverStatusBit6Names = {"disabled", "enabled"};
// Settings that are numbers or flags: their texts, index 0 first.
constexpr std::array<std::string_view, 2> kSpinSignNames = {"ccw", "cw"};  // +1, -1
constexpr std::array<std::string_view, 2> kBoolNames = {"true", "false"};
constexpr std::array<std::string_view, 2> kBmsScaleNames = {"0.01", "0.1"};
constexpr std::array<std::string_view, 2> kCurrentSignNames = {"discharge_positive",
                                                               "charge_positive"};  // +1, -1
constexpr std::array<std::string_view, 2> kTxDlcNames = {"0", "8"};

template <std::size_t N>
std::string_view name_at(const std::array<std::string_view, N>& names, int index) {
  return index >= 0 && static_cast<std::size_t>(index) < N ? names[static_cast<std::size_t>(index)]
                                                           : std::string_view("unknown");
}

template <std::size_t N>
std::vector<std::string_view> list(const std::array<std::string_view, N>& names) {
  return {names.begin(), names.end()};
}

// The index of each numeric or boolean field's value; -1 when the field holds no valid value.
int sign_index(int sign) {
  return sign == +1 ? 0 : sign == -1 ? 1 : -1;
}
int scale_index(double scale) {
  return scale == 0.01 ? 0 : scale == 0.1 ? 1 : -1;
}
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
int tx_dlc_index(int dlc) {
  return dlc == 0 ? 0 : dlc == 8 ? 1 : -1;
}

struct Row {
  ProfileSetting setting;
  int (*get)(const ProtocolProfile&);  // index into setting.values; -1 = invalid value
  void (*set)(ProtocolProfile&, int);  // index into setting.values
  // The field's value as text when get() says it is invalid (for validate()'s message).
  std::string (*raw)(const ProtocolProfile&);
};

template <typename E>
int enum_index(E e) {
  return static_cast<int>(e);
}

#define RANGER_ENUM_ROW(field, Enum, names, description)                             \
  Row {                                                                              \
    {#field, description, list(names)},                                              \
        [](const ProtocolProfile& p) {                                               \
          const int i = enum_index(p.field);                                         \
          return i >= 0 && i < static_cast<int>(names.size()) ? i : -1;              \
        },                                                                           \
        [](ProtocolProfile& p, int i) { p.field = static_cast<Enum>(i); },           \
        [](const ProtocolProfile& p) { return std::to_string(enum_index(p.field)); } \
  }

const std::vector<Row>& rows() {
  static const std::vector<Row> kRows = {
      RANGER_ENUM_ROW(steering_unit_111, AngleUnit, kAngleUnitNames,
                      "unit of the 0x111 steering angle: 0.01 deg or 0.001 rad"),
      RANGER_ENUM_ROW(steering_unit_221, AngleUnit, kAngleUnitNames,
                      "unit of the 0x221 steering angle: 0.01 deg or 0.001 rad"),
      RANGER_ENUM_ROW(steering_unit_271, AngleUnit, kAngleUnitNames,
                      "unit of the four 0x271 wheel angles: 0.01 deg or 0.001 rad"),
      RANGER_ENUM_ROW(steering_sign_111, SteeringSign, kSteeringSignNames,
                      "which turn a positive 0x111 steering angle commands"),
      RANGER_ENUM_ROW(steering_sign_221, SteeringSign, kSteeringSignNames,
                      "which turn a positive 0x221 steering angle reports"),
      RANGER_ENUM_ROW(steering_sign_271, SteeringSign, kSteeringSignNames,
                      "which way a positive 0x271 wheel angle points"),
      RANGER_ENUM_ROW(steering_reference, SteeringReference, kSteeringReferenceNames,
                      "the angle 0x111 steers and 0x221 reports in Ackermann mode: the front "
                      "wheels' mean or the inner front wheel's"),
      RANGER_ENUM_ROW(spin_field, SpinField, kSpinFieldNames,
                      "where the spin speed goes: a wheel speed in 0x111 bytes 4-5 (0x221 bytes "
                      "0-1) or a yaw rate in bytes 2-3"),
      Row{{"spin_sign", "the turn a positive spin value on the wire makes", list(kSpinSignNames)},
          [](const ProtocolProfile& p) { return sign_index(p.spin_sign); },
          [](ProtocolProfile& p, int i) { p.spin_sign = i == 0 ? +1 : -1; },
          [](const ProtocolProfile& p) { return std::to_string(p.spin_sign); }},
      RANGER_ENUM_ROW(feedback_speed, FeedbackSpeed, kFeedbackSpeedNames,
                      "what the 0x221 speed is in Ackermann mode: the mean of the four wheel "
                      "speeds or the body centre's speed"),
      RANGER_ENUM_ROW(error_word, ErrorWordLayout, kErrorWordNames,
                      "layout of 0x211 bytes 4-7: one 32-bit error word, or a 16-bit word in "
                      "bytes 4-5 and a counter in byte 7"),
      Row{{"vehicle_status_1_is_estop",
           "whether 0x211 byte 0 = 0x01 is an emergency stop (else: abnormal)", list(kBoolNames)},
          [](const ProtocolProfile& p) { return p.vehicle_status_1_is_estop ? 0 : 1; },
          [](ProtocolProfile& p, int i) { p.vehicle_status_1_is_estop = i == 0; },
          [](const ProtocolProfile& p) {
            return std::string(p.vehicle_status_1_is_estop ? "true" : "false");
          }},
      Row{{"bms_voltage_scale", "volts per unit of the 0x361 voltage", list(kBmsScaleNames)},
          [](const ProtocolProfile& p) { return scale_index(p.bms_voltage_scale); },
          [](ProtocolProfile& p, int i) { p.bms_voltage_scale = i == 0 ? 0.01 : 0.1; },
          [](const ProtocolProfile& p) { return number_text(p.bms_voltage_scale); }},
      Row{{"bms_current_sign", "what a positive 0x361 current is: a discharge or a charge",
           list(kCurrentSignNames)},
          [](const ProtocolProfile& p) { return sign_index(p.bms_current_sign); },
          [](ProtocolProfile& p, int i) { p.bms_current_sign = i == 0 ? +1 : -1; },
          [](const ProtocolProfile& p) { return std::to_string(p.bms_current_sign); }},
      RANGER_ENUM_ROW(mode_numbering, ModeNumbering, kModeNumberingNames,
                      "wire values of the motion modes in 0x141 and 0x291"),
      RANGER_ENUM_ROW(driver_status_bit6, DriverStatusBit6, kDriverStatusBit6Names,
                      "what bit 6 of the 0x261-0x268 driver status set means"),
      Row{{"tx_dlc", "DLC of encoded frames: 0 = each frame's layout length, 8 = zero-padded to 8",
           list(kTxDlcNames)},
          [](const ProtocolProfile& p) { return tx_dlc_index(p.tx_dlc); },
          [](ProtocolProfile& p, int i) { p.tx_dlc = i == 0 ? 0 : 8; },
          [](const ProtocolProfile& p) { return std::to_string(p.tx_dlc); }},
  };
  return kRows;
}

#undef RANGER_ENUM_ROW

const Row* find_row(std::string_view name) {
  for (const Row& r : rows()) {
    if (r.setting.name == name) return &r;
  }
  return nullptr;
}

// "a, b or c"
std::string alternatives(const std::vector<std::string_view>& values, std::string_view last_sep) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += i + 1 == values.size() ? last_sep : std::string_view(", ");
    out += values[i];
  }
  return out;
}

std::string all_setting_names() {
  std::vector<std::string_view> names;
  for (const Row& r : rows())
    names.push_back(r.setting.name);
  return alternatives(names, ", ");
}

ProtocolProfile make_agx_v2() {
  ProtocolProfile p;
  p.revision = "agx_v2";
  p.steering_unit_111 = p.steering_unit_221 = p.steering_unit_271 = AngleUnit::kMilliradian;
  p.steering_sign_111 = p.steering_sign_221 = p.steering_sign_271 = SteeringSign::kLeftPositive;
  p.steering_reference = SteeringReference::kInnerFront;
  p.spin_field = SpinField::kYawRate;
  p.spin_sign = +1;  // yaw rate, counter-clockwise positive
  // The vendor's ROS 1 driver integrates 0x221's speed as the body centre's
  // (docs/PROTOCOL_INTERPRETATIONS.md, point 8).
  p.feedback_speed = FeedbackSpeed::kBodyCentre;
  p.error_word = ErrorWordLayout::kAgxV2_16;
  p.vehicle_status_1_is_estop = true;  // "0 normal, 1 e-stop, 2 exception"
  p.bms_voltage_scale = 0.1;
  p.bms_current_sign = -1;  // assumed: unknown, as for the manual
  p.mode_numbering = ModeNumbering::kAgxV2;
  p.driver_status_bit6 = DriverStatusBit6::kEnabled;
  p.tx_dlc = 8;  // the vendor's SDK pads every command
  return p;
}

}  // namespace

Status ProtocolProfile::validate() const {
  for (const Row& r : rows()) {
    if (r.get(*this) < 0) {
      return Error{Errc::kInvalidArgument, std::string(r.setting.name) + " = " + r.raw(*this) +
                                               ": valid " + alternatives(r.setting.values, " or ")};
    }
  }
  return ok_status();
}

bool operator==(const ProtocolProfile& a, const ProtocolProfile& b) {
  if (a.revision != b.revision) return false;
  for (const Row& r : rows()) {
    if (r.get(a) != r.get(b) || r.raw(a) != r.raw(b)) return false;
  }
  return true;
}

const ProtocolProfile& manual_profile() {
  static const ProtocolProfile kManual;
  return kManual;
}

const std::vector<std::string>& protocol_revision_names() {
  static const std::vector<std::string> kNames = {"manual", "agx_v2"};
  return kNames;
}

Result<ProtocolProfile> protocol_preset(std::string_view revision) {
  if (revision == "manual") return manual_profile();
  if (revision == "agx_v2") return make_agx_v2();
  std::vector<std::string_view> names(protocol_revision_names().begin(),
                                      protocol_revision_names().end());
  return Error{Errc::kInvalidArgument, "unknown protocol revision '" + std::string(revision) +
                                           "' (valid: " + alternatives(names, ", ") + ")"};
}

const std::vector<ProfileSetting>& profile_settings() {
  static const std::vector<ProfileSetting> kSettings = [] {
    std::vector<ProfileSetting> out;
    for (const Row& r : rows())
      out.push_back(r.setting);
    return out;
  }();
  return kSettings;
}

Result<std::string> get_setting(const ProtocolProfile& profile, std::string_view name) {
  const Row* r = find_row(name);
  if (r == nullptr) {
    return Error{Errc::kInvalidArgument, "unknown protocol setting '" + std::string(name) +
                                             "' (valid: " + all_setting_names() + ")"};
  }
  const int i = r->get(profile);
  if (i < 0) {
    return Error{Errc::kInvalidArgument,
                 std::string(name) + " holds the invalid value " + r->raw(profile)};
  }
  return std::string(r->setting.values[static_cast<std::size_t>(i)]);
}

Status set_setting(ProtocolProfile& profile, std::string_view name, std::string_view value) {
  const Row* r = find_row(name);
  if (r == nullptr) {
    return Error{Errc::kInvalidArgument, "unknown protocol setting '" + std::string(name) +
                                             "' (valid: " + all_setting_names() + ")"};
  }
  const auto& values = r->setting.values;
  const auto it = std::find(values.begin(), values.end(), value);
  if (it == values.end()) {
    std::string valid;
    for (std::size_t i = 0; i < values.size(); ++i)
      valid += (i ? "|" : "") + std::string(values[i]);
    return Error{Errc::kInvalidArgument, "protocol setting " + std::string(name) + " = '" +
                                             std::string(value) + "' is invalid (valid: " + valid +
                                             ")"};
  }
  r->set(profile, static_cast<int>(it - values.begin()));
  return ok_status();
}

Status apply_setting(ProtocolProfile& profile, std::string_view assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    return Error{Errc::kInvalidArgument,
                 "'" + std::string(assignment) +
                     "' is not NAME=VALUE (settings: " + all_setting_names() + ")"};
  }
  return set_setting(profile, assignment.substr(0, eq), assignment.substr(eq + 1));
}

std::string describe(const ProtocolProfile& profile) {
  const Result<ProtocolProfile> preset = protocol_preset(profile.revision);
  const ProtocolProfile& base = preset ? *preset : manual_profile();
  std::string out = profile.revision;
  std::string changed;
  for (const Row& r : rows()) {
    if (r.get(profile) == r.get(base) && r.raw(profile) == r.raw(base)) continue;
    const int i = r.get(profile);
    changed += changed.empty() ? "" : ",";
    changed += std::string(r.setting.name) + "=" +
               (i >= 0 ? std::string(r.setting.values[static_cast<std::size_t>(i)])
                       : "invalid(" + r.raw(profile) + ")");
  }
  return changed.empty() ? out : out + " with " + changed;
}

std::string_view to_string(AngleUnit v) {
  return name_at(kAngleUnitNames, static_cast<int>(v));
}
std::string_view to_string(SteeringSign v) {
  return name_at(kSteeringSignNames, static_cast<int>(v));
}
std::string_view to_string(SteeringReference v) {
  return name_at(kSteeringReferenceNames, static_cast<int>(v));
}
std::string_view to_string(SpinField v) {
  return name_at(kSpinFieldNames, static_cast<int>(v));
}
std::string_view to_string(FeedbackSpeed v) {
  return name_at(kFeedbackSpeedNames, static_cast<int>(v));
}
std::string_view to_string(ErrorWordLayout v) {
  return name_at(kErrorWordNames, static_cast<int>(v));
}
std::string_view to_string(ModeNumbering v) {
  return name_at(kModeNumberingNames, static_cast<int>(v));
}
std::string_view to_string(DriverStatusBit6 v) {
  return name_at(kDriverStatusBit6Names, static_cast<int>(v));
}

}  // namespace ranger
