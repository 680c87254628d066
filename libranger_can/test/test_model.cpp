// Model presets (control/model.hpp): every model's figures (PROTOCOL_AGX_V2.md's models table),
// the embedded presets equal the files in libranger_can/models/, the flat-YAML parser's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "ranger_can/control/model.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

std::string read_source_file(const std::string& relative) {
  std::ifstream in(std::string(RANGER_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ModelPreset preset(const std::string& name) {
  auto m = model_preset(name);
  EXPECT_TRUE(m.ok()) << (m ? "" : m.error().message);
  return m ? *m : ModelPreset{};
}

std::string setting(const ProtocolProfile& p, const char* name) {
  auto v = get_setting(p, name);
  return v ? *v : "?";
}

TEST(Model, NamesAreTheFourModels) {
  EXPECT_EQ(model_names(), (std::vector<std::string>{"ranger", "ranger_mini_v1", "ranger_mini_v2",
                                                     "ranger_mini_v3"}));
}

TEST(Model, EveryPresetIsValidAndNamedAfterItsFile) {
  for (const std::string& name : model_names()) {
    SCOPED_TRACE(name);
    const ModelPreset m = preset(name);
    EXPECT_EQ(m.name, name);
    EXPECT_FALSE(m.display_name.empty());
    EXPECT_TRUE(m.geometry.validate().ok());
    EXPECT_TRUE(m.limits.validate().ok());
    EXPECT_TRUE(m.profile.validate().ok());
    EXPECT_EQ(m.profile.revision, m.protocol);
    // The spin position (atan(L/W)) is reachable by the steering and inside the plausible range.
    EXPECT_LT(std::atan2(m.geometry.wheelbase, m.geometry.track),
              interpretation::kMaxPlausibleSteeringRad);
  }
}

TEST(Model, RangerIsTheManualsVehicleAndTheLibraryDefaultGeometry) {
  const ModelPreset m = preset("ranger");
  const VehicleGeometry defaults;
  EXPECT_EQ(m.display_name, "RANGER");
  EXPECT_DOUBLE_EQ(m.geometry.wheelbase, defaults.wheelbase);
  EXPECT_DOUBLE_EQ(m.geometry.track, defaults.track);
  EXPECT_DOUBLE_EQ(m.geometry.wheel_radius, defaults.wheel_radius);
  EXPECT_DOUBLE_EQ(m.geometry.wheelbase, 0.890);
  EXPECT_DOUBLE_EQ(m.geometry.track, 0.560);
  EXPECT_DOUBLE_EQ(m.limits.max_linear_speed, 2.6);
  EXPECT_DOUBLE_EQ(m.limits.max_ackermann_steering, 0.698);
  EXPECT_DOUBLE_EQ(m.limits.max_oblique_steering, 1.570);
  EXPECT_NEAR(m.limits.max_spin_wheel_speed / m.geometry.wheel_radius_from_centre(), 0.785, 0.002);
  EXPECT_EQ(m.protocol, "manual");
  EXPECT_TRUE(m.settings.empty());
  EXPECT_EQ(m.profile, manual_profile());
}

TEST(Model, MiniV1HasItsOwnUnitsSignsSpinAndModes) {
  const ModelPreset m = preset("ranger_mini_v1");
  EXPECT_DOUBLE_EQ(m.geometry.wheelbase, 0.36);
  EXPECT_DOUBLE_EQ(m.geometry.track, 0.36);
  EXPECT_NEAR(m.geometry.wheel_radius_from_centre(), 0.2546, 1e-4);  // the vendor's spin radius
  EXPECT_DOUBLE_EQ(m.limits.max_linear_speed, 1.5);
  EXPECT_DOUBLE_EQ(m.limits.max_ackermann_steering, 0.698);
  EXPECT_DOUBLE_EQ(m.limits.max_oblique_steering, 0.698);
  EXPECT_NEAR(m.limits.max_spin_wheel_speed / m.geometry.wheel_radius_from_centre(), 0.3, 0.002);
  EXPECT_EQ(m.protocol, "agx_v2");
  const ProtocolProfile& p = m.profile;
  for (const char* s : {"steering_unit_111", "steering_unit_221", "steering_unit_271"})
    EXPECT_EQ(setting(p, s), "centideg") << s;
  for (const char* s : {"steering_sign_111", "steering_sign_221", "steering_sign_271"})
    EXPECT_EQ(setting(p, s), "right_positive") << s;
  EXPECT_EQ(p.spin_field, SpinField::kWheelSpeed);
  EXPECT_EQ(p.spin_sign, -1);
  EXPECT_EQ(p.mode_numbering, ModeNumbering::kMiniV1);
  // The rest is the vendor's revision.
  EXPECT_EQ(p.error_word, ErrorWordLayout::kAgxV2_16);
  EXPECT_EQ(p.tx_dlc, 8);
  EXPECT_EQ(describe(p),
            "agx_v2 with steering_unit_111=centideg,steering_unit_221=centideg,"
            "steering_unit_271=centideg,steering_sign_111=right_positive,"
            "steering_sign_221=right_positive,steering_sign_271=right_positive,"
            "spin_field=wheel_speed,spin_sign=cw,mode_numbering=mini_v1");
}

TEST(Model, MiniV2AndV3) {
  for (const char* name : {"ranger_mini_v2", "ranger_mini_v3"}) {
    SCOPED_TRACE(name);
    const ModelPreset m = preset(name);
    EXPECT_DOUBLE_EQ(m.geometry.wheelbase, 0.494);
    EXPECT_DOUBLE_EQ(m.geometry.track, 0.364);
    EXPECT_DOUBLE_EQ(m.limits.max_ackermann_steering, 0.698);
    EXPECT_DOUBLE_EQ(m.limits.max_spin_wheel_speed, kMaxSpinSpeedMps);  // 4.8 rad/s is beyond it
  }
  const ModelPreset v2 = preset("ranger_mini_v2");
  EXPECT_DOUBLE_EQ(v2.limits.max_linear_speed, 1.5);
  EXPECT_DOUBLE_EQ(v2.limits.max_oblique_steering, 1.570);
  EXPECT_EQ(v2.protocol, "agx_v2");
  EXPECT_DOUBLE_EQ(v2.profile.bms_voltage_scale, 0.01);
  EXPECT_EQ(v2.profile.spin_field, SpinField::kWheelSpeed);
  EXPECT_EQ(describe(v2.profile), "agx_v2 with spin_field=wheel_speed,bms_voltage_scale=0.01");
}

TEST(Model, MiniV3SpeaksItsOwnManualWithItsLimits) {
  // The RANGER MINI 3.0's manual (PROTOCOL_MINI_V3.md): linear +-2.0 m/s, spin +-3.259 rad/s,
  // Ackermann inner angle +-0.698 rad, oblique +-1.571 rad; beyond 20 deg of steering +-1.0 m/s
  // (the field notes' reading of the manual; our transcription's 0.7 is a parameter away), the
  // steering at the field's 3.26 rad/s (docs/FIELD_FACTS.md).
  const ModelPreset v3 = preset("ranger_mini_v3");
  EXPECT_EQ(v3.protocol, "mini_v3");
  EXPECT_EQ(v3.profile, *protocol_preset("mini_v3"));
  EXPECT_DOUBLE_EQ(v3.limits.max_linear_speed, 2.0);
  EXPECT_DOUBLE_EQ(v3.limits.max_speed_at_large_steering, 1.0);
  EXPECT_DOUBLE_EQ(v3.limits.steering_rate, 3.26);
  EXPECT_DOUBLE_EQ(v3.limits.max_ackermann_steering, 0.698);
  EXPECT_NEAR(v3.limits.max_oblique_steering, 1.571, 0.0005);
  EXPECT_LE(v3.limits.max_oblique_steering, kMaxObliqueSteeringRad);
  const double spin_radius = std::hypot(v3.geometry.wheelbase / 2, v3.geometry.track / 2);
  EXPECT_NEAR(v3.limits.max_spin_wheel_speed / spin_radius, 3.259, 0.001);
  EXPECT_EQ(v3.profile.steering_reference, SteeringReference::kInnerFront);
  EXPECT_EQ(v3.profile.spin_field, SpinField::kYawRate);
}

TEST(Model, EmbeddedPresetsEqualTheFiles) {
  for (const std::string& name : model_names()) {
    SCOPED_TRACE(name);
    const std::string file = read_source_file("models/" + name + ".yaml");
    auto text = model_file_text(name);
    ASSERT_TRUE(text.ok());
    EXPECT_EQ(*text, file) << "rebuild: the embedded model file is stale";
    auto parsed = parse_model(file, name + ".yaml");
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    const ModelPreset m = preset(name);
    EXPECT_EQ(parsed->display_name, m.display_name);
    EXPECT_EQ(parsed->geometry.wheelbase, m.geometry.wheelbase);
    EXPECT_EQ(parsed->geometry.track, m.geometry.track);
    EXPECT_EQ(parsed->geometry.wheel_radius, m.geometry.wheel_radius);
    EXPECT_EQ(parsed->limits.max_linear_speed, m.limits.max_linear_speed);
    EXPECT_EQ(parsed->limits.max_spin_wheel_speed, m.limits.max_spin_wheel_speed);
    EXPECT_EQ(parsed->profile, m.profile);
    EXPECT_EQ(parsed->settings, m.settings);
  }
}

TEST(Model, UnknownModelListsTheValidNames) {
  auto m = model_preset("ranger_maxi");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error().code, Errc::kInvalidArgument);
  EXPECT_EQ(m.error().message,
            "unknown model 'ranger_maxi' (valid: ranger, ranger_mini_v1, ranger_mini_v2, "
            "ranger_mini_v3)");
}

TEST(Model, AnotherRevisionKeepsTheModelsOwnSettings) {
  const ModelPreset v1 = preset("ranger_mini_v1");
  auto manual = model_profile(v1, "manual");
  ASSERT_TRUE(manual.ok());
  EXPECT_EQ(manual->revision, "manual");
  EXPECT_EQ(manual->spin_sign, -1);
  EXPECT_EQ(manual->mode_numbering, ModeNumbering::kMiniV1);
  EXPECT_EQ(manual->error_word, ErrorWordLayout::kManual32);
  auto bad = model_profile(v1, "v3");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("valid: manual, agx_v2"), std::string::npos);
}

// A minimal valid file with one line replaced or added.
std::string minimal(const std::string& extra = "") {
  return "model: test\n"
         "wheelbase: 0.5\ntrack: 0.4\nwheel_radius: 0.1\n"
         "max_linear_speed: 1\nmax_speed_at_large_steering: 1\nmax_ackermann_steering: 0.5\n"
         "max_oblique_steering: 1\nmax_spin_wheel_speed: 0.5\n"
         "protocol: manual\n" +
         extra;
}

std::string replaced(const std::string& from, const std::string& to) {
  std::string text = minimal();
  return text.replace(text.find(from), from.size(), to);
}

TEST(Model, ParserAcceptsTheFlatSubset) {
  auto m = parse_model(minimal("# comment\n\ndescription/ultrasonic_1: [0.1, 0.2, 0.3]  # list\n"
                               "tx_dlc: 8\nspin_sign: 'cw'\n"),
                       "t.yaml");
  ASSERT_TRUE(m.ok()) << m.error().message;
  EXPECT_EQ(m->display_name, "test");
  EXPECT_EQ(m->profile.tx_dlc, 8);
  EXPECT_EQ(m->profile.spin_sign, -1);
  EXPECT_EQ(m->settings, (std::vector<std::pair<std::string, std::string>>{{"tx_dlc", "8"},
                                                                           {"spin_sign", "cw"}}));
}

TEST(Model, ParserErrorsNameTheLineAndTheKey) {
  const struct {
    std::string text;
    std::string message;
  } cases[] = {
      {minimal("colour: red\n"), "t.yaml: line 11: unknown key 'colour' (valid: model,"},
      {minimal("track: 0.5\n"), "t.yaml: line 11: track: given twice (first on line 3)"},
      {minimal("description:\n  body_length: 1\n"), "t.yaml: line 11: description: no value"},
      {minimal("  indented: 1\n"), "t.yaml: line 11: not flat"},
      {minimal("tx_dlc: 5\n"), "t.yaml: line 11: protocol setting tx_dlc = '5' is invalid"},
      {"model: x\n", "t.yaml: wheelbase: missing"},
      {replaced("track: 0.4", "track: wide"), "t.yaml: line 3: track: 'wide' is not a number"},
      {replaced("track: 0.4", "track: -1"), "t.yaml: geometry: track"},
      {replaced("protocol: manual", "protocol: v9"),
       "t.yaml: line 10: unknown protocol revision 'v9'"},
      {replaced("max_linear_speed: 1", "max_linear_speed: 9"),
       "t.yaml: kinematics limits: max_linear_speed"},
  };
  for (const auto& c : cases) {
    auto m = parse_model(c.text, "t.yaml");
    ASSERT_FALSE(m.ok()) << c.message;
    EXPECT_EQ(m.error().message.rfind(c.message, 0), 0u) << m.error().message;
  }
}

}  // namespace
}  // namespace ranger
