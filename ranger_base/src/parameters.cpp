#include "ranger_base/parameters.hpp"

#include <ros/node_handle.h>
#include <ros/param.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <set>
#include <sstream>

#include <ranger_can/control/commissioning.hpp>
#include <ranger_can/control/parameters.hpp>
#include <ranger_can/sim/chassis_commands.hpp>
#include <ranger_can/text.hpp>
#include <ranger_can/transport/bus_source.hpp>

namespace ranger_base {
namespace {

using std::chrono::duration;
using std::chrono::duration_cast;
using std::chrono::nanoseconds;

// A closed or half-open interval, printed the way the error messages show valid ranges.
struct Interval {
  double lo;
  double hi;
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string describe(const std::string& unit) const {
    std::ostringstream out;
    out << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
    if (!unit.empty()) out << ' ' << unit;
    return out.str();
  }
};
Interval closed(double lo, double hi) {
  return {lo, hi, false, false};
}
Interval open_closed(double lo, double hi) {
  return {lo, hi, true, false};
}

std::string show(const XmlRpc::XmlRpcValue& v) {
  XmlRpc::XmlRpcValue copy = v;  // toXml() is not const
  switch (copy.getType()) {
    case XmlRpc::XmlRpcValue::TypeString:
      return "\"" + static_cast<std::string&>(copy) + "\"";
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool&>(copy) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int&>(copy));
    case XmlRpc::XmlRpcValue::TypeDouble: {
      std::ostringstream out;
      out << static_cast<double&>(copy);
      return out.str();
    }
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list of " + std::to_string(copy.size());
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "a dictionary";
    default:
      return "a value of another type";
  }
}

using ranger::text::join;

std::optional<double> as_number(const XmlRpc::XmlRpcValue& v) {
  XmlRpc::XmlRpcValue copy = v;
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double&>(copy);
  if (copy.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int&>(copy);
  return std::nullopt;
}

// Reads parameters one by one, collecting every problem instead of stopping at the first.
class Reader {
 public:
  explicit Reader(const ParameterSource& source) : source_(source) {}

  double number(const std::string& name, double def, Interval valid, const std::string& unit) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return def;
    const auto v = as_number(*raw);
    if (!v) {
      fail(name, "= " + show(*raw) + ": expected a number in " + valid.describe(unit));
      return def;
    }
    if (!std::isfinite(*v) || !valid.contains(*v)) {
      fail(name, "= " + show(*raw) + " is out of range: valid " + valid.describe(unit));
      return def;
    }
    return *v;
  }

  int integer(const std::string& name, int def, int lo, int hi) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return def;
    XmlRpc::XmlRpcValue copy = *raw;
    const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (copy.getType() != XmlRpc::XmlRpcValue::TypeInt) {
      fail(name, "= " + show(*raw) + ": expected an integer in " + range);
      return def;
    }
    const int v = static_cast<int&>(copy);
    if (v < lo || v > hi) {
      fail(name, "= " + show(*raw) + " is out of range: valid " + range);
      return def;
    }
    return v;
  }

  nanoseconds seconds(const std::string& name, nanoseconds def, Interval valid) {
    const double s = number(name, duration<double>(def).count(), valid, "s");
    return duration_cast<nanoseconds>(duration<double>(s));
  }

  bool flag(const std::string& name, bool def) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return def;
    XmlRpc::XmlRpcValue copy = *raw;
    if (copy.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
      fail(name, "= " + show(*raw) + ": expected true or false");
      return def;
    }
    return static_cast<bool&>(copy);
  }

  std::string text(const std::string& name, const std::string& def) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return def;
    XmlRpc::XmlRpcValue copy = *raw;
    if (copy.getType() != XmlRpc::XmlRpcValue::TypeString) {
      fail(name, "= " + show(*raw) + ": expected a string");
      return def;
    }
    return static_cast<std::string&>(copy);
  }

  // A value that may be given as a string, a number or a bool (an interpretation setting:
  // `tx_dlc: 8`, `bms_voltage_scale: 0.1`, `vehicle_status_1_is_estop: true`), as text; nullopt
  // when unset. Lists and dictionaries are reported.
  std::optional<std::string> scalar_text(const std::string& name, const std::string& expected) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return std::nullopt;
    XmlRpc::XmlRpcValue copy = *raw;
    switch (copy.getType()) {
      case XmlRpc::XmlRpcValue::TypeString:
        return static_cast<std::string&>(copy);
      case XmlRpc::XmlRpcValue::TypeBoolean:
      case XmlRpc::XmlRpcValue::TypeInt:
      case XmlRpc::XmlRpcValue::TypeDouble:
        return show(*raw);
      default:
        fail(name, "= " + show(*raw) + ": expected " + expected);
        return std::nullopt;
    }
  }

  // A row of the library's parameter table (ranger_can/control/parameters.hpp): its type, range
  // and unit from the table, its default the value `config` holds.
  void driver_parameter(const ranger::DriverParameter& row, ranger::DriverConfig& config) {
    const std::string name(row.name);
    if (!source_.get(name)) {
      names_.push_back(name);
      return;
    }
    const ranger::ParameterRange& range = row.range;
    const double now = row.get(config);
    switch (row.type) {
      case ranger::ParameterType::kBool:
        row.set(config, flag(name, now != 0.0) ? 1.0 : 0.0);
        break;
      case ranger::ParameterType::kInteger:
        row.set(config, integer(name, static_cast<int>(now), static_cast<int>(range.lo),
                                static_cast<int>(range.hi)));
        break;
      case ranger::ParameterType::kNumber:
      case ranger::ParameterType::kSeconds:
        row.set(config, number(name, now, {range.lo, range.hi, range.lo_open, range.hi_open},
                               std::string(row.unit)));
        break;
    }
  }

  // A tf2 frame id: non-empty, no whitespace, no leading '/'.
  std::string frame(const std::string& name, const std::string& def) {
    std::string v = text(name, def);
    const bool has_space =
        std::any_of(v.begin(), v.end(), [](unsigned char c) { return std::isspace(c) != 0; });
    if (v.empty() || has_space || v.front() == '/') {
      fail(name, "= \"" + v + "\": expected a tf2 frame id (non-empty, no spaces, no leading '/')");
      return def;
    }
    return v;
  }

  std::array<double, 6> diagonal(const std::string& name, const std::array<double, 6>& def) {
    names_.push_back(name);
    const auto raw = source_.get(name);
    if (!raw) return def;
    XmlRpc::XmlRpcValue copy = *raw;
    const std::string expected =
        ": expected a list of 6 variances >= 0 (x, y, z, roll, pitch, yaw)";
    if (copy.getType() != XmlRpc::XmlRpcValue::TypeArray || copy.size() != 6) {
      fail(name, "= " + show(*raw) + expected);
      return def;
    }
    std::array<double, 6> out{};
    for (int i = 0; i < 6; ++i) {
      const auto v = as_number(copy[i]);
      if (!v || !std::isfinite(*v) || *v < 0.0) {
        fail(name, "[" + std::to_string(i) + "] = " + show(copy[i]) + expected);
        return def;
      }
      out[static_cast<std::size_t>(i)] = *v;
    }
    return out;
  }

  std::vector<std::string> text_list(const std::string& name) {
    names_.push_back(name);
    std::vector<std::string> out;
    const auto raw = source_.get(name);
    if (!raw) return out;
    XmlRpc::XmlRpcValue copy = *raw;
    if (copy.getType() != XmlRpc::XmlRpcValue::TypeArray) {
      fail(name, "= " + show(*raw) + ": expected a list of strings");
      return out;
    }
    for (int i = 0; i < copy.size(); ++i) {
      if (copy[i].getType() != XmlRpc::XmlRpcValue::TypeString) {
        fail(name, "[" + std::to_string(i) + "] = " + show(copy[i]) + ": expected a string");
        return {};
      }
      out.push_back(static_cast<std::string&>(copy[i]));
    }
    return out;
  }

  void fail(const std::string& name, const std::string& problem) {
    errors_.push_back("parameter " + source_.display_name(name) + " " + problem);
  }

  const std::vector<std::string>& errors() const { return errors_; }
  const std::vector<std::string>& names() const { return names_; }

 private:
  const ParameterSource& source_;
  std::vector<std::string> errors_;
  std::vector<std::string> names_;
};

// ros_controllers' per-axis limits (diff_drive_controller's SpeedLimiter parameters): defaults
// from the library's SpeedLimits{} (as SpeedLimiter's: 0, limits off); a missing min_* defaults
// to -max_*.
ranger::SpeedLimits read_speed_limits(Reader& r, const std::string& axis, const std::string& unit,
                                      double max_velocity_bound) {
  ranger::SpeedLimits l;
  const std::string vel_unit = unit + "/s", acc_unit = unit + "/s^2";
  l.has_velocity_limits = r.flag(axis + "/has_velocity_limits", l.has_velocity_limits);
  l.max_velocity =
      r.number(axis + "/max_velocity", l.max_velocity, closed(0.0, max_velocity_bound), vel_unit);
  l.min_velocity = r.number(axis + "/min_velocity", -l.max_velocity,
                            closed(-max_velocity_bound, l.max_velocity), vel_unit);
  l.has_acceleration_limits = r.flag(axis + "/has_acceleration_limits", l.has_acceleration_limits);
  l.max_acceleration =
      r.number(axis + "/max_acceleration", l.max_acceleration, open_closed(0.0, 1000.0), acc_unit);
  l.min_acceleration = r.number(axis + "/min_acceleration", -l.max_acceleration,
                                Interval{-1000.0, 0.0, false, true}, acc_unit);
  return l;
}

// A port_name: what ranger::sim::open_bus_source accepts.
void check_port_name(Reader& r, const std::string& port) {
  const std::string forms =
      "expected a CAN interface name (1-15 characters, e.g. can0, vcan0), sim[:VARIANT] (the "
      "in-process virtual chassis; variants: " +
      [] {
        std::string v;
        for (const auto& n : ranger::sim::variant_names())
          v += (v.empty() ? "" : ", ") + n;
        return v;
      }() +
      ") or replay:FILE (a candump log, read-only)";
  const auto kind = ranger::bus_kind(port);
  if (!kind) {
    r.fail("port_name", "= \"" + port + "\": " + forms);
    return;
  }
  if (*kind == ranger::BusKind::kSocketCan && port.find_first_of("/ \t:") != std::string::npos) {
    r.fail("port_name", "= \"" + port + "\": " + forms);
  } else if (*kind == ranger::BusKind::kSim && port.size() > 3) {
    if (auto v = ranger::sim::apply_variant(port.substr(4), {}); !v) {
      r.fail("port_name", "= \"" + port + "\": " + v.error().message);
    }
  }
}

// The protocol settings: `protocol`, `commissioning_file`, one parameter per interpretation
// setting and `identify_timeout`, resolved into DriverConfig::protocol and controller.profile.
void read_protocol(Reader& r, const ranger::ModelPreset& model, NodeParameters& p) {
  auto& pp = p.protocol;
  auto& d = p.driver;

  std::vector<std::string> choices = {"auto"};
  for (const auto& n : ranger::protocol_revision_names())
    choices.push_back(n);
  pp.protocol = r.text("protocol", pp.protocol);
  const bool known_protocol =
      std::find(choices.begin(), choices.end(), pp.protocol) != choices.end();
  if (!known_protocol) {
    r.fail("protocol", "= \"" + pp.protocol + "\": expected one of " + join(choices) +
                           " (auto: identified from the chassis before anything moves)");
  }

  pp.commissioning_file = r.text("commissioning_file", pp.commissioning_file);
  std::optional<ranger::ProtocolProfile> commissioned;
  if (!pp.commissioning_file.empty()) {
    auto loaded = ranger::load_commissioning_file(pp.commissioning_file);
    if (loaded) {
      commissioned = *loaded;
    } else {
      r.fail("commissioning_file",
             "= \"" + pp.commissioning_file + "\": " + loaded.error().message);
    }
  }

  // One parameter per interpretation setting, checked against the settings table: they force
  // that setting after whatever the profile started from.
  for (const ranger::ProfileSetting& s : ranger::profile_settings()) {
    const std::string name(s.name);
    std::vector<std::string> values(s.values.begin(), s.values.end());
    const auto value = r.scalar_text(name, "one of " + join(values));
    if (!value) continue;
    ranger::ProtocolProfile scratch;
    if (!ranger::set_setting(scratch, name, *value)) {
      r.fail(name, "= \"" + *value + "\": expected one of " + join(values) + " (" +
                       std::string(s.description) + ")");
      continue;
    }
    pp.settings.emplace_back(name, *value);
  }

  // The profile: a commissioning file, else the model's on the revision `protocol` names (the
  // model's own revision for auto: the fallback an identification starts from); then every
  // interpretation parameter.
  ranger::ProtocolProfile profile = model.profile;
  if (commissioned) {
    profile = *commissioned;
  } else if (known_protocol && pp.protocol != "auto") {
    if (auto m = ranger::model_profile(model, pp.protocol)) profile = *m;
  }
  std::vector<std::string> forced;
  for (const auto& [name, value] : pp.settings) {
    (void)ranger::set_setting(profile, name, value);  // checked above
    forced.push_back(name + ": " + value);
  }
  d.controller.profile = profile;

  const std::string on_model = "model " + pp.model;
  if (!pp.commissioning_file.empty()) {
    d.protocol = ranger::ProtocolChoice::kForced;
    pp.source = "forced: commissioning file " + pp.commissioning_file;
    if (pp.protocol != "auto") pp.source += " (it overrides protocol " + pp.protocol + ")";
  } else if (pp.protocol != "auto") {
    d.protocol = ranger::ProtocolChoice::kForced;
    pp.source = "forced: protocol " + pp.protocol + ", " + on_model;
  } else if (!pp.settings.empty()) {
    // The driver identifies a whole profile; it cannot keep single settings forced on top of
    // it. Set settings win: the profile is forced, and the start-up log says so.
    d.protocol = ranger::ProtocolChoice::kForced;
    pp.auto_overridden = true;
    pp.source = "forced: protocol auto overridden by the interpretation parameters, " + on_model;
  } else {
    d.protocol = ranger::ProtocolChoice::kAuto;
    pp.source = "auto: identified from the chassis, " + on_model;
  }
  if (!forced.empty()) pp.source += ", with " + join(forced);
}

// Reads everything; `r` collects the problems.
NodeParameters read_all(Reader& r) {
  NodeParameters p;
  auto& c = p.driver.controller;
  auto& o = p.driver.odometry;

  // ---- connection and frames
  p.port_name = r.text("port_name", p.port_name);
  check_port_name(r, p.port_name);
  p.odom_frame = r.frame("odom_frame", p.odom_frame);
  p.base_frame = r.frame("base_frame", p.base_frame);
  if (p.odom_frame == p.base_frame) {
    r.fail("base_frame", "= \"" + p.base_frame + "\" must differ from odom_frame");
  }
  p.frame_prefix = r.text("frame_prefix", p.frame_prefix);
  if (p.frame_prefix.find_first_of(" \t") != std::string::npos ||
      (!p.frame_prefix.empty() && p.frame_prefix.front() == '/')) {
    r.fail("frame_prefix", "= \"" + p.frame_prefix +
                               "\": expected a tf2 frame prefix such as \"robot1/\" (no spaces, "
                               "no leading '/')");
  }
  p.publish_odom_tf = r.flag("publish_odom_tf", p.publish_odom_tf);
  // The chassis reports its motion every 20 ms: a higher rate would have no estimate to publish.
  p.publish_rate = r.number("publish_rate", p.publish_rate, open_closed(0.0, 50.0), "Hz");
  p.state_publish_rate =
      r.number("state_publish_rate", p.state_publish_rate, open_closed(0.0, 100.0), "Hz");
  p.publish_cmd = r.flag("publish_cmd", p.publish_cmd);

  // ---- the vehicle model: its geometry, limits and protocol profile are the defaults of the
  // geometry and limit parameters below and of the protocol settings; the virtual chassis (port
  // sim[:VARIANT]) is that model.
  auto& pp = p.protocol;
  pp.model = r.text("model", pp.model);
  ranger::ModelPreset model = ranger::model_preset("ranger").value();
  if (auto m = ranger::model_preset(pp.model)) {
    model = *m;
  } else {
    r.fail("model", "= \"" + pp.model + "\": expected one of " + join(ranger::model_names()) +
                        " (libranger_can/models/)");
  }
  pp.model_display_name = model.display_name;
  pp.model_settings = model.settings;
  c.limits = model.limits;
  p.sim.chassis = ranger::sim::chassis_for_model(model, p.sim.chassis);

  // ---- the library's parameter table: control, identify_timeout, reconnect_interval, automatic
  // motion-mode selection, odometry timing and variance growth (ranger_can/control/parameters.hpp)
  for (const ranger::DriverParameter& row : ranger::driver_parameters())
    r.driver_parameter(row, p.driver);

  // ---- geometry (the model's; ranger_description/config/geometry.yaml for the RANGER)
  ranger::VehicleGeometry g = model.geometry;
  g.wheelbase = r.number("wheelbase", g.wheelbase, open_closed(0.0, 10.0), "m");
  g.track = r.number("track", g.track, open_closed(0.0, 10.0), "m");
  g.wheel_radius = r.number("wheel_radius", g.wheel_radius, open_closed(0.0, 5.0), "m");
  c.geometry = g;
  o.geometry = g;
  p.sim.chassis.geometry = g;

  // ---- kinematic limits: the library's defaults are the protocol's full ranges for steering and
  // spin; its KinematicsLimits::validate() knows the speed range.
  auto& k = c.limits;
  const ranger::KinematicsLimits full;
  const auto degrees = [](double rad) {
    std::ostringstream out;
    out << "rad (" << std::lround(ranger::rad_to_deg(rad)) << " deg)";
    return out.str();
  };
  const auto speed_limit = [&r](const std::string& name, double& field) {
    const double v = r.number(name, field, open_closed(0.0, 1e3), "m/s");
    ranger::KinematicsLimits probe;
    (name == "max_linear_speed" ? probe.max_linear_speed : probe.max_speed_at_large_steering) = v;
    if (const auto st = probe.validate(); !st) {
      r.fail(name, "is out of range: " + st.error().message + " m/s");
    } else {
      field = v;
    }
  };
  speed_limit("max_linear_speed", k.max_linear_speed);
  speed_limit("max_speed_at_large_steering", k.max_speed_at_large_steering);
  k.max_ackermann_steering =
      r.number("max_ackermann_steering", k.max_ackermann_steering,
               open_closed(0.0, full.max_ackermann_steering), degrees(full.max_ackermann_steering));
  k.max_oblique_steering =
      r.number("max_oblique_steering", k.max_oblique_steering,
               open_closed(0.0, full.max_oblique_steering), degrees(full.max_oblique_steering));
  k.max_spin_wheel_speed = r.number("max_spin_wheel_speed", k.max_spin_wheel_speed,
                                    open_closed(0.0, full.max_spin_wheel_speed), "m/s");

  // ---- velocity / acceleration limits per axis (ros_controllers names)
  c.limit_vx = read_speed_limits(r, "linear/x", "m", 10.0);
  c.limit_vy = read_speed_limits(r, "linear/y", "m", 10.0);
  c.limit_wz = read_speed_limits(r, "angular/z", "rad", 10.0);

  // ---- odometry
  const std::string source = r.text("odometry_source", std::string(ranger::to_string(o.source)));
  if (auto parsed = ranger::parse_odometry_source(source)) {
    o.source = *parsed;
  } else {
    r.fail("odometry_source", "= \"" + source + "\": expected \"wheels\" or \"motion\"");
  }
  p.pose_covariance_diagonal = r.diagonal("pose_covariance_diagonal", p.pose_covariance_diagonal);
  p.twist_covariance_diagonal =
      r.diagonal("twist_covariance_diagonal", p.twist_covariance_diagonal);
  // The node adds the floor above; the library models only the growth.
  o.initial_pose_variance_xy = 0.0;
  o.initial_pose_variance_yaw = 0.0;

  // ---- ultrasonic as sensor_msgs/Range
  auto& u = p.ultrasonic;
  u.field_of_view =
      r.number("ultrasonic/field_of_view", u.field_of_view, open_closed(0.0, M_PI), "rad");
  u.min_range = r.number("ultrasonic/min_range", u.min_range, closed(0.0, 10.0), "m");
  u.max_range = r.number("ultrasonic/max_range", u.max_range,
                         Interval{u.min_range, 32.767, true, false}, "m");

  // ---- the in-process virtual chassis (port_name sim[:VARIANT])
  auto& s = p.sim.chassis;
  s.initial_soc = r.number("sim/initial_soc", s.initial_soc, closed(0.0, 100.0), "%");
  s.mode_switch_duration =
      r.seconds("sim/mode_switch_duration", s.mode_switch_duration, closed(0.0, 10.0));
  s.boot_in_remote_mode = r.flag("sim/boot_in_remote_mode", s.boot_in_remote_mode);
  s.version = r.text("sim/firmware_version", s.version);
  const double ultrasonic_m =
      r.number("sim/ultrasonic_range", s.ultrasonic[0] / 1000.0, closed(0.0, 32.767), "m");
  s.ultrasonic.fill(static_cast<std::int16_t>(std::lround(ultrasonic_m * 1000.0)));
  // Error bits by index or name, in the error-word layout of the port's variant.
  ranger::ErrorWordLayout layout = s.profile.error_word;
  if (const auto kind = ranger::bus_kind(p.port_name);
      kind && *kind == ranger::BusKind::kSim && p.port_name.size() > 4) {
    if (auto v = ranger::sim::apply_variant(p.port_name.substr(4), {}))
      layout = v->profile.error_word;
  }
  for (const auto& name : r.text_list("sim/errors")) {
    if (auto bit = ranger::sim::parse_error_bit(name, layout)) {
      p.sim.boot_error_bits |= 1u << *bit;
    } else {
      r.fail("sim/errors", "contains \"" + name + "\": " + bit.error().message);
    }
  }

  read_protocol(r, model, p);
  return p;
}

}  // namespace

NodeHandleParameterSource::NodeHandleParameterSource(const ros::NodeHandle& private_nh)
    : nh_(private_nh) {}

std::optional<XmlRpc::XmlRpcValue> NodeHandleParameterSource::get(const std::string& name) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return std::nullopt;
  return v;
}

std::string NodeHandleParameterSource::display_name(const std::string& name) const {
  return nh_.resolveName(name);
}

std::vector<std::string> NodeHandleParameterSource::names() const {
  std::vector<std::string> all, out;
  if (!ros::param::getParamNames(all)) return out;
  std::string prefix = nh_.getNamespace();
  if (prefix.empty() || prefix.back() != '/') prefix += '/';
  for (const auto& n : all) {
    if (n.compare(0, prefix.size(), prefix) == 0) out.push_back(n.substr(prefix.size()));
  }
  return out;
}

std::optional<XmlRpc::XmlRpcValue> MapParameterSource::get(const std::string& name) const {
  const auto it = values.find(name);
  if (it == values.end()) return std::nullopt;
  return it->second;
}

std::vector<std::string> MapParameterSource::names() const {
  std::vector<std::string> out;
  for (const auto& kv : values)
    out.push_back(kv.first);
  return out;
}

bool NodeParameters::is_sim() const {
  const auto kind = ranger::bus_kind(port_name);
  return kind && *kind == ranger::BusKind::kSim;
}

std::string hardware_id(const std::string& ns, const std::string& port_name) {
  return "ranger:" + (ns.empty() ? std::string("/") : ns) + ":" + port_name;
}

ranger::Result<NodeParameters> load_parameters(const ParameterSource& source) {
  Reader reader(source);
  NodeParameters p = read_all(reader);
  std::vector<std::string> errors = reader.errors();

  // The library's own checks catch combinations the per-parameter ranges cannot (e.g.
  // min_velocity above max_velocity after defaults, hysteresis thresholds in the wrong order).
  if (errors.empty()) {
    if (auto st = p.driver.validate(); !st) {
      errors.push_back("parameters rejected: " + st.error().message);
    }
  }
  if (errors.empty()) return p;
  std::string message;
  for (const auto& e : errors)
    message += (message.empty() ? "" : "\n") + e;
  return ranger::Error{ranger::Errc::kInvalidArgument, message};
}

const std::vector<std::string>& known_parameter_names() {
  static const std::vector<std::string> names = [] {
    MapParameterSource empty;
    Reader reader(empty);
    read_all(reader);
    return reader.names();
  }();
  return names;
}

std::vector<std::string> unknown_parameter_names(const ParameterSource& source) {
  const auto& known = known_parameter_names();
  const std::set<std::string> known_set(known.begin(), known.end());
  std::vector<std::string> out;
  for (const auto& n : source.names()) {
    if (n.rfind("description/", 0) == 0) continue;  // the URDF's part of geometry.yaml
    if (n == "diagnostic_period") continue;         // read by diagnostic_updater
    if (known_set.count(n) == 0) out.push_back(n);
  }
  return out;
}

}  // namespace ranger_base
