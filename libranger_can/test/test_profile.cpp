// The protocol profile: the three presets field by field, every setting by name (its valid
// values, its default per revision, a rejected value with the message), validation and
// descriptions.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ranger_can/control/model.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {
namespace {

ProtocolProfile preset(const char* name) {
  const auto p = protocol_preset(name);
  EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().message);
  return p.ok() ? *p : ProtocolProfile{};
}

// ---- Presets ------------------------------------------------------------------------------------

TEST(ProfilePresets, ManualIsTodaysBehaviour) {
  const ProtocolProfile m = preset("manual");
  EXPECT_EQ(m, ProtocolProfile{});
  EXPECT_EQ(m, manual_profile());
  EXPECT_EQ(m.revision, "manual");
  EXPECT_EQ(m.steering_unit_111, AngleUnit::kCentidegree);
  EXPECT_EQ(m.steering_unit_221, AngleUnit::kCentidegree);
  EXPECT_EQ(m.steering_unit_271, AngleUnit::kCentidegree);
  EXPECT_EQ(m.steering_sign_111, SteeringSign::kRightPositive);
  EXPECT_EQ(m.steering_sign_221, SteeringSign::kRightPositive);
  EXPECT_EQ(m.steering_sign_271, SteeringSign::kRightPositive);
  EXPECT_EQ(m.steering_reference, SteeringReference::kMeanFront);
  EXPECT_EQ(m.spin_field, SpinField::kWheelSpeed);
  EXPECT_EQ(m.spin_sign, +1);
  EXPECT_EQ(m.feedback_speed, FeedbackSpeed::kMeanWheel);
  EXPECT_EQ(m.error_word, ErrorWordLayout::kManual32);
  EXPECT_TRUE(m.vehicle_status_1_is_estop);
  EXPECT_EQ(m.bms_voltage_scale, 0.01);
  EXPECT_EQ(m.bms_current_sign, -1);  // charge positive, as the node and the simulator read it
  EXPECT_EQ(m.mode_numbering, ModeNumbering::kManual);
  EXPECT_EQ(m.driver_status_bit6, DriverStatusBit6::kDisabled);
  EXPECT_EQ(m.tx_dlc, 0);
  EXPECT_TRUE(m.validate().ok());
}

TEST(ProfilePresets, AgxV2FollowsTheVendorsSoftware) {
  const ProtocolProfile v = preset("agx_v2");
  EXPECT_EQ(v.revision, "agx_v2");
  EXPECT_EQ(v.steering_unit_111, AngleUnit::kMilliradian);
  EXPECT_EQ(v.steering_unit_221, AngleUnit::kMilliradian);
  EXPECT_EQ(v.steering_unit_271, AngleUnit::kMilliradian);
  EXPECT_EQ(v.steering_sign_111, SteeringSign::kLeftPositive);
  EXPECT_EQ(v.steering_sign_221, SteeringSign::kLeftPositive);
  EXPECT_EQ(v.steering_sign_271, SteeringSign::kLeftPositive);
  EXPECT_EQ(v.steering_reference, SteeringReference::kInnerFront);
  EXPECT_EQ(v.spin_field, SpinField::kYawRate);
  EXPECT_EQ(v.spin_sign, +1);
  EXPECT_EQ(v.feedback_speed, FeedbackSpeed::kBodyCentre);  // its ROS 1 driver's odometry
  EXPECT_EQ(v.error_word, ErrorWordLayout::kAgxV2_16);
  EXPECT_TRUE(v.vehicle_status_1_is_estop);
  EXPECT_EQ(v.bms_voltage_scale, 0.1);
  EXPECT_EQ(v.bms_current_sign, -1);
  EXPECT_EQ(v.mode_numbering, ModeNumbering::kAgxV2);
  EXPECT_EQ(v.driver_status_bit6, DriverStatusBit6::kEnabled);
  EXPECT_EQ(v.tx_dlc, 8);
  EXPECT_TRUE(v.validate().ok());
  EXPECT_NE(v, preset("manual"));
}

TEST(ProfilePresets, MiniV3FollowsTheMini30Manual) {
  const ProtocolProfile m = preset("mini_v3");
  EXPECT_EQ(m.revision, "mini_v3");
  // As agx_v2: 0x111 i16 x 0.001 (m/s, spin rad/s in bytes 2-3, inner angle rad, left positive).
  EXPECT_EQ(m.steering_unit_111, AngleUnit::kMilliradian);
  EXPECT_EQ(m.steering_unit_221, AngleUnit::kMilliradian);
  EXPECT_EQ(m.steering_unit_271, AngleUnit::kMilliradian);
  EXPECT_EQ(m.steering_sign_111, SteeringSign::kLeftPositive);
  EXPECT_EQ(m.steering_sign_221, SteeringSign::kLeftPositive);
  EXPECT_EQ(m.steering_sign_271, SteeringSign::kLeftPositive);
  EXPECT_EQ(m.steering_reference, SteeringReference::kInnerFront);
  EXPECT_EQ(m.spin_field, SpinField::kYawRate);
  EXPECT_EQ(m.spin_sign, +1);
  // The field's readings where a real one contradicts the transcribed manual (FIELD_FACTS.md).
  EXPECT_EQ(m.bms_voltage_scale, 0.01);
  EXPECT_FALSE(m.vehicle_status_1_is_estop);
  // Its own: the 32-bit fault word without a counter, park as 3 and no side slip, 0x291 of 3
  // bytes with 0x312 and 0x423, odometers in mm, lights on/off, each command's own length.
  EXPECT_EQ(m.error_word, ErrorWordLayout::kMini32);
  EXPECT_EQ(m.mode_numbering, ModeNumbering::kMiniV3);
  EXPECT_EQ(m.frame_layout, FrameLayout::kMiniV3);
  EXPECT_EQ(m.odometer_unit, OdometerUnit::kMillimetre);
  EXPECT_EQ(m.light_modes, LightModes::kOnOff);
  EXPECT_EQ(m.tx_dlc, 0);
  EXPECT_TRUE(m.validate().ok());
  EXPECT_NE(m, preset("agx_v2"));
  EXPECT_EQ(describe(m), "mini_v3");
}

TEST(ProfilePresets, RevisionNamesAndUnknownRevision) {
  EXPECT_EQ(protocol_revision_names(), (std::vector<std::string>{"manual", "agx_v2", "mini_v3"}));
  for (const auto& name : protocol_revision_names())
    EXPECT_EQ(preset(name.c_str()).revision, name);
  const auto bad = protocol_preset("agx_v3");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, Errc::kInvalidArgument);
  EXPECT_EQ(bad.error().message,
            "unknown protocol revision 'agx_v3' (valid: manual, agx_v2, mini_v3)");
  EXPECT_FALSE(protocol_preset("").ok());
  EXPECT_FALSE(protocol_preset("Manual").ok());  // names are exact
}

// ---- Every setting by name ----------------------------------------------------------------------

struct SettingCase {
  const char* name;
  std::vector<std::string> values;
  const char* manual_default;
  const char* agx_v2_default;
  const char* mini_v3_default;
};

std::ostream& operator<<(std::ostream& os, const SettingCase& c) {
  return os << c.name;
}

const std::vector<SettingCase>& setting_cases() {
  static const std::vector<SettingCase> kCases = {
      {"steering_unit_111", {"centideg", "millirad"}, "centideg", "millirad", "millirad"},
      {"steering_unit_221", {"centideg", "millirad"}, "centideg", "millirad", "millirad"},
      {"steering_unit_271", {"centideg", "millirad"}, "centideg", "millirad", "millirad"},
      {"steering_sign_111",
       {"right_positive", "left_positive"},
       "right_positive",
       "left_positive",
       "left_positive"},
      {"steering_sign_221",
       {"right_positive", "left_positive"},
       "right_positive",
       "left_positive",
       "left_positive"},
      {"steering_sign_271",
       {"right_positive", "left_positive"},
       "right_positive",
       "left_positive",
       "left_positive"},
      {"steering_reference",
       {"mean_front", "inner_front"},
       "mean_front",
       "inner_front",
       "inner_front"},
      {"spin_field", {"wheel_speed", "yaw_rate"}, "wheel_speed", "yaw_rate", "yaw_rate"},
      {"spin_sign", {"ccw", "cw"}, "ccw", "ccw", "ccw"},
      {"feedback_speed", {"mean_wheel", "body_centre"}, "mean_wheel", "body_centre", "body_centre"},
      {"error_word", {"manual32", "agx16", "mini32"}, "manual32", "agx16", "mini32"},
      {"vehicle_status_1_is_estop", {"true", "false"}, "true", "true", "false"},
      {"bms_voltage_scale", {"0.01", "0.1"}, "0.01", "0.1", "0.01"},
      {"bms_current_sign",
       {"discharge_positive", "charge_positive"},
       "charge_positive",
       "charge_positive",
       "charge_positive"},
      {"mode_numbering", {"manual", "agx_v2", "mini_v1", "mini_v3"}, "manual", "agx_v2", "mini_v3"},
      {"driver_status_bit6", {"disabled", "enabled"}, "disabled", "enabled", "enabled"},
      {"frame_layout", {"manual", "agx_v2", "mini_v3"}, "manual", "agx_v2", "mini_v3"},
      {"odometer_unit", {"unknown", "mm"}, "unknown", "unknown", "mm"},
      {"light_modes", {"front_rear", "on_off"}, "front_rear", "front_rear", "on_off"},
      {"tx_dlc", {"0", "8"}, "0", "8", "0"},
  };
  return kCases;
}

TEST(ProfileSettings, TheTableNamesEveryFieldButTheRevisionOnce) {
  const auto& table = profile_settings();
  ASSERT_EQ(table.size(), setting_cases().size());
  std::set<std::string> names;
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(table[i].name, setting_cases()[i].name);
    EXPECT_TRUE(names.insert(std::string(table[i].name)).second) << table[i].name;
    EXPECT_FALSE(table[i].description.empty()) << table[i].name;
    EXPECT_GE(table[i].values.size(), 2u) << table[i].name;
  }
  EXPECT_EQ(names.count("revision"), 0u);
}

class EverySetting : public ::testing::TestWithParam<SettingCase> {};

TEST_P(EverySetting, ListsItsValidValues) {
  const SettingCase& c = GetParam();
  for (const auto& s : profile_settings()) {
    if (s.name != c.name) continue;
    ASSERT_EQ(s.values.size(), c.values.size());
    for (std::size_t i = 0; i < c.values.size(); ++i)
      EXPECT_EQ(s.values[i], c.values[i]);
    return;
  }
  FAIL() << "no setting " << c.name;
}

TEST_P(EverySetting, HasItsDefaultPerRevision) {
  const SettingCase& c = GetParam();
  EXPECT_EQ(*get_setting(preset("manual"), c.name), c.manual_default);
  EXPECT_EQ(*get_setting(preset("agx_v2"), c.name), c.agx_v2_default);
  EXPECT_EQ(*get_setting(preset("mini_v3"), c.name), c.mini_v3_default);
}

TEST_P(EverySetting, AcceptsEachValidValueAndChangesOnlyItself) {
  const SettingCase& c = GetParam();
  for (const char* base : {"manual", "agx_v2", "mini_v3"}) {
    for (const auto& value : c.values) {
      ProtocolProfile p = preset(base);
      const Status st = set_setting(p, c.name, value);
      ASSERT_TRUE(st.ok()) << st.error().message;
      EXPECT_EQ(*get_setting(p, c.name), value);
      EXPECT_TRUE(p.validate().ok());
      EXPECT_EQ(p.revision, base) << "the revision names the preset, not the values";
      for (const auto& other : setting_cases()) {
        if (std::string(other.name) == c.name) continue;
        EXPECT_EQ(*get_setting(p, other.name), *get_setting(preset(base), other.name))
            << "setting " << c.name << " changed " << other.name;
      }
      // The same through one NAME=VALUE text.
      ProtocolProfile q = preset(base);
      ASSERT_TRUE(apply_setting(q, std::string(c.name) + "=" + value).ok());
      EXPECT_EQ(q, p);
    }
  }
}

TEST_P(EverySetting, RejectsOtherValuesNamingTheSettingAndTheValidValues) {
  const SettingCase& c = GetParam();
  std::string valid;
  for (const auto& v : c.values)
    valid += (valid.empty() ? "" : "|") + v;
  for (const char* bad : {"", "bogus", "1", "-1", "TRUE", "0.010"}) {
    ProtocolProfile p = preset("manual");
    if (std::find(c.values.begin(), c.values.end(), bad) != c.values.end()) continue;
    const Status st = set_setting(p, c.name, bad);
    ASSERT_FALSE(st.ok()) << c.name << " accepted '" << bad << "'";
    EXPECT_EQ(st.error().code, Errc::kInvalidArgument);
    EXPECT_EQ(st.error().message, "protocol setting " + std::string(c.name) + " = '" + bad +
                                      "' is invalid (valid: " + valid + ")");
    EXPECT_EQ(p, preset("manual")) << "a refused value changes nothing";
  }
}

INSTANTIATE_TEST_SUITE_P(Profile, EverySetting, ::testing::ValuesIn(setting_cases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ProfileSettings, UnknownNamesListTheValidOnes) {
  ProtocolProfile p;
  const Status st = set_setting(p, "steering_unit", "millirad");
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().code, Errc::kInvalidArgument);
  EXPECT_EQ(st.error().message.rfind("unknown protocol setting 'steering_unit' (valid: ", 0), 0u)
      << st.error().message;
  for (const auto& c : setting_cases())
    EXPECT_NE(st.error().message.find(c.name), std::string::npos) << c.name;
  EXPECT_FALSE(get_setting(p, "revision").ok());
  EXPECT_FALSE(get_setting(p, "").ok());
}

TEST(ProfileSettings, AssignmentText) {
  ProtocolProfile p;
  EXPECT_TRUE(apply_setting(p, "tx_dlc=8").ok());
  EXPECT_EQ(p.tx_dlc, 8);
  for (const char* bad : {"tx_dlc", "=8", "", "tx_dlc:8"}) {
    const Status st = apply_setting(p, bad);
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_NE(st.error().message.find("NAME=VALUE"), std::string::npos) << st.error().message;
  }
  const Status empty_value = apply_setting(p, "tx_dlc=");
  ASSERT_FALSE(empty_value.ok());
  EXPECT_NE(empty_value.error().message.find("(valid: 0|8)"), std::string::npos);
  EXPECT_FALSE(apply_setting(p, "tx_dlc=8=8").ok());
}

// ---- Validation -------------------------------------------------------------------------------

TEST(ProfileValidate, NamesTheSettingAndItsValidValues) {
  auto message = [](const ProtocolProfile& p) {
    const Status st = p.validate();
    EXPECT_FALSE(st.ok());
    return st.ok() ? std::string() : st.error().message;
  };
  ProtocolProfile p;
  p.tx_dlc = 5;
  EXPECT_EQ(message(p), "tx_dlc = 5: valid 0 or 8");
  p = {};
  p.spin_sign = 0;
  EXPECT_EQ(message(p), "spin_sign = 0: valid ccw or cw");
  p = {};
  p.bms_current_sign = 2;
  EXPECT_EQ(message(p), "bms_current_sign = 2: valid discharge_positive or charge_positive");
  p = {};
  p.bms_voltage_scale = 0.05;
  EXPECT_EQ(message(p), "bms_voltage_scale = 0.05: valid 0.01 or 0.1");
  p = {};
  p.mode_numbering = static_cast<ModeNumbering>(7);
  EXPECT_EQ(message(p), "mode_numbering = 7: valid manual, agx_v2, mini_v1 or mini_v3");
  p = {};
  p.steering_unit_271 = static_cast<AngleUnit>(-1);
  EXPECT_EQ(message(p), "steering_unit_271 = -1: valid centideg or millirad");
  EXPECT_FALSE(get_setting(p, "steering_unit_271").ok());
}

// ---- Descriptions and names -------------------------------------------------------------------

TEST(ProfileDescribe, TheRevisionAndWhatDiffersFromItsPreset) {
  EXPECT_EQ(describe(preset("manual")), "manual");
  EXPECT_EQ(describe(preset("agx_v2")), "agx_v2");
  ProtocolProfile p = preset("agx_v2");
  ASSERT_TRUE(set_setting(p, "steering_unit_271", "centideg").ok());
  ASSERT_TRUE(set_setting(p, "tx_dlc", "0").ok());
  EXPECT_EQ(describe(p), "agx_v2 with steering_unit_271=centideg,tx_dlc=0");
  p.revision = "lab";  // not a preset: compared with the manual's
  EXPECT_EQ(describe(p).rfind("lab with steering_unit_111=millirad,", 0), 0u) << describe(p);
}

TEST(ProfileNames, EnumerationsAsTheSettingsSpellThem) {
  EXPECT_EQ(to_string(AngleUnit::kCentidegree), "centideg");
  EXPECT_EQ(to_string(AngleUnit::kMilliradian), "millirad");
  EXPECT_EQ(to_string(SteeringSign::kRightPositive), "right_positive");
  EXPECT_EQ(to_string(SteeringSign::kLeftPositive), "left_positive");
  EXPECT_EQ(to_string(SteeringReference::kMeanFront), "mean_front");
  EXPECT_EQ(to_string(SteeringReference::kInnerFront), "inner_front");
  EXPECT_EQ(to_string(SpinField::kWheelSpeed), "wheel_speed");
  EXPECT_EQ(to_string(SpinField::kYawRate), "yaw_rate");
  EXPECT_EQ(to_string(FeedbackSpeed::kMeanWheel), "mean_wheel");
  EXPECT_EQ(to_string(FeedbackSpeed::kBodyCentre), "body_centre");
  EXPECT_EQ(to_string(ErrorWordLayout::kManual32), "manual32");
  EXPECT_EQ(to_string(ErrorWordLayout::kAgxV2_16), "agx16");
  EXPECT_EQ(to_string(ModeNumbering::kManual), "manual");
  EXPECT_EQ(to_string(ModeNumbering::kAgxV2), "agx_v2");
  EXPECT_EQ(to_string(ModeNumbering::kMiniV1), "mini_v1");
  EXPECT_EQ(to_string(DriverStatusBit6::kDisabled), "disabled");
  EXPECT_EQ(to_string(DriverStatusBit6::kEnabled), "enabled");
  EXPECT_EQ(to_string(ErrorWordLayout::kMini32), "mini32");
  EXPECT_EQ(to_string(ModeNumbering::kMiniV3), "mini_v3");
  EXPECT_EQ(to_string(FrameLayout::kManual), "manual");
  EXPECT_EQ(to_string(FrameLayout::kAgxV2), "agx_v2");
  EXPECT_EQ(to_string(FrameLayout::kMiniV3), "mini_v3");
  EXPECT_EQ(to_string(OdometerUnit::kUnknown), "unknown");
  EXPECT_EQ(to_string(OdometerUnit::kMillimetre), "mm");
  EXPECT_EQ(to_string(LightModes::kFrontRear), "front_rear");
  EXPECT_EQ(to_string(LightModes::kOnOff), "on_off");
  EXPECT_EQ(to_string(static_cast<ModeNumbering>(9)), "unknown");
}

// ---- docs/PROTOCOL_INTERPRETATIONS.md lists every setting as the code has it -------------------

// The cells of a Markdown table row ("| a | b \\| c |" -> {"a", "b | c"}), trimmed.
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < row.size(); ++i) {
    if (row[i] == '\\' && i + 1 < row.size() && row[i + 1] == '|') {
      cell += '|';
      ++i;
    } else if (row[i] == '|') {
      const auto b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
      out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
      cell.clear();
    } else {
      cell += row[i];
    }
  }
  return out;
}

TEST(ProfileDocs, TheSettingsTableMatchesTheCode) {
  std::ifstream in(std::string(RANGER_SOURCE_DIR) + "/../docs/PROTOCOL_INTERPRETATIONS.md");
  ASSERT_TRUE(in.good());
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `", 0) == 0) rows.push_back(line);
  }
  for (const auto& s : profile_settings()) {
    SCOPED_TRACE(std::string(s.name));
    const std::string key = "| `" + std::string(s.name) + "` |";
    const auto row = std::find_if(rows.begin(), rows.end(),
                                  [&](const std::string& r) { return r.rfind(key, 0) == 0; });
    ASSERT_NE(row, rows.end()) << "no row for the setting";
    const auto c = cells(*row);
    ASSERT_GE(c.size(), 8u) << *row;
    for (const auto& v : s.values)
      EXPECT_NE(c[2].find("`" + std::string(v) + "`"), std::string::npos) << c[2];
    EXPECT_EQ(c[3], "`" + *get_setting(preset("manual"), s.name) + "`");
    EXPECT_EQ(c[4], "`" + *get_setting(preset("agx_v2"), s.name) + "`");
    EXPECT_EQ(c[5], "`" + *get_setting(preset("mini_v3"), s.name) + "`");
    // Per model: "ranger_mini_v1 `centideg`" for every model whose preset differs from its
    // revision's there, "—" when none does.
    bool any = false;
    for (const std::string& name : model_names()) {
      const ModelPreset model = *model_preset(name);
      const std::string value = *get_setting(model.profile, s.name);
      const bool differs = value != *get_setting(preset(model.protocol.c_str()), s.name);
      any = any || differs;
      EXPECT_EQ(c[6].find(name + " `" + value + "`") != std::string::npos, differs)
          << name << ": " << c[6];
    }
    if (!any) EXPECT_EQ(c[6], "—");
    EXPECT_FALSE(c[7].empty()) << "evidence";
  }
}

}  // namespace
}  // namespace ranger
