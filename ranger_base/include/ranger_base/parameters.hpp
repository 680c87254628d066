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
#include <utility>
#include <vector>

#include <ranger_can/control/driver.hpp>
#include <ranger_can/control/model.hpp>
#include <ranger_can/result.hpp>
#include <ranger_can/sim/sim_bus_source.hpp>

namespace ros {
class NodeHandle;
}

namespace ranger_base {

struct UltrasonicRangeParameters {
  double field_of_view = 0.52;  // rad, sensor_msgs/Range field_of_view
  double min_range = 0.05;      // m
  double max_range = 5.0;       // m
};

// Where the protocol settings come from: the parameters `protocol`, `model`, one parameter per
// interpretation setting (profile_settings()) and `commissioning_file`, and what they made of
// DriverConfig::protocol and controller.profile.
struct ProtocolParameters {
  std::string protocol = "auto";  // the parameter: auto, or a revision (manual, agx_v2)
  std::string model = "ranger";   // the parameter: a model_names() entry
  std::string model_display_name = "RANGER";
  // The model's own settings on top of its revision (ModelPreset::settings): forced with a
  // revision, the identification's to decide with `auto`.
  std::vector<std::pair<std::string, std::string>> model_settings;
  std::string commissioning_file;  // "" = none
  // The interpretation parameters that were set (NAME, VALUE as text), in the settings table's
  // order: they force those settings, after the preset, the model or the commissioning file.
  std::vector<std::pair<std::string, std::string>> settings;
  // `protocol: auto` with interpretation parameters set: the driver cannot apply forced settings
  // on top of an identification, so the settings are forced (kForced) and identification is off.
  bool auto_overridden = false;
  // One line, for the start-up log and diagnostics: where the settings in use come from, e.g.
  // "auto: identified from the chassis (model ranger)", "forced: protocol manual (model ranger)",
  // "forced: commissioning file /etc/ranger.yaml".
  std::string source;
};

// Every default below that has a library counterpart is read from the library's own structs
// (ranger::DriverConfig{}, ControllerConfig{}, OdometryConfig{}, sim::VirtualChassisConfig{}, and
// the model's preset, ranger::model_preset(model), for geometry, limits and protocol profile), so
// the node and `ranger_can scenario --model MODEL` behave alike.
struct NodeParameters {
  // The bus (ranger::sim::open_bus_source): a SocketCAN interface, sim[:VARIANT] or replay:FILE.
  std::string port_name = "can0";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  // Prefix of the frames the node names itself (ultrasonic_<n>_link), e.g. "robot1/": the launch
  // files give odom_frame and base_frame with the same prefix.
  std::string frame_prefix;
  bool publish_odom_tf = true;
  double publish_rate = 50.0;        // Hz: odom, TF, joint_states (at most the feedback's 50 Hz)
  double state_publish_rate = 10.0;  // Hz: ranger_msgs states, battery, ultrasonic
  bool publish_cmd = false;          // cmd_vel_out: the twist each motion command realises

  // x, y, z, roll, pitch, yaw. The pose entries are a floor to which the odometry's growing
  // x/y/yaw variance is added; the twist entries are published as they are (the planar ones
  // default to the library's twist variances).
  std::array<double, 6> pose_covariance_diagonal{1e-4, 1e-4, 1e6, 1e6, 1e6, 1e-3};
  std::array<double, 6> twist_covariance_diagonal{ranger::OdometryConfig{}.twist_variance_linear,
                                                  ranger::OdometryConfig{}.twist_variance_linear,
                                                  1e6,
                                                  1e6,
                                                  1e6,
                                                  ranger::OdometryConfig{}.twist_variance_angular};

  UltrasonicRangeParameters ultrasonic;

  ProtocolParameters protocol;

  // controller (geometry, limits, cmd_vel_timeout, ...), odometry (the same geometry, source,
  // covariance growth), reconnect_interval, request_answer_timeout.
  ranger::DriverConfig driver;
  // The virtual chassis (port_name sim[:VARIANT] only): its configuration and boot faults.
  ranger::sim::SimSourceOptions sim;

  bool is_sim() const;
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

// The diagnostics' hardware_id: "ranger:<namespace>:<port_name>", e.g. "ranger:/robot1:sim", so
// that robots on one master are told apart.
std::string hardware_id(const std::string& ns, const std::string& port_name);

// Every parameter name load_parameters() reads (for the README check and unknown-name warnings).
const std::vector<std::string>& known_parameter_names();

// Names set in `source` that the node does not read (typically typos such as `odom_frame_id`),
// except the `description/` block of ranger_description's geometry.yaml, which is the URDF's.
std::vector<std::string> unknown_parameter_names(const ParameterSource& source);

}  // namespace ranger_base
