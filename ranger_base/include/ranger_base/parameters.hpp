// The node's parameters: read from the private namespace, checked, and turned into
// libranger_can's configuration structs. Every check names the parameter and its valid range, and
// all problems are reported at once, so a bad launch file is fixed in one go.
//
// Reading goes through ParameterSource so that the rules are unit-tested without a ROS master.
// Names follow ros_controllers (diff_drive_controller) where one exists; ranger_base/README.md
// documents every parameter.
#pragma once

#include <xmlrpcpp/XmlRpcValue.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <ranger_can/control/controller.hpp>
#include <ranger_can/control/odometry.hpp>
#include <ranger_can/result.hpp>
#include <ranger_can/sim/virtual_chassis.hpp>

namespace ros {
class NodeHandle;
}

namespace ranger_base {

// The port name that selects the in-process virtual chassis instead of a CAN interface.
inline constexpr const char* kSimPortName = "sim";

struct UltrasonicRangeParameters {
  double field_of_view = 0.52;  // rad, sensor_msgs/Range field_of_view
  double min_range = 0.05;      // m
  double max_range = 5.0;       // m
};

struct NodeParameters {
  std::string port_name = "can0";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  bool publish_odom_tf = true;
  double publish_rate = 50.0;        // Hz: odom, TF, joint_states
  double state_publish_rate = 10.0;  // Hz: ranger_msgs states, battery, ultrasonic
  bool publish_cmd = false;          // cmd_vel_out: the twist each 0x111 realises
  std::chrono::nanoseconds reconnect_interval = std::chrono::seconds(1);

  // x, y, z, roll, pitch, yaw. The pose entries are a floor to which the odometry's growing
  // x/y/yaw variance is added; the twist entries are published as they are.
  std::array<double, 6> pose_covariance_diagonal{1e-4, 1e-4, 1e6, 1e6, 1e6, 1e-3};
  std::array<double, 6> twist_covariance_diagonal{1e-3, 1e-3, 1e6, 1e6, 1e6, 2e-3};

  UltrasonicRangeParameters ultrasonic;

  ranger::ControllerConfig controller;    // geometry, limits, cmd_vel_timeout, ...
  ranger::OdometryConfig odometry;        // geometry (same), source, covariance growth
  ranger::sim::VirtualChassisConfig sim;  // port_name = sim only
  std::uint32_t sim_error_bits = 0;       // 0x211 error bits the virtual chassis boots with

  bool is_sim() const { return port_name == kSimPortName; }
};

// Where parameter values come from: the node's private namespace, or a map in tests.
class ParameterSource {
 public:
  virtual ~ParameterSource() = default;
  // The value of `name` (relative to the private namespace, '/'-separated), or nullopt if unset.
  virtual std::optional<XmlRpc::XmlRpcValue> get(const std::string& name) const = 0;
  // How `name` is shown in messages (e.g. "/robot1/ranger_base_node/publish_rate").
  virtual std::string display_name(const std::string& name) const = 0;
  // Every parameter name set below the private namespace (relative, '/'-separated).
  virtual std::vector<std::string> names() const = 0;
};

class NodeHandleParameterSource final : public ParameterSource {
 public:
  explicit NodeHandleParameterSource(const ros::NodeHandle& private_nh);
  std::optional<XmlRpc::XmlRpcValue> get(const std::string& name) const override;
  std::string display_name(const std::string& name) const override;
  std::vector<std::string> names() const override;

 private:
  const ros::NodeHandle& nh_;
};

class MapParameterSource final : public ParameterSource {
 public:
  std::map<std::string, XmlRpc::XmlRpcValue> values;
  std::optional<XmlRpc::XmlRpcValue> get(const std::string& name) const override;
  std::string display_name(const std::string& name) const override { return "~" + name; }
  std::vector<std::string> names() const override;
};

// Reads and checks every parameter. On failure the Error's message lists every problem, one per
// line, each naming the parameter, the value found and the valid range.
ranger::Result<NodeParameters> load_parameters(const ParameterSource& source);

// Every parameter name load_parameters() reads (for the README check and unknown-name warnings).
const std::vector<std::string>& known_parameter_names();

// Names set in `source` that the node does not read (typically typos such as `odom_frame_id`),
// except the `description/` block of ranger_description's geometry.yaml, which is the URDF's.
std::vector<std::string> unknown_parameter_names(const ParameterSource& source);

}  // namespace ranger_base
