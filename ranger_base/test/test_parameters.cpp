// Parameter loading and validation, without a ROS master (MapParameterSource).
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "ranger_base/parameters.hpp"

#include <ranger_can/control/diagnostics.hpp>
#include <ranger_can/control/parameters.hpp>

namespace ranger_base {
namespace {

using XmlRpc::XmlRpcValue;
using namespace std::chrono_literals;

XmlRpcValue list(std::initializer_list<double> values) {
  XmlRpcValue v;
  v.setSize(static_cast<int>(values.size()));
  int i = 0;
  for (double d : values)
    v[i++] = d;
  return v;
}

std::string load_error(const MapParameterSource& source) {
  auto result = load_parameters(source);
  EXPECT_FALSE(result.ok());
  return result.ok() ? "" : result.error().message;
}

TEST(Parameters, DefaultsMatchTheLibraryAndTheIssue) {
  MapParameterSource source;
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->port_name, "can0");
  EXPECT_EQ(p->odom_frame, "odom");
  EXPECT_EQ(p->base_frame, "base_link");
  EXPECT_EQ(p->frame_prefix, "");
  EXPECT_TRUE(p->publish_odom_tf);
  EXPECT_DOUBLE_EQ(p->publish_rate, 50.0);
  EXPECT_EQ(p->driver.odometry.source, ranger::OdometrySource::kWheels);
  EXPECT_FALSE(p->is_sim());
  // The vendor node's complaint: zero covariance. Ours is never zero on the planar axes.
  EXPECT_GT(p->pose_covariance_diagonal[0], 0.0);
  EXPECT_GT(p->twist_covariance_diagonal[5], 0.0);
}

// Every node default that has a library counterpart is the library's: the node and
// `ranger_can scenario` behave alike.
TEST(Parameters, EveryDefaultIsTheLibrarysOwn) {
  MapParameterSource source;
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const ranger::DriverConfig d;
  // Geometry, limits and profile are the default model's (ranger): its preset, as
  // `ranger_can scenario --model ranger` has them.
  const ranger::ModelPreset ranger_model = ranger::model_preset("ranger").value();
  const auto& c = p->driver.controller;
  EXPECT_EQ(p->driver.reconnect_interval, d.reconnect_interval);
  EXPECT_EQ(p->driver.request_answer_timeout, d.request_answer_timeout);
  EXPECT_EQ(c.cmd_timeout, d.controller.cmd_timeout);
  EXPECT_EQ(c.auto_command_mode, d.controller.auto_command_mode);
  EXPECT_EQ(c.auto_reclaim_after_remote, d.controller.auto_reclaim_after_remote);
  EXPECT_FALSE(c.auto_reclaim_after_remote);
  EXPECT_EQ(c.link_timeout, d.controller.link_timeout);
  EXPECT_EQ(c.min_command_interval, d.controller.min_command_interval);
  EXPECT_EQ(c.mode_switch_timeout, d.controller.mode_switch_timeout);
  EXPECT_EQ(c.mode_switch_max_attempts, d.controller.mode_switch_max_attempts);
  EXPECT_DOUBLE_EQ(c.standstill_speed, d.controller.standstill_speed);
  EXPECT_DOUBLE_EQ(c.steer_first_threshold, d.controller.steer_first_threshold);
  EXPECT_DOUBLE_EQ(c.low_battery_soc, d.controller.low_battery_soc);
  EXPECT_DOUBLE_EQ(c.geometry.wheelbase, d.controller.geometry.wheelbase);
  EXPECT_DOUBLE_EQ(c.geometry.track, d.controller.geometry.track);
  EXPECT_DOUBLE_EQ(c.geometry.wheel_radius, d.controller.geometry.wheel_radius);
  EXPECT_DOUBLE_EQ(p->driver.odometry.geometry.track, d.odometry.geometry.track);
  EXPECT_DOUBLE_EQ(p->sim.chassis.geometry.wheel_radius, d.controller.geometry.wheel_radius);
  EXPECT_DOUBLE_EQ(c.geometry.wheelbase, ranger_model.geometry.wheelbase);
  EXPECT_DOUBLE_EQ(c.limits.max_linear_speed, ranger_model.limits.max_linear_speed);
  EXPECT_DOUBLE_EQ(c.limits.max_speed_at_large_steering,
                   ranger_model.limits.max_speed_at_large_steering);
  EXPECT_DOUBLE_EQ(c.limits.max_ackermann_steering, ranger_model.limits.max_ackermann_steering);
  EXPECT_DOUBLE_EQ(c.limits.max_oblique_steering, ranger_model.limits.max_oblique_steering);
  EXPECT_DOUBLE_EQ(c.limits.max_spin_wheel_speed, ranger_model.limits.max_spin_wheel_speed);
  EXPECT_EQ(c.profile, ranger_model.profile);
  EXPECT_EQ(p->sim.chassis.profile, ranger_model.profile);
  // protocol auto (the default): identified, with the library's identification defaults.
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kAuto);
  EXPECT_EQ(p->driver.identification.timeout, d.identification.timeout);
  EXPECT_FALSE(p->driver.identify_revision.has_value());
  for (const auto* axis : {&c.limit_vx, &c.limit_vy, &c.limit_wz}) {
    const ranger::SpeedLimits l;
    EXPECT_EQ(axis->has_velocity_limits, l.has_velocity_limits);
    EXPECT_EQ(axis->has_acceleration_limits, l.has_acceleration_limits);
    EXPECT_DOUBLE_EQ(axis->max_velocity, l.max_velocity);
    EXPECT_DOUBLE_EQ(axis->max_acceleration, l.max_acceleration);
  }
  const auto& m = c.mode_selection;
  const auto& dm = d.controller.mode_selection;
  EXPECT_DOUBLE_EQ(m.lateral_enter, dm.lateral_enter);
  EXPECT_DOUBLE_EQ(m.lateral_exit, dm.lateral_exit);
  EXPECT_DOUBLE_EQ(m.linear_enter, dm.linear_enter);
  EXPECT_DOUBLE_EQ(m.linear_exit, dm.linear_exit);
  EXPECT_DOUBLE_EQ(m.rotation_enter, dm.rotation_enter);
  EXPECT_DOUBLE_EQ(m.rotation_exit, dm.rotation_exit);
  EXPECT_DOUBLE_EQ(m.min_linear_speed, dm.min_linear_speed);
  EXPECT_DOUBLE_EQ(m.min_yaw_rate, dm.min_yaw_rate);
  EXPECT_EQ(m.confirm_time, dm.confirm_time);
  EXPECT_EQ(m.min_dwell, dm.min_dwell);
  EXPECT_DOUBLE_EQ(m.oblique_side_band, dm.oblique_side_band);
  const auto& o = p->driver.odometry;
  EXPECT_EQ(o.source, d.odometry.source);
  EXPECT_EQ(o.wheel_data_timeout, d.odometry.wheel_data_timeout);
  EXPECT_DOUBLE_EQ(o.pose_variance_per_meter, d.odometry.pose_variance_per_meter);
  EXPECT_DOUBLE_EQ(o.yaw_variance_per_radian, d.odometry.yaw_variance_per_radian);
  EXPECT_DOUBLE_EQ(o.yaw_variance_per_meter, d.odometry.yaw_variance_per_meter);
  EXPECT_DOUBLE_EQ(p->twist_covariance_diagonal[0], d.odometry.twist_variance_linear);
  EXPECT_DOUBLE_EQ(p->twist_covariance_diagonal[5], d.odometry.twist_variance_angular);
  const ranger::sim::VirtualChassisConfig v;
  EXPECT_DOUBLE_EQ(p->sim.chassis.initial_soc, v.initial_soc);
  EXPECT_EQ(p->sim.chassis.mode_switch_duration, v.mode_switch_duration);
  EXPECT_EQ(p->sim.chassis.boot_in_remote_mode, v.boot_in_remote_mode);
  EXPECT_EQ(p->sim.chassis.ultrasonic, v.ultrasonic);
  EXPECT_EQ(p->sim.boot_error_bits, 0u);
}

TEST(Parameters, PortNamesAreWhatTheBusFactoryAccepts) {
  for (const char* ok : {"can0", "vcan0", "sim", "sim:manual", "replay:/tmp/drive.log"}) {
    MapParameterSource source;
    source.values["port_name"] = ok;
    auto p = load_parameters(source);
    EXPECT_TRUE(p.ok()) << ok << ": " << p.error().message;
  }
  MapParameterSource sim;
  sim.values["port_name"] = "sim:manual";
  EXPECT_TRUE(load_parameters(sim)->is_sim());
  MapParameterSource unknown_variant;
  unknown_variant.values["port_name"] = "sim:warp";
  const std::string message = load_error(unknown_variant);
  EXPECT_NE(message.find("~port_name"), std::string::npos) << message;
  EXPECT_NE(message.find("manual"), std::string::npos) << message;  // names the valid variants
}

TEST(Parameters, HardwareIdNamesTheRobot) {
  EXPECT_EQ(ranger::hardware_id("/robot1", "sim"), "ranger:/robot1:sim");
  EXPECT_NE(ranger::hardware_id("/robot1", "sim"), ranger::hardware_id("/robot2", "sim"));
  EXPECT_EQ(ranger::hardware_id("/", "can0"), "ranger:/:can0");
}

TEST(Parameters, ValuesAreReadIntoTheLibraryConfigs) {
  MapParameterSource source;
  source.values["port_name"] = "sim";
  source.values["cmd_vel_timeout"] = 0.25;
  source.values["wheelbase"] = 1.0;
  source.values["track"] = 0.6;
  source.values["odometry_source"] = "motion";
  source.values["auto_command_mode"] = false;
  source.values["publish_rate"] = 20;  // an int is a valid number
  source.values["linear/x/has_velocity_limits"] = true;
  source.values["linear/x/max_velocity"] = 0.8;
  source.values["auto_reclaim_after_remote"] = true;
  source.values["steer_first_threshold"] = 0.2;
  source.values["mode_selection/min_linear_speed"] = 0.005;
  source.values["frame_prefix"] = "robot1/";
  source.values["sim/errors"] = [] {
    XmlRpcValue v;
    v[0] = "motor_driver_1_communication_fault";
    return v;
  }();
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const auto& c = p->driver.controller;
  EXPECT_TRUE(p->is_sim());
  EXPECT_EQ(c.cmd_timeout, 250ms);
  EXPECT_DOUBLE_EQ(c.geometry.wheelbase, 1.0);
  EXPECT_DOUBLE_EQ(p->driver.odometry.geometry.wheelbase, 1.0);
  EXPECT_DOUBLE_EQ(p->sim.chassis.geometry.track, 0.6);
  EXPECT_EQ(p->driver.odometry.source, ranger::OdometrySource::kMotion);
  EXPECT_FALSE(c.auto_command_mode);
  EXPECT_DOUBLE_EQ(p->publish_rate, 20.0);
  EXPECT_TRUE(c.limit_vx.has_velocity_limits);
  EXPECT_DOUBLE_EQ(c.limit_vx.max_velocity, 0.8);
  EXPECT_DOUBLE_EQ(c.limit_vx.min_velocity, -0.8);  // ros_controllers' default
  EXPECT_TRUE(c.auto_reclaim_after_remote);
  EXPECT_DOUBLE_EQ(c.steer_first_threshold, 0.2);
  EXPECT_DOUBLE_EQ(c.mode_selection.min_linear_speed, 0.005);
  EXPECT_EQ(p->frame_prefix, "robot1/");
  EXPECT_NE(p->sim.boot_error_bits, 0u);
}

struct BadValue {
  const char* name;
  XmlRpcValue value;
  const char* expected;  // must appear in the message besides the parameter's name
};

class RejectsBadValue : public ::testing::TestWithParam<BadValue> {};

TEST_P(RejectsBadValue, NamingTheParameterAndTheValidRange) {
  const auto& bad = GetParam();
  MapParameterSource source;
  source.values[bad.name] = bad.value;
  const std::string message = load_error(source);
  EXPECT_NE(message.find(std::string("~") + bad.name), std::string::npos) << message;
  EXPECT_NE(message.find(bad.expected), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Parameters, RejectsBadValue,
    ::testing::Values(
        BadValue{"publish_rate", -5.0, "(0, 50] Hz"}, BadValue{"publish_rate", 0.0, "(0, 50] Hz"},
        BadValue{"publish_rate", 100.0, "(0, 50] Hz"},
        BadValue{"publish_rate", "fast", "expected a number"},
        BadValue{"cmd_vel_timeout", 0.0, "[0.02, 60] s"},
        BadValue{"cmd_vel_timeout", std::numeric_limits<double>::quiet_NaN(), "[0.02, 60] s"},
        BadValue{"wheelbase", -0.89, "(0, 10] m"}, BadValue{"track", 0.0, "(0, 10] m"},
        BadValue{"max_linear_speed", 3.0, "(0, 2.6] m/s"},
        BadValue{"max_ackermann_steering", 1.0, "40 deg"},
        BadValue{"max_spin_wheel_speed", 1.5, "(0, 1] m/s"},
        BadValue{"model", "ranger_maxi", "ranger_mini_v1, ranger_mini_v2"},
        BadValue{"protocol", "agx_v3", "auto, manual, agx_v2"},
        BadValue{"protocol", true, "expected a string"},
        BadValue{"steering_unit_111", "mrad", "centideg, millirad"},
        BadValue{"spin_sign", "left", "ccw, cw"}, BadValue{"tx_dlc", 5, "0, 8"},
        BadValue{"bms_voltage_scale", 1.0, "0.01, 0.1"},
        BadValue{"vehicle_status_1_is_estop", "maybe", "true, false"},
        BadValue{"steering_reference", list({1, 2}), "mean_front, inner_front"},
        BadValue{"identify_timeout", 0.0, "[1, 600] s"},
        BadValue{"commissioning_file", "/nonexistent/ranger.yaml", "/nonexistent/ranger.yaml"},
        BadValue{"odometry_source", "gps", "\"wheels\" or \"motion\""},
        BadValue{"port_name", "", "CAN interface name"},
        BadValue{"port_name", "a/b", "CAN interface name"},
        BadValue{"port_name", "replay:", "replay:FILE"},
        BadValue{"steer_first_threshold", 2.0, "[0, 1.5708] rad"},
        BadValue{"frame_prefix", "/robot1/", "no leading '/'"},
        BadValue{"odom_frame", "/odom", "no leading '/'"},
        BadValue{"base_frame", "odom", "must differ from odom_frame"},
        BadValue{"publish_odom_tf", 1, "expected true or false"},
        BadValue{"pose_covariance_diagonal", list({1, 2, 3, 4, 5}), "list of 6"},
        BadValue{"twist_covariance_diagonal", list({1, 1, 1, -1, 1, 1}), "list of 6"},
        BadValue{"linear/x/max_acceleration", -1.0, "(0, 1000] m/s^2"},
        BadValue{"low_battery_soc", 120.0, "[0, 100] %"},
        BadValue{"mode_switch_max_attempts", 0, "[1, 100]"},
        BadValue{"ultrasonic/max_range", 0.01, "m"},
        BadValue{"sim/errors", XmlRpcValue("motor_driver_9"), "list of strings"}));

// ---- protocol settings: protocol, model, the interpretation parameters, commissioning_file --

// A commissioning file written for one test, removed after it.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/ranger_base_test_XXXXXX";
    const int fd = ::mkstemp(name);
    path_ = name;
    if (fd >= 0) ::close(fd);
    std::ofstream(path_) << text;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

ranger::ProtocolProfile preset(const char* revision) {
  return ranger::protocol_preset(revision).value();
}

TEST(Protocol, ARevisionForcesItsPresetOnTheModel) {
  MapParameterSource source;
  source.values["protocol"] = "agx_v2";
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kForced);
  EXPECT_EQ(p->driver.controller.profile, preset("agx_v2"));
  EXPECT_EQ(p->protocol.source, "forced: protocol agx_v2, model ranger");
  EXPECT_FALSE(p->protocol.auto_overridden);
  // The virtual chassis is the model's, whatever the driver is told to speak (a chassis of
  // another revision is sim:VARIANT).
  EXPECT_EQ(p->sim.chassis.profile, preset("manual"));
}

TEST(Protocol, AModelGivesGeometryLimitsAndProfileAndTheParametersOverrideThem) {
  const ranger::ModelPreset mini = ranger::model_preset("ranger_mini_v1").value();
  MapParameterSource source;
  source.values["model"] = "ranger_mini_v1";
  source.values["port_name"] = "sim";
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const auto& c = p->driver.controller;
  EXPECT_DOUBLE_EQ(c.geometry.wheelbase, mini.geometry.wheelbase);
  EXPECT_DOUBLE_EQ(c.geometry.track, mini.geometry.track);
  EXPECT_DOUBLE_EQ(p->driver.odometry.geometry.wheel_radius, mini.geometry.wheel_radius);
  EXPECT_DOUBLE_EQ(c.limits.max_oblique_steering, mini.limits.max_oblique_steering);
  EXPECT_DOUBLE_EQ(c.limits.max_spin_wheel_speed, mini.limits.max_spin_wheel_speed);
  EXPECT_EQ(c.profile, mini.profile);  // auto: the fallback before the decision
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kAuto);
  EXPECT_EQ(p->protocol.model_display_name, "RANGER MINI V1");
  EXPECT_FALSE(p->protocol.model_settings.empty());
  // The in-process chassis is a MINI V1 too.
  EXPECT_DOUBLE_EQ(p->sim.chassis.geometry.wheelbase, mini.geometry.wheelbase);
  EXPECT_EQ(p->sim.chassis.profile, mini.profile);

  // Explicit geometry and limit parameters win over the model's values.
  source.values["wheelbase"] = 0.4;
  source.values["max_linear_speed"] = 0.5;
  source.values["protocol"] = "manual";  // the model's own settings on the manual's preset
  p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_DOUBLE_EQ(p->driver.controller.geometry.wheelbase, 0.4);
  EXPECT_DOUBLE_EQ(p->sim.chassis.geometry.wheelbase, 0.4);
  EXPECT_DOUBLE_EQ(p->driver.controller.geometry.track, mini.geometry.track);
  EXPECT_DOUBLE_EQ(p->driver.controller.limits.max_linear_speed, 0.5);
  EXPECT_EQ(p->driver.controller.profile, ranger::model_profile(mini, "manual").value());
}

TEST(Protocol, InterpretationParametersForceTheirSettingsAfterThePreset) {
  MapParameterSource source;
  source.values["protocol"] = "manual";
  source.values["steering_unit_111"] = "millirad";
  source.values["tx_dlc"] = 8;                         // an int
  source.values["bms_voltage_scale"] = 0.1;            // a double
  source.values["vehicle_status_1_is_estop"] = false;  // a bool
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  auto expected = preset("manual");
  expected.steering_unit_111 = ranger::AngleUnit::kMilliradian;
  expected.tx_dlc = 8;
  expected.bms_voltage_scale = 0.1;
  expected.vehicle_status_1_is_estop = false;
  EXPECT_EQ(p->driver.controller.profile, expected);
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kForced);
  ASSERT_EQ(p->protocol.settings.size(), 4u);  // in the settings table's order
  EXPECT_EQ(p->protocol.settings[0],
            std::make_pair(std::string("steering_unit_111"), std::string("millirad")));
  EXPECT_NE(p->protocol.source.find("with steering_unit_111: millirad"), std::string::npos)
      << p->protocol.source;
}

// The driver identifies a whole profile and cannot keep single settings forced on top of it:
// a set interpretation parameter with protocol auto forces the profile (the log says so).
TEST(Protocol, InterpretationParametersWithAutoForceTheProfile) {
  MapParameterSource source;
  source.values["spin_sign"] = "cw";
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kForced);
  EXPECT_TRUE(p->protocol.auto_overridden);
  EXPECT_EQ(p->driver.controller.profile.spin_sign, -1);
  EXPECT_EQ(p->driver.controller.profile.revision, "manual");
  EXPECT_NE(p->protocol.source.find("auto overridden"), std::string::npos) << p->protocol.source;
}

TEST(Protocol, ACommissioningFileIsForcedOverProtocolAndModelAndUnderTheParameters) {
  const TempFile file(
      "# ranger_can commission sim:spin_cw --wheels-lifted\nprotocol: manual\n"
      "spin_sign: cw\nfeedback_speed: body_centre\n");
  MapParameterSource source;
  source.values["commissioning_file"] = file.path();
  source.values["protocol"] = "agx_v2";            // the file wins
  source.values["feedback_speed"] = "mean_wheel";  // a parameter wins over the file
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  auto expected = preset("manual");
  expected.spin_sign = -1;
  EXPECT_EQ(p->driver.controller.profile, expected);
  EXPECT_EQ(p->driver.protocol, ranger::ProtocolChoice::kForced);
  EXPECT_NE(p->protocol.source.find("commissioning file " + file.path()), std::string::npos)
      << p->protocol.source;
  EXPECT_NE(p->protocol.source.find("overrides protocol agx_v2"), std::string::npos)
      << p->protocol.source;
}

TEST(Protocol, ABadCommissioningFileIsRefusedWithTheLoadersMessage) {
  const TempFile file("protocol: manual\nsteering_unit_111: mrad\n");
  MapParameterSource source;
  source.values["commissioning_file"] = file.path();
  const std::string message = load_error(source);
  EXPECT_NE(message.find("~commissioning_file"), std::string::npos) << message;
  EXPECT_NE(message.find("line 2"), std::string::npos) << message;
  EXPECT_NE(message.find("centideg|millirad"), std::string::npos) << message;
}

TEST(Protocol, IdentifyTimeoutReachesTheIdentification) {
  MapParameterSource source;
  source.values["identify_timeout"] = 20;
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->driver.identification.timeout, 20s);
}

TEST(Protocol, UnknownModelProtocolAndValuesAreRefusedAllAtOnceListingTheValidOnes) {
  MapParameterSource source;
  source.values["model"] = "ranger_maxi";
  source.values["protocol"] = "vendor";
  source.values["steering_sign_271"] = "up";
  const std::string message = load_error(source);
  for (const char* expected :
       {"~model", "ranger, ranger_mini_v1, ranger_mini_v2, ranger_mini_v3", "~protocol",
        "auto, manual, agx_v2", "~steering_sign_271", "right_positive, left_positive"}) {
    EXPECT_NE(message.find(expected), std::string::npos) << expected << " in:\n" << message;
  }
}

TEST(Protocol, EverySettingIsAParameter) {
  const auto& known = known_parameter_names();
  for (const ranger::ProfileSetting& s : ranger::profile_settings()) {
    EXPECT_NE(std::find(known.begin(), known.end(), std::string(s.name)), known.end()) << s.name;
  }
  for (const char* name : {"protocol", "model", "commissioning_file", "identify_timeout"}) {
    EXPECT_NE(std::find(known.begin(), known.end(), name), known.end()) << name;
  }
}

TEST(Parameters, ReportsEveryProblemAtOnce) {
  MapParameterSource source;
  source.values["publish_rate"] = -1.0;
  source.values["odometry_source"] = "gps";
  source.values["wheelbase"] = 0.0;
  const std::string message = load_error(source);
  EXPECT_NE(message.find("~publish_rate"), std::string::npos) << message;
  EXPECT_NE(message.find("~odometry_source"), std::string::npos) << message;
  EXPECT_NE(message.find("~wheelbase"), std::string::npos) << message;
}

TEST(Parameters, MinimumAboveMaximumIsRejected) {
  MapParameterSource source;
  source.values["angular/z/max_velocity"] = 1.0;
  source.values["angular/z/min_velocity"] = 2.0;
  const std::string message = load_error(source);
  EXPECT_NE(message.find("~angular/z/min_velocity"), std::string::npos) << message;
}

TEST(Parameters, UnknownErrorNameForTheSimIsRejected) {
  MapParameterSource source;
  XmlRpcValue errors;
  errors[0] = "motor_driver_9_communication_fault";
  source.values["sim/errors"] = errors;
  const std::string message = load_error(source);
  EXPECT_NE(message.find("motor_driver_9_communication_fault"), std::string::npos) << message;
}

TEST(Parameters, TyposAreReportedAsUnknownButTheUrdfBlockIsNot) {
  MapParameterSource source;
  source.values["odom_frame_id"] = "odom";  // diff_drive_controller's name, not ours
  source.values["publish_rate"] = 50.0;
  source.values["description/body_length"] = 1.228;
  const auto unknown = unknown_parameter_names(source);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "odom_frame_id");
}

TEST(Parameters, EveryParameterIsDocumentedInTheReadme) {
  std::ifstream in(std::string(RANGER_BASE_SOURCE_DIR) + "/README.md");
  ASSERT_TRUE(in) << "README.md not found";
  std::stringstream text;
  text << in.rdbuf();
  for (const auto& name : known_parameter_names()) {
    EXPECT_NE(text.str().find("`" + name + "`"), std::string::npos)
        << name << " is not documented in ranger_base/README.md";
  }
}

// The library's parameter table is the one source of names, ranges and defaults: the node reads
// every row (the driver's defaults included), each parameter row of the README is a row of the
// table character for character and every row is in the README, and a bad value is reported with
// the table's range.
TEST(Parameters, TheLibrarysTableIsWhatTheNodeReadsAndTheReadmeShows) {
  MapParameterSource empty;
  const auto p = load_parameters(empty);
  ASSERT_TRUE(p.ok()) << p.error().message;
  const auto& known = known_parameter_names();
  std::ifstream in(std::string(RANGER_BASE_SOURCE_DIR) + "/README.md");
  ASSERT_TRUE(in) << "README.md not found";
  std::set<std::string> readme_rows;
  bool in_parameters = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) in_parameters = line.rfind("## Parameters", 0) == 0;
    if (in_parameters && line.rfind("| `", 0) == 0) readme_rows.insert(line);
  }
  std::set<std::string> table_rows;
  for (const ranger::Parameter& row : ranger::node_parameters()) {
    const std::string name(row.name);
    EXPECT_NE(std::find(known.begin(), known.end(), name), known.end()) << name;
    table_rows.insert(ranger::markdown_row(row));
    EXPECT_EQ(readme_rows.count(ranger::markdown_row(row)), 1u)
        << "ranger_base/README.md should have the row\n"
        << ranger::markdown_row(row);
  }
  for (const std::string& line : readme_rows) {
    EXPECT_EQ(table_rows.count(line), 1u)
        << "ranger_base/README.md has a parameter row that is not the table's:\n"
        << line;
  }
  for (const ranger::DriverParameter& row : ranger::driver_parameters()) {
    const std::string name(row.name);
    EXPECT_EQ(row.get(p->driver), ranger::default_value(row)) << name;
    // Out of range: the node names the parameter and the table's range.
    MapParameterSource bad;
    bad.values[name] = row.type == ranger::ParameterType::kBool ? XmlRpcValue(3.0)
                                                                : XmlRpcValue(row.range.hi + 1.0);
    const std::string message = load_error(bad);
    EXPECT_NE(message.find("~" + name), std::string::npos) << message;
    if (row.type != ranger::ParameterType::kBool) {
      EXPECT_NE(message.find(ranger::valid_text(row)), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace ranger_base
