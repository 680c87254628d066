// The one parameter table (control/parameters.hpp's rows, frontend/node_parameters.hpp's table
// and loader): every driver row in it once and unchanged, the per-axis rows generated, each
// type's check naming the problem with the row's range, and the loader reading it in a loop. The
// ROS node's use of it (XmlRpc values, the README's rows) is ranger_base's test_parameters.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "ranger_can/frontend/node_parameters.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

std::string problem(const Parameter& row, const ParameterValue& v) {
  const auto checked = check_parameter(row, v);
  return checked ? "<accepted>" : checked.error().message;
}

TEST(NodeParameters, EveryDriverRowIsInTheTableOnceAsItIs) {
  std::map<std::string, int> seen;
  for (const Parameter& p : node_parameters())
    ++seen[p.name];
  for (const auto& [name, n] : seen)
    EXPECT_EQ(n, 1) << name;
  for (const Parameter& d : driver_parameters()) {
    const Parameter* p = find_node_parameter(d.name);
    ASSERT_NE(p, nullptr) << d.name;
    EXPECT_EQ(markdown_row(*p), markdown_row(d));
    EXPECT_EQ(p->set, d.set) << d.name;
  }
  EXPECT_EQ(known_parameter_names().size(), node_parameters().size());
}

TEST(NodeParameters, PerAxisRowsAreGeneratedForEachAxisInItsUnit) {
  for (const auto& [axis, unit] : {std::pair<std::string, std::string>{"linear/x", "m"},
                                   {"linear/y", "m"},
                                   {"angular/z", "rad"}}) {
    for (const char* name : {"has_velocity_limits", "max_velocity", "min_velocity",
                             "has_acceleration_limits", "max_acceleration", "min_acceleration"}) {
      const Parameter* p = find_node_parameter(axis + "/" + name);
      ASSERT_NE(p, nullptr) << axis << "/" << name;
      if (p->type == ParameterType::kNumber) {
        EXPECT_EQ(p->unit.rfind(unit + "/s", 0), 0u) << p->name << ": " << p->unit;
      }
    }
  }
}

TEST(NodeParameters, EachTypeIsCheckedAndTheProblemNamesTheRange) {
  const Parameter& rate = *find_node_parameter("publish_rate");
  EXPECT_EQ(problem(rate, -5.0), "= -5 is out of range: valid (0, 50] Hz");
  EXPECT_EQ(problem(rate, "fast"), "= \"fast\": expected a number in (0, 50] Hz");
  EXPECT_EQ(check_parameter(rate, 20).value().number, 20.0);  // an integer is a number
  EXPECT_EQ(problem(*find_node_parameter("max_ackermann_steering"), 1.0),
            "= 1 is out of range: valid (0, 0.698132] rad (40 deg)");
  EXPECT_EQ(problem(*find_node_parameter("mode_switch_max_attempts"), 2.5),
            "= 2.5: expected an integer in [1, 100]");
  EXPECT_EQ(problem(*find_node_parameter("publish_odom_tf"), 1), "= 1: expected true or false");
  EXPECT_EQ(problem(*find_node_parameter("protocol"), true), "= true: expected a string");
  EXPECT_EQ(problem(*find_node_parameter("protocol"), "agx_v3"),
            "= \"agx_v3\": expected one of auto, manual, agx_v2");
  EXPECT_EQ(problem(*find_node_parameter("odometry_source"), "gps"),
            "= \"gps\": expected \"wheels\" or \"motion\"");
  // A setting takes a number or a bool as its text.
  const Parameter& tx_dlc = *find_node_parameter("tx_dlc");
  EXPECT_EQ(check_parameter(tx_dlc, 8).value().text, "8");
  EXPECT_NE(problem(tx_dlc, 5).find("= \"5\": expected one of 0, 8 ("), std::string::npos);
  const Parameter& pose = *find_node_parameter("pose_covariance_diagonal");
  EXPECT_EQ(problem(pose, std::vector<ParameterValue>{1.0, 2.0}),
            "= a list of 2: expected a list of 6 numbers in [0, inf)");
  EXPECT_EQ(problem(*find_node_parameter("sim/errors"), "motor_driver_9"),
            "= \"motor_driver_9\": expected a list of strings");
}

TEST(NodeParameters, TheLoaderReadsTheTableAndReportsEveryProblemAtOnce) {
  MapParameterSource source;
  source.values["port_name"] = "sim:agx_v2";
  source.values["linear/y/max_velocity"] = 0.5;
  source.values["sim/errors"] = std::vector<ParameterValue>{"battery_warning"};
  source.values["spin_sign"] = "cw";
  auto p = load_parameters(source);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_DOUBLE_EQ(p->driver.controller.limit_vy.min_velocity, -0.5);  // -max
  EXPECT_NE(p->sim.boot_error_bits, 0u);  // by name, in the variant's (agx16) layout
  EXPECT_EQ(p->driver.controller.profile.spin_sign, -1);
  EXPECT_TRUE(p->protocol.auto_overridden);

  source.values["publish_rate"] = 0.0;
  source.values["ultrasonic/min_range"] = 1.0;
  source.values["ultrasonic/max_range"] = 0.5;
  source.values["bogus_name"] = 1;
  const auto bad = load_parameters(source);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("parameter ~publish_rate = 0 is out of range"),
            std::string::npos)
      << bad.error().message;
  EXPECT_NE(bad.error().message.find(
                "parameter ~ultrasonic/max_range = 0.5 is out of range: valid (1, 32.767] m"),
            std::string::npos)
      << bad.error().message;
  EXPECT_EQ(unknown_parameter_names(source), std::vector<std::string>{"bogus_name"});
  EXPECT_TRUE(unknown_parameter_names(source, {"bogus_name"}).empty());
}

TEST(NodeParameters, ReadmeRowsSayDefaultValidAndMeaning) {
  EXPECT_EQ(markdown_row(*find_node_parameter("publish_rate")),
            "| `publish_rate` | 50 | (0, 50] Hz | `odom`, TF, `joint_states` (and "
            "`sim/ground_truth`): each estimate once, so at most the chassis's 50 Hz motion "
            "feedback |");
  const auto starts = [](const char* name, const std::string& prefix) {
    const std::string row = markdown_row(*find_node_parameter(name));
    return row.rfind(prefix, 0) == 0 ? prefix : row;
  };
  const std::string protocol = "| `protocol` | `auto` | `auto`, `manual`, `agx_v2` |";
  EXPECT_EQ(starts("protocol", protocol), protocol);
  const std::string spin = "| `spin_sign` | unset: manual `ccw`, agx_v2 `ccw` | `ccw`, `cw` |";
  EXPECT_EQ(starts("spin_sign", spin), spin);
}

}  // namespace
}  // namespace ranger
