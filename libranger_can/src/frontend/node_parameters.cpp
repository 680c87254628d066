#include "ranger_can/frontend/node_parameters.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

#include "ranger_can/control/commissioning.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus_source.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using T = ParameterType;
using Apply = std::function<Status(NodeParameters&, const ParameterValue&)>;

// A row and where its checked value goes (nullptr: read by a step of its own, the model first).
struct Binding {
  Parameter row;
  Apply apply;
};

constexpr ParameterRange closed(double lo, double hi) {
  return {lo, hi, false, false};
}
constexpr ParameterRange open_closed(double lo, double hi) {
  return {lo, hi, true, false};
}
// Variances: any finite value >= 0.
constexpr ParameterRange kVariance{0.0, std::numeric_limits<double>::infinity(), false, true};
// The farthest distance an ultrasonic value (int16 mm) can say.
constexpr double kMaxUltrasonicRange = 32.767;

Error problem(std::string message) {
  return Error{Errc::kInvalidArgument, std::move(message)};
}

// A node's row, built field by field.
struct Row {
  Binding b;
  Row(std::string name, T type, std::string unit, ParameterRange range, ParameterValue def,
      std::string meaning) {
    b.row.name = std::move(name);
    b.row.type = type;
    b.row.unit = std::move(unit);
    b.row.range = range;
    b.row.default_value = std::move(def);
    b.row.meaning = std::move(meaning);
  }
  Row& choices(std::vector<std::string> c) {
    b.row.choices = std::move(c);
    return *this;
  }
  Row& valid(std::string note) {
    b.row.valid_note = std::move(note);
    return *this;
  }
  Row& by_default(std::string note) {
    b.row.default_note = std::move(note);
    return *this;
  }
  Row& size(std::size_t n) {
    b.row.size = n;
    return *this;
  }
  Row& apply(Apply f) {
    b.apply = std::move(f);
    return *this;
  }
  operator Binding() const { return b; }  // NOLINT: a row is its binding
};

// An apply that sets one field from the checked value (`v`) and accepts it.
#define RANGER_SET(field, expr)                    \
  [](NodeParameters& p, const ParameterValue& v) { \
    p.field = (expr);                              \
    return ok_status();                            \
  }

std::chrono::nanoseconds from_secs(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

// A driver row: its value goes into NodeParameters::driver through the row's accessor.
Binding driver_row(std::string_view name) {
  const Parameter& row = *find_driver_parameter(name);
  return {row, [set = row.set, type = row.type](NodeParameters& p, const ParameterValue& v) {
            const double x = type == T::kBool      ? (v.boolean ? 1.0 : 0.0)
                             : type == T::kInteger ? static_cast<double>(v.integer)
                                                   : v.number;
            set(p.driver, x);
            return ok_status();
          }};
}

// ---- checks of the node's own values ------------------------------------------------------------

Status check_port_name(const std::string& port) {
  const std::string forms =
      "expected a CAN interface name (1-15 characters, e.g. can0, vcan0), sim[:VARIANT] (the "
      "in-process virtual chassis; variants: " +
      text::join(sim::variant_names()) + ") or replay:FILE (a candump log, read-only)";
  const auto kind = bus_kind(port);
  if (!kind || (*kind == BusKind::kSocketCan && port.find_first_of("/ \t:") != std::string::npos)) {
    return problem("= \"" + port + "\": " + forms);
  }
  if (*kind == BusKind::kSim && port.size() > 3) {
    if (auto v = sim::apply_variant(port.substr(4), {}); !v) {
      return problem("= \"" + port + "\": " + v.error().message);
    }
  }
  return ok_status();
}

// A tf2 frame id: non-empty, no whitespace, no leading '/'.
Status check_frame(const std::string& v) {
  const bool has_space =
      std::any_of(v.begin(), v.end(), [](unsigned char c) { return std::isspace(c) != 0; });
  if (v.empty() || has_space || v.front() == '/') {
    return problem("= \"" + v +
                   "\": expected a tf2 frame id (non-empty, no spaces, no leading '/')");
  }
  return ok_status();
}

Status check_prefix(const std::string& v) {
  if (v.find_first_of(" \t") != std::string::npos || (!v.empty() && v.front() == '/')) {
    return problem("= \"" + v +
                   "\": expected a tf2 frame prefix such as \"robot1/\" (no spaces, no leading "
                   "'/')");
  }
  return ok_status();
}

// An apply that sets a text field once `check` accepts the value.
Apply checked_text(std::string NodeParameters::*field, Status (*check)(const std::string&)) {
  return [field, check](NodeParameters& p, const ParameterValue& v) {
    Status st = check(v.text);
    if (st) p.*field = v.text;
    return st;
  };
}

// Boot faults by index or name, in the error-word layout of the port's variant.
Status apply_sim_errors(NodeParameters& p, const ParameterValue& v) {
  ErrorWordLayout layout = p.sim.chassis.profile.error_word;
  if (const auto kind = bus_kind(p.port_name);
      kind && *kind == BusKind::kSim && p.port_name.size() > 4) {
    if (auto variant = sim::apply_variant(p.port_name.substr(4), {})) {
      layout = variant->profile.error_word;
    }
  }
  std::vector<std::string> bad;
  for (const ParameterValue& item : v.items) {
    if (auto bit = sim::parse_error_bit(item.text, layout)) {
      p.sim.boot_error_bits |= 1u << *bit;
    } else {
      bad.push_back("contains \"" + item.text + "\": " + bit.error().message);
    }
  }
  if (!bad.empty()) return problem(text::join(bad, "; "));
  return ok_status();
}

// The model's geometry, limits and virtual chassis: the defaults of the rows that follow it.
void apply_model(const ModelPreset& model, NodeParameters& p) {
  p.protocol.model = model.name;
  p.protocol.model_display_name = model.display_name;
  p.protocol.model_settings = model.settings;
  p.driver.controller.limits = model.limits;
  p.driver.controller.geometry = model.geometry;
  p.driver.controller.profile = model.profile;
  p.sim.chassis = sim::chassis_for_model(model, p.sim.chassis);
}

const ModelPreset& default_model() {
  static const ModelPreset model = model_preset("ranger").value();
  return model;
}

const NodeParameters& defaults() {
  static const NodeParameters d = [] {
    NodeParameters p;
    apply_model(default_model(), p);
    return p;
  }();
  return d;
}

// "the model's (RANGER 0.89)": the default of a geometry or limit row.
std::string models(double value) {
  return "the model's (" + default_model().display_name + " " + number_text(value) + ")";
}

// ---- the rows -----------------------------------------------------------------------------------

void add_connection(std::vector<Binding>& out) {
  const NodeParameters& d = defaults();
  std::vector<std::string> variants;
  for (const std::string& v : sim::variant_names())
    variants.push_back("`" + v + "`");
  out.push_back(
      Row("port_name", T::kText, "", {}, d.port_name,
          "the bus: a SocketCAN interface (`can0`, `vcan0`); the in-process virtual chassis (of "
          "the `model`; a variant reads the protocol another way, "
          "`docs/PROTOCOL_INTERPRETATIONS.md`); or a candump log replayed through the node "
          "(read-only)")
          .valid("an interface name (1-15 characters), `sim`, `sim:VARIANT` (variants: " +
                 text::join(variants) + ") or `replay:FILE`")
          .apply(checked_text(&NodeParameters::port_name, check_port_name)));
  out.push_back(driver_row("reconnect_interval"));
  out.push_back(Row("odom_frame", T::kText, "", {}, d.odom_frame, "REP-105 odometry frame")
                    .valid("tf2 frame id")
                    .apply(checked_text(&NodeParameters::odom_frame, check_frame)));
  out.push_back(Row("base_frame", T::kText, "", {}, d.base_frame, "the robot frame")
                    .valid("tf2 frame id, ≠ `odom_frame`")
                    .apply(checked_text(&NodeParameters::base_frame, check_frame)));
  out.push_back(
      Row("frame_prefix", T::kText, "", {}, d.frame_prefix,
          "prefix of the frames the node names itself (the ultrasonic sensors' "
          "`ultrasonic_<n>_link`), e.g. `robot1/`; `odom_frame` and `base_frame` are given whole "
          "(ranger_bringup's launch files pass all three with the namespace)")
          .valid("no spaces, no leading `/`")
          .apply(checked_text(&NodeParameters::frame_prefix, check_prefix)));
  out.push_back(Row("publish_odom_tf", T::kBool, "", {}, d.publish_odom_tf,
                    "broadcast `odom_frame` → `base_frame`")
                    .apply(RANGER_SET(publish_odom_tf, v.boolean)));
  // The chassis reports its motion every 20 ms: a higher rate would have no estimate to publish.
  out.push_back(Row("publish_rate", T::kNumber, "Hz", open_closed(0.0, 50.0), d.publish_rate,
                    "`odom`, TF, `joint_states` (and `sim/ground_truth`): each estimate once, so "
                    "at most the chassis's 50 Hz motion feedback")
                    .apply(RANGER_SET(publish_rate, v.number)));
  out.push_back(Row("state_publish_rate", T::kNumber, "Hz", open_closed(0.0, 100.0),
                    d.state_publish_rate,
                    "`system_state`, `actuator_state`, `bms_state`, `battery_state`, ultrasonic "
                    "(each built and sent only while it has a subscriber)")
                    .apply(RANGER_SET(state_publish_rate, v.number)));
  out.push_back(Row("publish_cmd", T::kBool, "", {}, d.publish_cmd, "publish `cmd_vel_out`")
                    .apply(RANGER_SET(publish_cmd, v.boolean)));
  out.push_back(
      Row("cmd_vel_stamped", T::kChoice, "", {}, std::string(to_string(d.cmd_vel_stamped)),
          "`cmd_vel` as geometry_msgs/TwistStamped (`true`: Nav2's `enable_stamped_cmd_vel`, "
          "ros2_control's drive controllers, twist_mux and the teleops' `stamped`) or Twist "
          "(`false`); `auto`: the type of the topic's publishers, once the first appears and "
          "whenever they all use the other (said in the log). A stamp older than "
          "`cmd_vel_timeout` is not obeyed (`stale_command`); a zero stamp means now. Both nodes, "
          "by the library's rule and in its words (`frontend/cmd_vel_type.hpp`); the ROS 1 node's "
          "`auto` also reads each message as the type its publisher declares")
          .choices(kCmdVelStampedNames.names())
          .apply([](NodeParameters& p, const ParameterValue& v) {
            p.cmd_vel_stamped = kCmdVelStampedNames.parse(v.text).value_or(CmdVelStamped::kAuto);
            return ok_status();
          }));
}

void add_control(std::vector<Binding>& out) {
  for (const char* name :
       {"cmd_vel_timeout", "auto_command_mode", "auto_reclaim_after_remote", "rearm_on_zero_twist",
        "link_timeout", "min_command_interval", "mode_switch_timeout", "mode_switch_max_attempts",
        "mode_switch_blind_time", "mode_switch_min_time", "mode_switch_wheel_tolerance",
        "standstill_speed", "steer_first_threshold", "low_battery_soc"}) {
    out.push_back(driver_row(name));
  }
}

// "unset: manual `centideg`, agx_v2 `millirad`": what a setting is on each revision's preset.
std::string preset_values(std::string_view setting) {
  std::vector<std::string> each;
  for (const std::string& revision : protocol_revision_names()) {
    const auto value = get_setting(protocol_preset(revision).value(), setting);
    each.push_back(revision + " `" + (value ? *value : "?") + "`");
  }
  return "unset: " + text::join(each);
}

void add_protocol(std::vector<Binding>& out) {
  const NodeParameters& d = defaults();
  out.push_back(
      Row("model", T::kText, "", {}, d.protocol.model,
          "the vehicle (`libranger_can/models/MODEL.yaml`): the defaults of the geometry and limit "
          "parameters below and the protocol profile a revision starts from; with `port_name: "
          "sim[:VARIANT]` the virtual chassis is that model. Explicit geometry and limit "
          "parameters still override the model's values")
          .choices(model_names()));
  std::vector<std::string> protocols = {"auto"};
  for (const std::string& r : protocol_revision_names())
    protocols.push_back(r);
  out.push_back(
      Row("protocol", T::kText, "", {}, d.protocol.protocol,
          "`auto`: identified from the chassis before anything moves (see \"How it runs\"); "
          "`manual` (the user manual), `agx_v2` (the vendor's software since firmware v5.7) or "
          "`mini_v3` (the RANGER MINI 3.0's manual; the default of `model: ranger_mini_v3`): "
          "that preset, with the model's own settings")
          .choices(protocols)
          .apply(RANGER_SET(protocol.protocol, v.text)));
  out.push_back(Row("commissioning_file", T::kText, "", {}, d.protocol.commissioning_file,
                    "the settings commissioning decided for this chassis, forced (over "
                    "`protocol` and the model's profile); `\"\"`: none")
                    .valid("a file written by `ranger_can commission IFACE --wheels-lifted "
                           "--output FILE`")
                    .apply(RANGER_SET(protocol.commissioning_file, v.text)));
  out.push_back(driver_row("identify_timeout"));
  // One parameter per interpretation setting: set, it forces that setting.
  for (const ProfileSetting& s : profile_settings()) {
    const std::string name(s.name);
    out.push_back(Row(name, T::kChoice, "", {}, std::string(), std::string(s.description))
                      .choices(std::vector<std::string>(s.values.begin(), s.values.end()))
                      .by_default(preset_values(s.name))
                      .apply([name](NodeParameters& p, const ParameterValue& v) {
                        p.protocol.settings.emplace_back(name, v.text);
                        return ok_status();
                      }));
  }
}

void add_geometry_and_limits(std::vector<Binding>& out) {
  const auto& g = defaults().driver.controller.geometry;
  const auto& l = defaults().driver.controller.limits;
  const KinematicsLimits full;  // the protocol's ranges
  const double top_speed = interpretation::kMaxLinearSpeedMps;
  out.push_back(Row("wheelbase", T::kNumber, "m", open_closed(0.0, 10.0), g.wheelbase,
                    "front axle to rear axle")
                    .by_default(models(g.wheelbase))
                    .apply(RANGER_SET(driver.controller.geometry.wheelbase, v.number)));
  out.push_back(
      Row("track", T::kNumber, "m", open_closed(0.0, 10.0), g.track, "left to right wheel centre")
          .by_default(models(g.track))
          .apply(RANGER_SET(driver.controller.geometry.track, v.number)));
  out.push_back(Row("wheel_radius", T::kNumber, "m", open_closed(0.0, 5.0), g.wheel_radius,
                    "for the wheel joint angles")
                    .by_default(models(g.wheel_radius))
                    .apply(RANGER_SET(driver.controller.geometry.wheel_radius, v.number)));
  out.push_back(Row("max_linear_speed", T::kNumber, "m/s", open_closed(0.0, top_speed),
                    l.max_linear_speed, "body speed in Ackermann and oblique mode")
                    .by_default(models(l.max_linear_speed))
                    .apply(RANGER_SET(driver.controller.limits.max_linear_speed, v.number)));
  out.push_back(
      Row("max_speed_at_large_steering", T::kNumber, "m/s", open_closed(0.0, top_speed),
          l.max_speed_at_large_steering,
          "speed limit while steering beyond 20° (the manual names such a limit without a value)")
          .by_default(models(l.max_speed_at_large_steering))
          .apply(RANGER_SET(driver.controller.limits.max_speed_at_large_steering, v.number)));
  out.push_back(Row("max_ackermann_steering", T::kNumber, "rad",
                    open_closed(0.0, full.max_ackermann_steering), l.max_ackermann_steering,
                    "mean front-wheel angle in Ackermann mode")
                    .by_default(models(l.max_ackermann_steering))
                    .apply(RANGER_SET(driver.controller.limits.max_ackermann_steering, v.number)));
  out.push_back(Row("max_oblique_steering", T::kNumber, "rad",
                    open_closed(0.0, full.max_oblique_steering), l.max_oblique_steering,
                    "direction of travel in oblique mode")
                    .by_default(models(l.max_oblique_steering))
                    .apply(RANGER_SET(driver.controller.limits.max_oblique_steering, v.number)));
  out.push_back(Row("max_spin_wheel_speed", T::kNumber, "m/s",
                    open_closed(0.0, full.max_spin_wheel_speed), l.max_spin_wheel_speed,
                    "wheel speed in spin mode (yaw rate = speed / hypot(wheelbase/2, track/2))")
                    .by_default(models(l.max_spin_wheel_speed))
                    .apply(RANGER_SET(driver.controller.limits.max_spin_wheel_speed, v.number)));
  out.push_back(
      Row("steering_rate", T::kNumber, "rad/s", open_closed(0.0, 100.0), l.steering_rate,
          "how fast the chassis turns its steering (no manual gives it; the RANGER MINI 3.0 was "
          "seen "
          "at 3.26 rad/s): the odometry's assumption for a silence of the chassis's feedback that "
          "its own odometer bridges, the wheels turning toward what the driver commanded "
          "meanwhile; "
          "not a command limit")
          .by_default(models(l.steering_rate))
          .apply(RANGER_SET(driver.controller.limits.steering_rate, v.number)));
}

// ros_controllers' per-axis limits (diff_drive_controller's SpeedLimiter parameters), generated
// for one axis: defaults from SpeedLimits{} (limits off); a missing min_* is -max_*.
void add_axis(std::vector<Binding>& out, const std::string& axis, const std::string& unit,
              const std::string& what, SpeedLimits ControllerConfig::*field) {
  const SpeedLimits none;
  const std::string vel = unit + "/s", acc = unit + "/s^2";
  const auto limits = [field](NodeParameters& p) -> SpeedLimits& {
    return p.driver.controller.*field;
  };
  out.push_back(Row(axis + "/has_velocity_limits", T::kBool, "", {}, none.has_velocity_limits,
                    "limit the " + what + " to [`min_velocity`, `max_velocity`]")
                    .apply([limits](NodeParameters& p, const ParameterValue& v) {
                      limits(p).has_velocity_limits = v.boolean;
                      return ok_status();
                    }));
  out.push_back(Row(axis + "/max_velocity", T::kNumber, vel, closed(0.0, 10.0), none.max_velocity,
                    "the highest " + what +
                        " (0 as in ros_controllers: set it with "
                        "`has_velocity_limits`)")
                    .apply([limits](NodeParameters& p, const ParameterValue& v) {
                      limits(p).max_velocity = v.number;
                      limits(p).min_velocity = -v.number;
                      return ok_status();
                    }));
  out.push_back(Row(axis + "/min_velocity", T::kNumber, vel, closed(-10.0, 10.0),
                    -none.max_velocity, "the lowest " + what)
                    .by_default("-`max_velocity`")
                    .valid("[-10, `max_velocity`] " + vel)
                    .apply([limits, vel](NodeParameters& p, const ParameterValue& v) {
                      if (v.number > limits(p).max_velocity) {
                        return Status(problem("= " + shown(v) + " is out of range: valid [-10, " +
                                              number_text(limits(p).max_velocity) + "] " + vel));
                      }
                      limits(p).min_velocity = v.number;
                      return ok_status();
                    }));
  out.push_back(Row(axis + "/has_acceleration_limits", T::kBool, "", {},
                    none.has_acceleration_limits, "limit how fast the " + what + " changes")
                    .apply([limits](NodeParameters& p, const ParameterValue& v) {
                      limits(p).has_acceleration_limits = v.boolean;
                      return ok_status();
                    }));
  out.push_back(Row(axis + "/max_acceleration", T::kNumber, acc, open_closed(0.0, 1000.0),
                    none.max_acceleration,
                    "the fastest increase (0 as in ros_controllers: set it with "
                    "`has_acceleration_limits`)")
                    .apply([limits](NodeParameters& p, const ParameterValue& v) {
                      limits(p).max_acceleration = v.number;
                      limits(p).min_acceleration = -v.number;
                      return ok_status();
                    }));
  out.push_back(Row(axis + "/min_acceleration", T::kNumber, acc, {-1000.0, 0.0, false, true},
                    -none.max_acceleration, "the fastest decrease")
                    .by_default("-`max_acceleration`")
                    .apply([limits](NodeParameters& p, const ParameterValue& v) {
                      limits(p).min_acceleration = v.number;
                      return ok_status();
                    }));
}

void add_axes(std::vector<Binding>& out) {
  add_axis(out, "linear/x", "m", "forward speed vx", &ControllerConfig::limit_vx);
  add_axis(out, "linear/y", "m", "lateral speed vy", &ControllerConfig::limit_vy);
  add_axis(out, "angular/z", "rad", "yaw rate wz", &ControllerConfig::limit_wz);
  for (const char* name : {"mode_selection/lateral_enter", "mode_selection/lateral_exit",
                           "mode_selection/linear_enter", "mode_selection/linear_exit",
                           "mode_selection/rotation_enter", "mode_selection/rotation_exit",
                           "mode_selection/min_linear_speed", "mode_selection/min_yaw_rate",
                           "mode_selection/confirm_time", "mode_selection/min_dwell",
                           "mode_selection/oblique_side_band"}) {
    out.push_back(driver_row(name));
  }
}

std::vector<ParameterValue> numbers(const std::array<double, 6>& values) {
  return std::vector<ParameterValue>(values.begin(), values.end());
}

void add_odometry(std::vector<Binding>& out) {
  const NodeParameters& d = defaults();
  out.push_back(
      Row("odometry_source", T::kText, "", {}, std::string(to_string(d.driver.odometry.source)),
          "`wheels`: least-squares fit to the four wheel angles and speeds (0x271 + 0x281), "
          "falling back to 0x221 while those are missing; `motion`: 0x221 + 0x291 only")
          .choices({std::string(to_string(OdometrySource::kWheels)),
                    std::string(to_string(OdometrySource::kMotion))})
          .apply(RANGER_SET(driver.odometry.source, *parse_odometry_source(v.text))));
  out.push_back(driver_row("wheel_data_timeout"));
  const auto diagonal = [](std::array<double, 6> NodeParameters::*field) {
    return [field](NodeParameters& p, const ParameterValue& v) {
      for (std::size_t i = 0; i < v.items.size(); ++i)
        (p.*field)[i] = v.items[i].number;
      return ok_status();
    };
  };
  out.push_back(Row("pose_covariance_diagonal", T::kNumberList, "", kVariance,
                    numbers(d.pose_covariance_diagonal),
                    "x, y, z, roll, pitch, yaw: the floor of the pose covariance; the odometry "
                    "adds its growing x/y/yaw variance, and after a gap in the chassis's feedback "
                    "(a silence longer than 0.5 s the odometry cannot integrate) what the chassis "
                    "could have moved in it: (`max_linear_speed` × gap)² on x and y, (its fastest "
                    "turn × gap)² on yaw (at most π²); `system_state.odometry_gap` says how long "
                    "it was. Where the chassis counts its wheels' distance in metres (the RANGER "
                    "MINI 3.0's 0x311), the pose advances by what it counted in the gap, along "
                    "the motion before it")
                    .size(6)
                    .apply(diagonal(&NodeParameters::pose_covariance_diagonal)));
  out.push_back(Row("twist_covariance_diagonal", T::kNumberList, "", kVariance,
                    numbers(d.twist_covariance_diagonal), "published as the twist covariance")
                    .size(6)
                    .apply(diagonal(&NodeParameters::twist_covariance_diagonal)));
  for (const char* name :
       {"pose_variance_per_meter", "yaw_variance_per_radian", "yaw_variance_per_meter"}) {
    out.push_back(driver_row(name));
  }
}

void add_ultrasonic_and_sim(std::vector<Binding>& out) {
  const NodeParameters& d = defaults();
  const double max_raw = kMaxUltrasonicRange;
  out.push_back(Row("ultrasonic/field_of_view", T::kNumber, "rad", open_closed(0.0, M_PI),
                    d.ultrasonic.field_of_view, "sensor_msgs/Range `field_of_view` of every sensor")
                    .apply(RANGER_SET(ultrasonic.field_of_view, v.number)));
  out.push_back(Row("ultrasonic/min_range", T::kNumber, "m", closed(0.0, 10.0),
                    d.ultrasonic.min_range, "sensor_msgs/Range `min_range`")
                    .apply(RANGER_SET(ultrasonic.min_range, v.number)));
  out.push_back(Row("ultrasonic/max_range", T::kNumber, "m", open_closed(0.0, max_raw),
                    d.ultrasonic.max_range,
                    "sensor_msgs/Range `max_range`: a farther reading is +inf (REP-117)")
                    .valid("(`ultrasonic/min_range`, " + number_text(max_raw) + "] m")
                    .apply([max_raw](NodeParameters& p, const ParameterValue& v) {
                      if (v.number <= p.ultrasonic.min_range) {
                        return Status(problem("= " + shown(v) + " is out of range: valid (" +
                                              number_text(p.ultrasonic.min_range) + ", " +
                                              number_text(max_raw) + "] m"));
                      }
                      p.ultrasonic.max_range = v.number;
                      return ok_status();
                    }));
  const sim::VirtualChassisConfig& s = d.sim.chassis;
  out.push_back(
      Row("sim/initial_soc", T::kNumber, "%", closed(0.0, 100.0), s.initial_soc, "battery at boot")
          .apply(RANGER_SET(sim.chassis.initial_soc, v.number)));
  out.push_back(Row("sim/mode_switch_duration", T::kSeconds, "s", closed(0.0, 10.0),
                    std::chrono::duration<double>(s.mode_switch_duration).count(),
                    "how long a motion-mode switch takes (the manual's fixed-time switch; "
                    "not the field's, ranger_mini_v3, whose wheels turn at 3.26 rad/s)")
                    .apply(RANGER_SET(sim.chassis.mode_switch_duration, from_secs(v.number))));
  out.push_back(Row("sim/boot_in_remote_mode", T::kBool, "", {}, s.boot_in_remote_mode,
                    "boot with the remote control in charge")
                    .apply(RANGER_SET(sim.chassis.boot_in_remote_mode, v.boolean)));
  out.push_back(Row("sim/firmware_version", T::kText, "", {}, s.version,
                    "what the chassis answers the 0x4A1 version request with (variants with the "
                    "vendor's frames: `agx_v2`, `mini_v1`)")
                    .apply(RANGER_SET(sim.chassis.version, v.text)));
  out.push_back(Row("sim/ultrasonic_range", T::kNumber, "m", closed(0.0, max_raw),
                    s.ultrasonic[0] * interpretation::kUltrasonicMetresPerUnit,
                    "distance every sensor reports")
                    .apply([](NodeParameters& p, const ParameterValue& v) {
                      p.sim.chassis.ultrasonic.fill(static_cast<std::int16_t>(
                          std::lround(v.number / interpretation::kUltrasonicMetresPerUnit)));
                      return ok_status();
                    }));
  out.push_back(Row("sim/errors", T::kTextList, "", {}, std::vector<ParameterValue>{},
                    "faults the virtual chassis boots with (tests, demos)")
                    .valid("list of 0x211 error bits: names (the `ranger_msgs/SystemErrors` field "
                           "names) or indices in the error word of the port's variant (0-31; "
                           "agx_v2: 0-15)")
                    .apply(apply_sim_errors));
}

#undef RANGER_SET

const std::vector<Binding>& bindings() {
  static const std::vector<Binding> all = [] {
    std::vector<Binding> out;
    add_connection(out);
    add_control(out);
    add_protocol(out);
    add_geometry_and_limits(out);
    add_axes(out);
    add_odometry(out);
    add_ultrasonic_and_sim(out);
    return out;
  }();
  return all;
}

// ---- loading ------------------------------------------------------------------------------------

// Every problem, one line each, naming the parameter as the source shows it.
class Problems {
 public:
  explicit Problems(const ParameterSource& source) : source_(source) {}
  void fail(const std::string& name, const std::string& problem) {
    lines.push_back("parameter " + source_.display_name(name) + " " + problem);
  }
  std::vector<std::string> lines;

 private:
  const ParameterSource& source_;
};

// The model first: its geometry, limits and profile are the defaults of what follows.
ModelPreset read_model(const ParameterSource& source, NodeParameters& p, Problems& problems) {
  ModelPreset model = default_model();
  if (const auto raw = source.get("model")) {
    const auto v = check_parameter(*find_node_parameter("model"), *raw);
    if (!v) {
      problems.fail("model", v.error().message + " (libranger_can/models/)");
    } else {
      model = model_preset(v->text).value();
    }
  }
  apply_model(model, p);
  return model;
}

// Where the settings in use come from, in one line (ProtocolParameters::source).
std::string settings_source(const ProtocolParameters& pp, const std::vector<std::string>& forced) {
  const std::string on_model = "model " + pp.model;
  std::string out;
  if (!pp.commissioning_file.empty()) {
    out = "forced: commissioning file " + pp.commissioning_file;
    if (pp.protocol != "auto") out += " (it overrides protocol " + pp.protocol + ")";
  } else if (pp.protocol != "auto") {
    out = "forced: protocol " + pp.protocol + ", " + on_model;
  } else if (pp.auto_overridden) {
    out = "forced: protocol auto overridden by the interpretation parameters, " + on_model;
  } else {
    out = "auto: identified from the chassis, " + on_model;
  }
  if (!forced.empty()) out += ", with " + text::join(forced);
  return out;
}

// The profile: a commissioning file, else the model's on the revision `protocol` names (the
// model's own revision for auto: the fallback an identification starts from); then every
// interpretation parameter. Whether the driver identifies it.
void resolve_protocol(const ModelPreset& model, NodeParameters& p, Problems& problems) {
  ProtocolParameters& pp = p.protocol;
  ProtocolProfile profile = model.profile;
  if (!pp.commissioning_file.empty()) {
    if (auto loaded = load_commissioning_file(pp.commissioning_file)) {
      profile = *loaded;
    } else {
      problems.fail("commissioning_file",
                    "= \"" + pp.commissioning_file + "\": " + loaded.error().message);
    }
  } else if (pp.protocol != "auto") {
    if (auto m = model_profile(model, pp.protocol)) profile = *m;
  }
  std::vector<std::string> forced;
  for (const auto& [name, value] : pp.settings) {
    if (Status st = set_setting(profile, name, value); !st) problems.fail(name, st.error().message);
    forced.push_back(name + ": " + value);
  }
  p.driver.controller.profile = profile;
  // The driver identifies a whole profile; it cannot keep single settings forced on top of it.
  // Set settings win: the profile is forced, and the start-up log says so.
  pp.auto_overridden =
      pp.commissioning_file.empty() && pp.protocol == "auto" && !pp.settings.empty();
  p.driver.protocol = pp.commissioning_file.empty() && pp.protocol == "auto" && !pp.auto_overridden
                          ? ProtocolChoice::kAuto
                          : ProtocolChoice::kForced;
  pp.source = settings_source(pp, forced);
}

// What the rows cannot say alone, and the copies of the geometry.
void finish(NodeParameters& p, Problems& problems) {
  if (p.odom_frame == p.base_frame) {
    problems.fail("base_frame", "= \"" + p.base_frame + "\" must differ from odom_frame");
  }
  auto& d = p.driver;
  d.odometry.geometry = d.controller.geometry;
  p.sim.chassis.geometry = d.controller.geometry;
  // The node adds the pose covariance's floor; the library models only the growth.
  d.odometry.initial_pose_variance_xy = 0.0;
  d.odometry.initial_pose_variance_yaw = 0.0;
}

}  // namespace

bool NodeParameters::is_sim() const {
  const auto kind = bus_kind(port_name);
  return kind && *kind == BusKind::kSim;
}

const std::vector<Parameter>& node_parameters() {
  static const std::vector<Parameter> rows = [] {
    std::vector<Parameter> out;
    for (const Binding& b : bindings())
      out.push_back(b.row);
    return out;
  }();
  return rows;
}

const Parameter* find_node_parameter(std::string_view name) {
  for (const Parameter& p : node_parameters()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

const std::vector<std::string>& known_parameter_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Parameter& p : node_parameters())
      out.push_back(p.name);
    return out;
  }();
  return names;
}

Result<NodeParameters> load_parameters(const ParameterSource& source) {
  Problems problems(source);
  NodeParameters p;
  const ModelPreset model = read_model(source, p, problems);
  // The loop: every row the source sets, checked against the row, then applied.
  for (const Binding& b : bindings()) {
    if (!b.apply) continue;  // the model, read first
    const auto raw = source.get(b.row.name);
    if (!raw) continue;
    const auto v = check_parameter(b.row, *raw);
    if (!v) {
      problems.fail(b.row.name, v.error().message);
    } else if (Status st = b.apply(p, *v); !st) {
      problems.fail(b.row.name, st.error().message);
    }
  }
  resolve_protocol(model, p, problems);
  finish(p, problems);
  // The library's own checks catch combinations the per-parameter ranges cannot (hysteresis
  // thresholds in the wrong order, ...).
  if (problems.lines.empty()) {
    if (Status st = p.driver.validate(); !st) {
      problems.lines.push_back("parameters rejected: " + st.error().message);
    }
  }
  if (problems.lines.empty()) return p;
  return Error{Errc::kInvalidArgument, text::join(problems.lines, "\n")};
}

std::vector<std::string> unknown_parameter_names(const ParameterSource& source,
                                                 const std::vector<std::string>& also_read) {
  const auto& known = known_parameter_names();
  std::set<std::string> known_set(known.begin(), known.end());
  known_set.insert(also_read.begin(), also_read.end());
  std::vector<std::string> out;
  for (const auto& n : source.names()) {
    if (n.rfind("description/", 0) == 0) continue;  // the URDF's part of geometry.yaml
    if (known_set.count(n) == 0) out.push_back(n);
  }
  return out;
}

std::vector<std::string> parameter_problems(const ParameterSource& source,
                                            const std::vector<std::string>& also_read) {
  std::vector<std::string> out;
  for (const auto& name : unknown_parameter_names(source, also_read)) {
    out.push_back("parameter " + source.display_name(name) +
                  " is not one ranger_base_node reads (ranger_base/README.md lists them)");
  }
  if (const auto params = load_parameters(source); !params) {
    out.push_back(params.error().message);
  }
  return out;
}

}  // namespace ranger
