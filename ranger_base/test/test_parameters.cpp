// Parameter loading and validation, without a ROS master (MapParameterSource).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include <ranger_can/wire/interpretation.hpp>

#include "ranger_base/parameters.hpp"

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
  EXPECT_TRUE(p->publish_odom_tf);
  EXPECT_DOUBLE_EQ(p->publish_rate, 50.0);
  EXPECT_EQ(p->controller.cmd_timeout, 500ms);
  EXPECT_TRUE(p->controller.auto_command_mode);
  EXPECT_EQ(p->odometry.source, ranger::OdometrySource::kWheels);
  const ranger::VehicleGeometry defaults;
  EXPECT_DOUBLE_EQ(p->controller.geometry.wheelbase, defaults.wheelbase);
  EXPECT_DOUBLE_EQ(p->odometry.geometry.track, defaults.track);
  EXPECT_DOUBLE_EQ(p->sim.geometry.wheel_radius, defaults.wheel_radius);
  EXPECT_FALSE(p->is_sim());
  // The vendor node's complaint: zero covariance. Ours is never zero on the planar axes.
  EXPECT_GT(p->pose_covariance_diagonal[0], 0.0);
  EXPECT_GT(p->twist_covariance_diagonal[5], 0.0);
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
  source.values["sim/errors"] = [] {
    XmlRpcValue v;
    v[0] = "motor_driver_1_communication_fault";
    return v;
  }();
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_TRUE(p->is_sim());
  EXPECT_EQ(p->controller.cmd_timeout, 250ms);
  EXPECT_DOUBLE_EQ(p->controller.geometry.wheelbase, 1.0);
  EXPECT_DOUBLE_EQ(p->odometry.geometry.wheelbase, 1.0);
  EXPECT_DOUBLE_EQ(p->sim.geometry.track, 0.6);
  EXPECT_EQ(p->odometry.source, ranger::OdometrySource::kMotion);
  EXPECT_FALSE(p->controller.auto_command_mode);
  EXPECT_DOUBLE_EQ(p->publish_rate, 20.0);
  EXPECT_TRUE(p->controller.limit_vx.has_velocity_limits);
  EXPECT_DOUBLE_EQ(p->controller.limit_vx.max_velocity, 0.8);
  EXPECT_DOUBLE_EQ(p->controller.limit_vx.min_velocity, -0.8);  // ros_controllers' default
  EXPECT_NE(p->sim_error_bits, 0u);
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
    ::testing::Values(BadValue{"publish_rate", -5.0, "(0, 1000] Hz"},
                      BadValue{"publish_rate", 0.0, "(0, 1000] Hz"},
                      BadValue{"publish_rate", "fast", "expected a number"},
                      BadValue{"cmd_vel_timeout", 0.0, "[0.02, 60] s"},
                      BadValue{"cmd_vel_timeout", std::numeric_limits<double>::quiet_NaN(),
                               "[0.02, 60] s"},
                      BadValue{"wheelbase", -0.89, "(0, 10] m"},
                      BadValue{"track", 0.0, "(0, 10] m"},
                      BadValue{"max_linear_speed", 3.0, "(0, 2.6] m/s"},
                      BadValue{"max_ackermann_steering", 1.0, "40 deg"},
                      BadValue{"max_spin_wheel_speed", 1.5, "(0, 1] m/s"},
                      BadValue{"odometry_source", "gps", "\"wheels\" or \"motion\""},
                      BadValue{"port_name", "", "CAN interface name"},
                      BadValue{"port_name", "a/b", "CAN interface name"},
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

}  // namespace
}  // namespace ranger_base
