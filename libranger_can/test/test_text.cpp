// Names and text once (text.hpp, json.hpp): every enum's name table holds every enumerator of its
// enum, once, with a unique name; the word, line and number helpers; the JSON writer's fixed
// numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/diagnostics.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/mode_switch.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/control/rearm.hpp"
#include "ranger_can/frontend/cmd_vel_type.hpp"
#include "ranger_can/frontend/node_parameters.hpp"
#include "ranger_can/json.hpp"
#include "ranger_can/sim/scenario.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

// ---- every enumerator in its table --------------------------------------------------------------
// The compiler names a value of an enum in a template's signature: "E::kName" for an enumerator,
// "(E)7" for a value that is none. This finds an enum's enumerators without listing them again.
template <auto V>
constexpr std::string_view signature() {
  return __PRETTY_FUNCTION__;
}
template <auto V>
constexpr bool is_enumerator() {
  constexpr std::string_view s = signature<V>();
  constexpr std::size_t at = s.find("V = ");
  static_assert(at != std::string_view::npos, "unknown compiler signature format");
  return s[at + 4] != '(';
}

template <typename Enum, int kFirst, int... I>
std::vector<Enum> enumerators_in(std::integer_sequence<int, I...>) {
  std::vector<Enum> out;
  (
      [&] {
        if constexpr (is_enumerator<static_cast<Enum>(kFirst + I)>())
          out.push_back(static_cast<Enum>(kFirst + I));
      }(),
      ...);
  return out;
}

// The enumerators of `Enum` with a value in [-8, 128) ([0, 128) for an unsigned one): every
// enum with a name table keeps its values in that range (a bit-set enum up to 1 << 6).
template <typename Enum>
std::vector<Enum> enumerators() {
  constexpr int kFirst = std::is_signed_v<std::underlying_type_t<Enum>> ? -8 : 0;
  return enumerators_in<Enum, kFirst>(std::make_integer_sequence<int, 128 - kFirst>());
}

template <typename Enum, std::size_t N>
void expect_table_complete(const text::EnumNames<Enum, N>& table, const char* what) {
  std::set<Enum> in_table;
  std::set<std::string_view> names;
  for (const auto& [value, name] : table) {
    EXPECT_TRUE(in_table.insert(value).second) << what << ": a value twice (" << name << ")";
    EXPECT_TRUE(names.insert(name).second) << what << ": the name " << name << " twice";
    EXPECT_FALSE(name.empty()) << what;
    EXPECT_EQ(table.name(value), name) << what;
    EXPECT_EQ(table.parse(name), value) << what << ": " << name;
  }
  const std::vector<Enum> all = enumerators<Enum>();
  EXPECT_EQ(std::set<Enum>(all.begin(), all.end()), in_table)
      << what << ": an enumerator without its name (or a name of no enumerator)";
}

TEST(EnumNames, EveryTableHoldsEveryEnumerator) {
  expect_table_complete(protocol::kDirectionNames, "Direction");
  expect_table_complete(protocol::kMotionModeNames, "MotionMode");
  expect_table_complete(protocol::kControlModeNames, "ControlMode");
  expect_table_complete(protocol::kVehicleStatusNames, "VehicleStatus");
  expect_table_complete(protocol::kRemoteSwitchNames, "RemoteSwitch");
  expect_table_complete(protocol::kLightModeNames, "LightMode");
  expect_table_complete(protocol::kDriveModeNames, "DriveMode");
  expect_table_complete(protocol::kFaultNames, "Fault");
  expect_table_complete(protocol::kUltrasonicCodeNames, "UltrasonicCode");
  expect_table_complete(kAngleUnitNames, "AngleUnit");
  expect_table_complete(kSteeringSignNames, "SteeringSign");
  expect_table_complete(kSteeringReferenceNames, "SteeringReference");
  expect_table_complete(kSpinFieldNames, "SpinField");
  expect_table_complete(kFeedbackSpeedNames, "FeedbackSpeed");
  expect_table_complete(kErrorWordLayoutNames, "ErrorWordLayout");
  expect_table_complete(kModeNumberingNames, "ModeNumbering");
  expect_table_complete(kDriverStatusBit6Names, "DriverStatusBit6");
  expect_table_complete(kFrameLayoutNames, "FrameLayout");
  expect_table_complete(kOdometerUnitNames, "OdometerUnit");
  expect_table_complete(kLightModesNames, "LightModes");
  expect_table_complete(kProtocolSettingNames, "ProtocolSetting");
  expect_table_complete(kBusStateNames, "BusState");
  expect_table_complete(kMotionRefusalNames, "MotionRefusal");
  expect_table_complete(kLinkStateNames, "LinkState");
  expect_table_complete(kControllerFaultNames, "ControllerFault");
  expect_table_complete(kStopCauseNames, "StopCause");
  expect_table_complete(kModeSwitchPhaseNames, "ModeSwitchPhase");
  expect_table_complete(kOdometrySourceNames, "OdometrySource");
  expect_table_complete(kIdentificationPhaseNames, "IdentificationPhase");
  expect_table_complete(kParameterTypeNames, "ParameterType");
  expect_table_complete(kProtocolChoiceNames, "ProtocolChoice");
  expect_table_complete(kRequestKindNames, "RequestOutcome::Kind");
  expect_table_complete(kRequestStateNames, "RequestOutcome::State");
  expect_table_complete(kVendorFramesNames, "VendorFrames");
  expect_table_complete(kFirmwareStateNames, "FirmwareVersion::State");
  expect_table_complete(sim::kOpNames, "Expectation::Op");
  expect_table_complete(kSeverityNames, "Severity");
  expect_table_complete(kEventKindNames, "EventKind");
  expect_table_complete(kDiagnosticLevelNames, "DiagnosticLevel");
  expect_table_complete(kCmdVelStampedNames, "CmdVelStamped");
  expect_table_complete(kCmdVelTypeNames, "CmdVelType");
  expect_table_complete(kTypeSpellingNames, "TypeSpelling");
  expect_table_complete(kCmdVelTypeChangeNames, "CmdVelTypeChange");
}

// The finder itself: it sees a missing enumerator.
enum class Probe : std::uint8_t { kA = 0, kB = 1, kC = 5 };
TEST(EnumNames, TheEnumeratorFinderSeesEveryEnumerator) {
  EXPECT_EQ(enumerators<Probe>(), (std::vector<Probe>{Probe::kA, Probe::kB, Probe::kC}));
  EXPECT_EQ(enumerators<protocol::UltrasonicCode>().size(), 4u);
}

TEST(EnumNames, ToStringParseAndValuesComeFromTheTable) {
  EXPECT_EQ(protocol::to_string(protocol::MotionMode::kSideSlip), "side_slip");
  EXPECT_EQ(protocol::to_string(static_cast<protocol::MotionMode>(9)), "unknown");
  EXPECT_EQ(protocol::kMotionModeNames.parse("spin"), protocol::MotionMode::kSpin);
  EXPECT_FALSE(protocol::kMotionModeNames.parse("Spin").has_value());
  EXPECT_EQ(protocol::kLightModeNames.names(),
            (std::vector<std::string>{"off", "on", "breathing", "custom"}));
  const auto values = kLinkStateNames.values();
  EXPECT_EQ(std::vector<LinkState>(values.begin(), values.end()),
            (std::vector<LinkState>{LinkState::kNeverConnected, LinkState::kConnected,
                                    LinkState::kStale}));
  EXPECT_EQ(protocol::kFaultCount, 16);  // 14, and the MINI 3.0's over-voltage and e-stop bits
}

// The settings table is in kProtocolSettingNames's order, each row named by its enumerator.
TEST(EnumNames, TheProfileSettingsFollowTheirEnum) {
  const auto& settings = profile_settings();
  ASSERT_EQ(settings.size(), kProtocolSettingNames.size());
  std::size_t i = 0;
  for (const auto& [id, name] : kProtocolSettingNames) {
    EXPECT_EQ(settings[i].id, id) << name;
    EXPECT_EQ(settings[i].name, name);
    EXPECT_EQ(&profile_setting(id), &settings[i]) << name;
    ++i;
  }
  ProtocolProfile p;
  ASSERT_TRUE(set_setting(p, ProtocolSetting::kSteeringUnit271, "millirad"));
  EXPECT_EQ(p.steering_unit_271, AngleUnit::kMilliradian);
  EXPECT_EQ(*get_setting(p, ProtocolSetting::kSteeringUnit271), "millirad");
  EXPECT_EQ(*get_setting(p, "steering_unit_271"), "millirad");
  EXPECT_FALSE(set_setting(p, ProtocolSetting::kTxDlc, "5"));
}

// ---- words, lines, numbers ----------------------------------------------------------------------

TEST(Text, TrimAndSplit) {
  EXPECT_EQ(text::trim(" \t a b \r\n"), "a b");
  EXPECT_EQ(text::trim(" \t"), "");
  EXPECT_EQ(text::split_words("  cmd 0.5\t-1  2 "),
            (std::vector<std::string>{"cmd", "0.5", "-1", "2"}));
  EXPECT_TRUE(text::split_words(" \t ").empty());
  EXPECT_EQ(text::split("a,b,,c", ','), (std::vector<std::string>{"a", "b", "", "c"}));
  EXPECT_EQ(text::split("link_lost,", ','), (std::vector<std::string>{"link_lost"}));
  EXPECT_TRUE(text::split("", ',').empty());
  EXPECT_EQ(text::join(std::vector<std::string>{"a", "b"}, "|"), "a|b");
  EXPECT_EQ(text::alternatives({"a", "b", "c"}), "a, b or c");
  EXPECT_EQ(text::alternatives({"a"}), "a");
}

TEST(Text, KeyValueLines) {
  const auto lines = text::key_value_lines(
      "# a comment\n"
      "model: ranger   # the name\n"
      "\n"
      "  nested: 1\n"
      "- item\n"
      "no colon here\n"
      "url: http://x\r\n"
      "empty:\n"
      "   # only a comment");
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0].line, 2u);
  EXPECT_EQ(lines[0].key, "model");
  EXPECT_EQ(lines[0].value, "ranger");
  EXPECT_TRUE(lines[0].colon);
  EXPECT_FALSE(lines[0].indented);
  EXPECT_EQ(lines[1].line, 4u);
  EXPECT_TRUE(lines[1].indented);
  EXPECT_EQ(lines[1].key, "nested");
  EXPECT_TRUE(lines[2].indented);  // "- item"
  EXPECT_FALSE(lines[3].colon);
  EXPECT_EQ(lines[3].text, "no colon here");
  EXPECT_EQ(lines[4].key, "url");
  EXPECT_EQ(lines[4].value, "http://x");  // the first colon splits, CR trimmed
  EXPECT_EQ(lines[5].key, "empty");
  EXPECT_EQ(lines[5].value, "");
}

TEST(Text, Numbers) {
  EXPECT_EQ(text::number_text(0.89), "0.89");
  EXPECT_EQ(text::number_text(1e-5), "1e-05");
  EXPECT_EQ(text::fixed(-0.0001, 3), "-0.000");
  EXPECT_EQ(text::fixed(2.5, 0), "2");
  EXPECT_EQ(text::degrees(M_PI / 4), "45.00 deg");
  EXPECT_EQ(text::format("%6.2f|%s", 1.5, "x"), "  1.50|x");
  EXPECT_EQ(text::format("%s", std::string(1000, 'a').c_str()).size(), 1000u);
  EXPECT_EQ(text::hex(0x211), "0x211");
  EXPECT_EQ(text::hex(0x5, 2), "0x05");
  EXPECT_DOUBLE_EQ(rad_to_deg(deg_to_rad(40.0)), 40.0);
  EXPECT_EQ(deg_to_rad(180.0), M_PI);
}

TEST(Json, FixedNumbersStringsAndLists) {
  std::string s;
  JsonWriter w(s);
  w.begin_object().key("a").fixed(-0.0000001, 3).key("b").fixed(1.23456, 2);
  w.key("c").fixed(std::numeric_limits<double>::quiet_NaN(), 3);
  w.key("d").string_or_null(std::nullopt).key("e").string_or_null(std::string("x"));
  w.key("f").strings({"p", "q"}).key("g").strings({}).end_object();
  EXPECT_EQ(s, R"({"a":0.000,"b":1.23,"c":null,"d":null,"e":"x","f":["p","q"],"g":[]})");
}

}  // namespace
}  // namespace ranger
