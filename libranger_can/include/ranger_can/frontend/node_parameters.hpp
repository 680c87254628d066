// Everything a node reads, as one parameter table (control/parameters.hpp's row type): the
// driver's rows and the node's own — the bus, frames, publish rates, covariances, ultrasonic
// ranges, the virtual chassis, the vehicle model, the protocol settings and the commissioning file,
// per-axis speed limits generated for linear/x, linear/y and angular/z. The ROS 1 node reads it in
// a loop (load_parameters), the ROS 2 node declares its parameters from it, and every parameter row
// of ranger_base/README.md is markdown_row() of one of its rows.
//
// Every default that has a library counterpart is the library's own (DriverConfig{},
// OdometryConfig{}, sim::VirtualChassisConfig{}, and the model's preset for geometry, limits and
// protocol profile), so a node and `ranger_can scenario --model MODEL` behave alike.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

namespace ranger {

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
  // "auto: identified from the chassis, model ranger", "forced: protocol manual, model ranger",
  // "forced: commissioning file /etc/ranger.yaml".
  std::string source;
};

// Which message `cmd_vel` is taken as (cmd_vel_stamped): geometry_msgs/Twist or TwistStamped
// (Nav2 on Kilted, ros2_control's drive controllers, twist_mux and the teleops with `stamped`);
// kAuto: the type the topic's publishers use, once the first appears and whenever they all use
// the other. The rule and its log lines: frontend/cmd_vel_type.hpp (CmdVelTypeRule).
enum class CmdVelStamped { kAuto, kStamped, kPlain };
inline constexpr auto kCmdVelStampedNames = text::enum_names<CmdVelStamped>({
    {CmdVelStamped::kAuto, "auto"},
    {CmdVelStamped::kStamped, "true"},
    {CmdVelStamped::kPlain, "false"},
});
inline std::string_view to_string(CmdVelStamped c) {
  return kCmdVelStampedNames.name(c);
}

struct NodeParameters {
  // The bus (sim::open_bus_source): a SocketCAN interface, sim[:VARIANT] or replay:FILE.
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
  CmdVelStamped cmd_vel_stamped = CmdVelStamped::kAuto;  // cmd_vel's type

  // x, y, z, roll, pitch, yaw. The pose entries are a floor to which the odometry's growing
  // x/y/yaw variance is added (pose_covariance()); the twist entries are published as they are
  // (the planar ones default to the library's twist variances).
  std::array<double, 6> pose_covariance_diagonal{1e-4, 1e-4, 1e6, 1e6, 1e6, 1e-3};
  std::array<double, 6> twist_covariance_diagonal{
      OdometryConfig{}.twist_variance_linear, OdometryConfig{}.twist_variance_linear, 1e6, 1e6, 1e6,
      OdometryConfig{}.twist_variance_angular};

  UltrasonicRangeParameters ultrasonic;
  ProtocolParameters protocol;

  // controller (geometry, limits, cmd_vel_timeout, ...), odometry (the same geometry, source,
  // covariance growth), reconnect_interval, identification.
  DriverConfig driver;
  // The virtual chassis (port_name sim[:VARIANT] only): its configuration and boot faults.
  sim::SimSourceOptions sim;

  bool is_sim() const;
};

// Every row, in the README's order.
const std::vector<Parameter>& node_parameters();
const Parameter* find_node_parameter(std::string_view name);
// Every row's name (for unknown-name warnings and the README check).
const std::vector<std::string>& known_parameter_names();

// Reads every row from `source` and checks it: its type, its range or values (the table's), then
// what depends on other parameters (min_velocity <= max_velocity, max_range > min_range, the
// error bits of the port's variant, the commissioning file), then DriverConfig::validate(). On
// failure the Error's message lists every problem, one per line, each naming the parameter (the
// source's display_name), the value found and the valid range or values.
Result<NodeParameters> load_parameters(const ParameterSource& source);

// Names set in `source` that no row has (typically typos such as `odom_frame_id`), except the
// `description/` block of ranger_description's geometry.yaml, which is the URDF's, and `also_read`
// (what the front end's own libraries read, e.g. diagnostic_updater's `diagnostic_period`).
std::vector<std::string> unknown_parameter_names(const ParameterSource& source,
                                                 const std::vector<std::string>& also_read = {});

// Every problem a node would refuse to start with, one per line: each unknown name (as
// unknown_parameter_names, "parameter ~NAME is not one ranger_base_node reads ...") and every
// problem load_parameters reports. Empty: the parameters are good (`--check-parameters`).
std::vector<std::string> parameter_problems(const ParameterSource& source,
                                            const std::vector<std::string>& also_read = {});

}  // namespace ranger
