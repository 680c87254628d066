// The protocol profile: presets, the settings table and validation.
//
// Every setting is one row of kRows below, in kProtocolSettingNames's order: its description, its
// valid values, each with its text (an enum's from its name table, so a value is spelled in one
// place only) and the field it reads and writes. This file is the only one that knows a revision
// by its name.
#include "ranger_can/wire/profile.hpp"

#include <algorithm>
#include <functional>
#include <string>
#include <type_traits>

namespace ranger {

namespace {

// A setting's valid values, each with its text (the enums' from their name tables).
template <typename T>
using Choices = std::vector<text::EnumName<T>>;

template <typename Enum, std::size_t N>
Choices<Enum> choices(const text::EnumNames<Enum, N>& names) {
  return Choices<Enum>(names.begin(), names.end());
}

// A field's value as text when it holds none of the valid values (validate()'s message).
std::string raw_text(bool v) {
  return v ? "true" : "false";
}
std::string raw_text(double v) {
  return text::number_text(v);
}
std::string raw_text(int v) {
  return std::to_string(v);
}
template <typename Enum, typename = std::enable_if_t<std::is_enum_v<Enum>>>
std::string raw_text(Enum v) {
  return std::to_string(static_cast<int>(v));
}

// One setting: its description, its valid values as text (the index of a value is what get and
// set exchange) and the functions reading and writing the field.
struct Row {
  ProfileSetting setting;
  std::function<int(const ProtocolProfile&)> get;  // index into setting.values; -1 = invalid
  std::function<void(ProtocolProfile&, int)> set;  // index into setting.values
  std::function<std::string(const ProtocolProfile&)> raw;
};

template <typename T>
Row row(ProtocolSetting id, T ProtocolProfile::*field, Choices<T> valid,
        std::string_view description) {
  Row r;
  r.setting = {to_string(id), description, {}, id};
  for (const auto& c : valid)
    r.setting.values.push_back(c.name);
  r.get = [field, valid](const ProtocolProfile& p) {
    for (std::size_t i = 0; i < valid.size(); ++i) {
      if (valid[i].value == p.*field) return static_cast<int>(i);
    }
    return -1;
  };
  r.set = [field, valid](ProtocolProfile& p, int i) {
    p.*field = valid[static_cast<std::size_t>(i)].value;
  };
  r.raw = [field](const ProtocolProfile& p) { return raw_text(p.*field); };
  return r;
}

// In kProtocolSettingNames's order.
const std::vector<Row>& rows() {
  using S = ProtocolSetting;
  using P = ProtocolProfile;
  static const std::vector<Row> kRows = {
      row(S::kSteeringUnit111, &P::steering_unit_111, choices(kAngleUnitNames),
          "unit of the 0x111 steering angle: 0.01 deg or 0.001 rad"),
      row(S::kSteeringUnit221, &P::steering_unit_221, choices(kAngleUnitNames),
          "unit of the 0x221 steering angle: 0.01 deg or 0.001 rad"),
      row(S::kSteeringUnit271, &P::steering_unit_271, choices(kAngleUnitNames),
          "unit of the four 0x271 wheel angles: 0.01 deg or 0.001 rad"),
      row(S::kSteeringSign111, &P::steering_sign_111, choices(kSteeringSignNames),
          "which turn a positive 0x111 steering angle commands"),
      row(S::kSteeringSign221, &P::steering_sign_221, choices(kSteeringSignNames),
          "which turn a positive 0x221 steering angle reports"),
      row(S::kSteeringSign271, &P::steering_sign_271, choices(kSteeringSignNames),
          "which way a positive 0x271 wheel angle points"),
      row(S::kSteeringReference, &P::steering_reference, choices(kSteeringReferenceNames),
          "the angle 0x111 steers and 0x221 reports in Ackermann mode: the front wheels' mean or "
          "the inner front wheel's"),
      row(S::kSpinField, &P::spin_field, choices(kSpinFieldNames),
          "where the spin speed goes: a wheel speed in 0x111 bytes 4-5 (0x221 bytes 0-1) or a "
          "yaw rate in bytes 2-3"),
      row(S::kSpinSign, &P::spin_sign, Choices<int>{{+1, "ccw"}, {-1, "cw"}},
          "the turn a positive spin value on the wire makes"),
      row(S::kFeedbackSpeed, &P::feedback_speed, choices(kFeedbackSpeedNames),
          "what the 0x221 speed is in Ackermann mode: the mean of the four wheel speeds or the "
          "body centre's speed"),
      row(S::kErrorWord, &P::error_word, choices(kErrorWordLayoutNames),
          "layout of 0x211 bytes 4-7: the manual's 32-bit error word, a 16-bit word in bytes 4-5 "
          "and a counter in byte 7, or the MINI 3.0's 32-bit fault word"),
      row(S::kVehicleStatus1IsEstop, &P::vehicle_status_1_is_estop,
          Choices<bool>{{true, "true"}, {false, "false"}},
          "whether 0x211 byte 0 = 0x01 is an emergency stop (else: abnormal)"),
      row(S::kBmsVoltageScale, &P::bms_voltage_scale, Choices<double>{{0.01, "0.01"}, {0.1, "0.1"}},
          "volts per unit of the 0x361 voltage"),
      row(S::kBmsCurrentSign, &P::bms_current_sign,
          Choices<int>{{+1, "discharge_positive"}, {-1, "charge_positive"}},
          "what a positive 0x361 current is: a discharge or a charge"),
      row(S::kModeNumbering, &P::mode_numbering, choices(kModeNumberingNames),
          "wire values of the motion modes in 0x141 and 0x291"),
      row(S::kDriverStatusBit6, &P::driver_status_bit6, choices(kDriverStatusBit6Names),
          "what bit 6 of the 0x261-0x268 driver status set means"),
      row(S::kFrameLayout, &P::frame_layout, choices(kFrameLayoutNames),
          "which frames the chassis has and each one's length (the frame table's column): 0x291 "
          "of 3 bytes with the drive mode and 0x423 in mini_v3"),
      row(S::kOdometerUnit, &P::odometer_unit, choices(kOdometerUnitNames),
          "unit of the 0x311/0x312 wheel odometers: not stated (raw counts) or millimetres"),
      row(S::kLightModes, &P::light_modes, choices(kLightModesNames),
          "what 0x121 can ask: front and rear light off/on/breathing/custom, or on/off only"),
      row(S::kTxDlc, &P::tx_dlc, Choices<int>{{0, "0"}, {8, "8"}},
          "DLC of encoded frames: 0 = each frame's layout length, 8 = zero-padded to 8"),
  };
  return kRows;
}

const Row& row_of(ProtocolSetting id) {
  return rows()[static_cast<std::size_t>(id)];
}

const Row* find_row(std::string_view name) {
  const auto id = kProtocolSettingNames.parse(name);
  return id ? &row_of(*id) : nullptr;
}

std::string all_setting_names() {
  return text::join(kProtocolSettingNames.names());
}

Error unknown_setting(std::string_view name) {
  return Error{Errc::kInvalidArgument, "unknown protocol setting '" + std::string(name) +
                                           "' (valid: " + all_setting_names() + ")"};
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
  p.frame_layout = FrameLayout::kAgxV2;
  p.tx_dlc = 8;  // the vendor's SDK pads every command
  return p;
}

// The RANGER MINI 3.0's manual as transcribed (PROTOCOL_MINI_V3.md): the vendor's units, signs
// and spin field (which its manual states alike), its own fault word, mode numbering, frames and
// lengths; the BMS scale and the e-stop's body status as a real one reports them.
ProtocolProfile make_mini_v3() {
  ProtocolProfile p = make_agx_v2();
  p.revision = "mini_v3";
  p.error_word = ErrorWordLayout::kMini32;      // bytes 4-7 a 32-bit fault word, no counter
  p.mode_numbering = ModeNumbering::kMiniV3;    // 0-2, 3 park, no side slip
  p.frame_layout = FrameLayout::kMiniV3;        // 0x291 of 3 bytes, 0x312, 0x423
  p.odometer_unit = OdometerUnit::kMillimetre;  // 0x311 / 0x312: left, right in mm
  p.light_modes = LightModes::kOnOff;           // on/off only
  p.tx_dlc = 0;  // its manual gives each command's length (0x141, 0x421, 0x423, 0x441: 1)
  // Where a real MINI 3.0 contradicts our transcription of its manual, the field's reading
  // (docs/FIELD_FACTS.md; the manual's stays a setting away: --set NAME=VALUE, sim:mini_v3_manual):
  p.vehicle_status_1_is_estop = false;  // an e-stop is body status 2 + fault bit 7; 1 never seen
  p.bms_voltage_scale = 0.01;           // 0x361's voltage in 0.01 V (53.0 V = 0x14B4)
  return p;
}

}  // namespace

Status ProtocolProfile::validate() const {
  for (const Row& r : rows()) {
    if (r.get(*this) < 0) {
      return Error{Errc::kInvalidArgument, std::string(r.setting.name) + " = " + r.raw(*this) +
                                               ": valid " + text::alternatives(r.setting.values)};
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
  static const std::vector<std::string> kNames = {"manual", "agx_v2", "mini_v3"};
  return kNames;
}

Result<ProtocolProfile> protocol_preset(std::string_view revision) {
  if (revision == "manual") return manual_profile();
  if (revision == "agx_v2") return make_agx_v2();
  if (revision == "mini_v3") return make_mini_v3();
  return Error{Errc::kInvalidArgument, "unknown protocol revision '" + std::string(revision) +
                                           "' (valid: " + text::join(protocol_revision_names()) +
                                           ")"};
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

const ProfileSetting& profile_setting(ProtocolSetting id) {
  return profile_settings()[static_cast<std::size_t>(id)];
}

Result<std::string> get_setting(const ProtocolProfile& profile, ProtocolSetting id) {
  const Row& r = row_of(id);
  const int i = r.get(profile);
  if (i < 0) {
    return Error{Errc::kInvalidArgument,
                 std::string(r.setting.name) + " holds the invalid value " + r.raw(profile)};
  }
  return std::string(r.setting.values[static_cast<std::size_t>(i)]);
}

Result<std::string> get_setting(const ProtocolProfile& profile, std::string_view name) {
  const Row* r = find_row(name);
  if (r == nullptr) return unknown_setting(name);
  return get_setting(profile, r->setting.id);
}

Status set_setting(ProtocolProfile& profile, ProtocolSetting id, std::string_view value) {
  const Row& r = row_of(id);
  const auto& values = r.setting.values;
  const auto it = std::find(values.begin(), values.end(), value);
  if (it == values.end()) {
    return Error{Errc::kInvalidArgument,
                 "protocol setting " + std::string(r.setting.name) + " = '" + std::string(value) +
                     "' is invalid (valid: " + text::join(values, "|") + ")"};
  }
  r.set(profile, static_cast<int>(it - values.begin()));
  return ok_status();
}

Status set_setting(ProtocolProfile& profile, std::string_view name, std::string_view value) {
  const Row* r = find_row(name);
  if (r == nullptr) return unknown_setting(name);
  return set_setting(profile, r->setting.id, value);
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

}  // namespace ranger
