#include "options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>

#include "ranger_can/control/commissioning.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus_source.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::python {
namespace {

using text::join;

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string range_text(double lo, double hi, bool lo_open, bool hi_open, const std::string& unit) {
  std::string s = std::string(lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) +
                  (hi_open ? ")" : "]");
  return unit.empty() ? s : s + " " + unit;
}

std::string show(const Value& v) {
  struct Visitor {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const { return number_text(d); }
    std::string operator()(const std::string& s) const { return "\"" + s + "\""; }
    std::string operator()(const std::vector<double>& l) const {
      return "a list of " + std::to_string(l.size());
    }
    std::string operator()(const std::vector<std::string>& l) const {
      return "a list of " + std::to_string(l.size());
    }
  };
  return std::visit(Visitor{}, v);
}

// Reads values one by one, collecting every problem instead of stopping at the first.
class Reader {
 public:
  Reader(const std::map<std::string, Value>& values, std::string prefix)
      : values_(values), prefix_(std::move(prefix)) {}

  const Value* get(const std::string& name) {
    used_.insert(name);
    const auto it = values_.find(name);
    return it == values_.end() ? nullptr : &it->second;
  }

  double number(const std::string& name, double def, double lo, double hi, bool lo_open,
                bool hi_open, const std::string& unit) {
    const Value* raw = get(name);
    if (!raw) return def;
    const std::string valid = range_text(lo, hi, lo_open, hi_open, unit);
    double v = 0.0;
    if (const auto* d = std::get_if<double>(raw)) {
      v = *d;
    } else if (const auto* i = std::get_if<std::int64_t>(raw)) {
      v = static_cast<double>(*i);
    } else {
      fail(name, "= " + show(*raw) + ": expected a number in " + valid);
      return def;
    }
    const bool inside = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (!std::isfinite(v) || !inside) {
      fail(name, "= " + show(*raw) + " is out of range: valid " + valid);
      return def;
    }
    return v;
  }

  bool flag(const std::string& name, bool def) {
    const Value* raw = get(name);
    if (!raw) return def;
    if (const auto* b = std::get_if<bool>(raw)) return *b;
    fail(name, "= " + show(*raw) + ": expected true or false");
    return def;
  }

  std::string text(const std::string& name, const std::string& def) {
    const Value* raw = get(name);
    if (!raw) return def;
    if (const auto* s = std::get_if<std::string>(raw)) return *s;
    fail(name, "= " + show(*raw) + ": expected a string");
    return def;
  }

  // A setting given as a string, a number or a bool (`tx_dlc: 8`), as text; "" when unset.
  std::string scalar_text(const std::string& name, const std::string& expected) {
    const Value* raw = get(name);
    if (!raw) return "";
    if (const auto* s = std::get_if<std::string>(raw)) return *s;
    if (std::holds_alternative<std::vector<double>>(*raw) ||
        std::holds_alternative<std::vector<std::string>>(*raw)) {
      fail(name, "= " + show(*raw) + ": expected " + expected);
      return "";
    }
    return show(*raw);
  }

  std::vector<std::string> text_list(const std::string& name) {
    const Value* raw = get(name);
    if (!raw) return {};
    if (const auto* l = std::get_if<std::vector<std::string>>(raw)) return *l;
    if (const auto* l = std::get_if<std::vector<double>>(raw); l && l->empty()) return {};
    fail(name, "= " + show(*raw) + ": expected a list of strings");
    return {};
  }

  // A row of the library's parameter table: its range, unit and type from the table.
  void driver_parameter(const DriverParameter& row, DriverConfig& config) {
    const std::string name(row.name);
    const Value* raw = get(name);
    if (!raw) return;
    const double now = row.get(config);
    const ParameterRange& r = row.range;
    switch (row.type) {
      case ParameterType::kBool:
        row.set(config, flag(name, now != 0.0) ? 1.0 : 0.0);
        break;
      case ParameterType::kInteger: {
        const std::string range = "[" + number_text(r.lo) + ", " + number_text(r.hi) + "]";
        const auto* i = std::get_if<std::int64_t>(raw);
        if (!i) {
          fail(name, "= " + show(*raw) + ": expected an integer in " + range);
        } else if (static_cast<double>(*i) < r.lo || static_cast<double>(*i) > r.hi) {
          fail(name, "= " + show(*raw) + " is out of range: valid " + range);
        } else {
          row.set(config, static_cast<double>(*i));
        }
        break;
      }
      case ParameterType::kNumber:
      case ParameterType::kSeconds:
        row.set(config, number(name, now, r.lo, r.hi, r.lo_open, r.hi_open, std::string(row.unit)));
        break;
      case ParameterType::kText:  // a node's rows (frontend/node_parameters.hpp), no driver row
      case ParameterType::kChoice:
      case ParameterType::kNumberList:
      case ParameterType::kTextList:
        break;
    }
  }

  void fail(const std::string& name, const std::string& problem) {
    errors_.push_back("parameter " + prefix_ + name + " " + problem);
  }

  // Every name given that no row read.
  void report_unknown() {
    for (const auto& [name, value] : values_) {
      if (used_.count(name) == 0) {
        errors_.push_back("parameter " + prefix_ + name +
                          " unknown (ranger_can.parameters() lists the names)");
      }
    }
  }

  const std::vector<std::string>& errors() const { return errors_; }

 private:
  const std::map<std::string, Value>& values_;
  std::string prefix_;
  std::set<std::string> used_;
  std::vector<std::string> errors_;
};

// The kinematic limits' rows: name, the protocol's full range (upper bound), unit.
struct LimitRow {
  const char* name;
  double KinematicsLimits::*field;
  const char* unit;
  const char* meaning;
};
const LimitRow kLimitRows[] = {
    {"max_linear_speed", &KinematicsLimits::max_linear_speed, "m/s",
     "body speed in Ackermann and oblique mode"},
    {"max_speed_at_large_steering", &KinematicsLimits::max_speed_at_large_steering, "m/s",
     "speed limit while steering beyond 20 deg"},
    {"max_ackermann_steering", &KinematicsLimits::max_ackermann_steering, "rad",
     "mean front-wheel angle in Ackermann mode"},
    {"max_oblique_steering", &KinematicsLimits::max_oblique_steering, "rad",
     "direction of travel in oblique mode"},
    {"max_spin_wheel_speed", &KinematicsLimits::max_spin_wheel_speed, "m/s",
     "wheel speed in spin mode"},
};
struct GeometryRow {
  const char* name;
  double VehicleGeometry::*field;
  double hi;
  const char* meaning;
};
const GeometryRow kGeometryRows[] = {
    {"wheelbase", &VehicleGeometry::wheelbase, 10.0, "front axle to rear axle"},
    {"track", &VehicleGeometry::track, 10.0, "left to right wheel centre"},
    {"wheel_radius", &VehicleGeometry::wheel_radius, 5.0, "for the wheel joint angles"},
};
struct AxisRow {
  const char* axis;
  SpeedLimits ControllerConfig::*field;
  const char* unit;
};
const AxisRow kAxisRows[] = {{"linear/x", &ControllerConfig::limit_vx, "m"},
                             {"linear/y", &ControllerConfig::limit_vy, "m"},
                             {"angular/z", &ControllerConfig::limit_wz, "rad"}};
constexpr double kMaxAxisVelocity = 10.0;
constexpr double kMaxAxisAcceleration = 1000.0;

SpeedLimits read_axis(Reader& r, const std::string& axis, const std::string& unit) {
  SpeedLimits l;
  const std::string vel = unit + "/s", acc = unit + "/s^2";
  l.has_velocity_limits = r.flag(axis + "/has_velocity_limits", l.has_velocity_limits);
  l.max_velocity =
      r.number(axis + "/max_velocity", l.max_velocity, 0.0, kMaxAxisVelocity, false, false, vel);
  l.min_velocity = r.number(axis + "/min_velocity", -l.max_velocity, -kMaxAxisVelocity,
                            l.max_velocity, false, false, vel);
  l.has_acceleration_limits = r.flag(axis + "/has_acceleration_limits", l.has_acceleration_limits);
  l.max_acceleration = r.number(axis + "/max_acceleration", l.max_acceleration, 0.0,
                                kMaxAxisAcceleration, true, false, acc);
  l.min_acceleration = r.number(axis + "/min_acceleration", -l.max_acceleration,
                                -kMaxAxisAcceleration, 0.0, false, true, acc);
  return l;
}

void read_sim(Reader& r, const std::string& port, sim::SimSourceOptions& sim) {
  auto& s = sim.chassis;
  s.initial_soc = r.number("sim/initial_soc", s.initial_soc, 0.0, 100.0, false, false, "%");
  s.mode_switch_duration = from_seconds(r.number(
      "sim/mode_switch_duration", seconds(s.mode_switch_duration), 0.0, 10.0, false, false, "s"));
  s.boot_in_remote_mode = r.flag("sim/boot_in_remote_mode", s.boot_in_remote_mode);
  s.version = r.text("sim/firmware_version", s.version);
  const double metres =
      r.number("sim/ultrasonic_range", s.ultrasonic[0] / 1000.0, 0.0, 32.767, false, false, "m");
  s.ultrasonic.fill(static_cast<std::int16_t>(std::lround(metres * 1000.0)));
  ErrorWordLayout layout = s.profile.error_word;
  if (port.rfind("sim:", 0) == 0) {
    if (auto v = sim::apply_variant(port.substr(4), {})) layout = v->profile.error_word;
  }
  for (const auto& name : r.text_list("sim/errors")) {
    if (auto bit = sim::parse_error_bit(name, layout)) {
      sim.boot_error_bits |= 1u << *bit;
    } else {
      r.fail("sim/errors", "contains \"" + name + "\": " + bit.error().message);
    }
  }
}

// `protocol`, `commissioning_file` and one value per interpretation setting, resolved into
// DriverConfig::protocol and the controller's profile (as the ROS 1 node resolves them).
void read_protocol(Reader& r, const ModelPreset& model, Setup& setup) {
  std::vector<std::string> choices = {"auto"};
  for (const auto& n : protocol_revision_names())
    choices.push_back(n);
  setup.protocol = r.text("protocol", setup.protocol);
  const bool known = std::find(choices.begin(), choices.end(), setup.protocol) != choices.end();
  if (!known) {
    r.fail("protocol", "= \"" + setup.protocol + "\": expected one of " + join(choices) +
                           " (auto: identified from the chassis before anything moves)");
  }
  const std::string file = r.text("commissioning_file", "");
  std::optional<ProtocolProfile> commissioned;
  if (!file.empty()) {
    if (auto loaded = load_commissioning_file(file)) {
      commissioned = *loaded;
    } else {
      r.fail("commissioning_file", "= \"" + file + "\": " + loaded.error().message);
    }
  }
  std::vector<std::pair<std::string, std::string>> settings;
  for (const ProfileSetting& s : profile_settings()) {
    const std::string name(s.name);
    const std::vector<std::string> values(s.values.begin(), s.values.end());
    const std::string value = r.scalar_text(name, "one of " + join(values));
    if (value.empty()) continue;
    ProtocolProfile scratch;
    if (!set_setting(scratch, name, value)) {
      r.fail(name, "= \"" + value + "\": expected one of " + join(values) + " (" +
                       std::string(s.description) + ")");
      continue;
    }
    settings.emplace_back(name, value);
  }
  ProtocolProfile profile = model.profile;
  if (commissioned) {
    profile = *commissioned;
  } else if (known && setup.protocol != "auto") {
    if (auto m = model_profile(model, setup.protocol)) profile = *m;
  }
  std::vector<std::string> forced;
  for (const auto& [name, value] : settings) {
    (void)set_setting(profile, name, value);  // checked above
    forced.push_back(name + ": " + value);
  }
  DriverConfig& d = setup.driver;
  d.controller.profile = profile;
  const std::string on_model = "model " + model.name;
  if (!file.empty()) {
    d.protocol = ProtocolChoice::kForced;
    setup.protocol_source = "forced: commissioning file " + file;
  } else if (setup.protocol != "auto") {
    d.protocol = ProtocolChoice::kForced;
    setup.protocol_source = "forced: protocol " + setup.protocol + ", " + on_model;
  } else if (!settings.empty()) {
    d.protocol = ProtocolChoice::kForced;
    setup.protocol_source =
        "forced: protocol auto overridden by the interpretation parameters, " + on_model;
  } else {
    d.protocol = ProtocolChoice::kAuto;
    setup.protocol_source = "auto: identified from the chassis, " + on_model;
  }
  if (!forced.empty()) setup.protocol_source += ", with " + join(forced);
}

void check_port(Reader& r, const std::string& port) {
  const auto kind = bus_kind(port);
  if (!kind) {
    r.fail("port_name", "= \"" + port + "\": " + kind.error().message);
  } else if (*kind == BusKind::kSim && port.size() > 3) {
    if (auto v = sim::apply_variant(port.substr(4), {}); !v) {
      r.fail("port_name", "= \"" + port + "\": " + v.error().message);
    }
  }
}

ParameterRow number_row(std::string name, std::string unit, double lo, double hi, bool lo_open,
                        bool hi_open, std::string def, std::string meaning, std::string group) {
  ParameterRow row;
  row.name = std::move(name);
  row.type = "double";
  row.unit = std::move(unit);
  row.lo = lo;
  row.hi = hi;
  row.lo_open = lo_open;
  row.hi_open = hi_open;
  row.has_range = true;
  row.default_text = std::move(def);
  row.meaning = std::move(meaning);
  row.group = std::move(group);
  return row;
}

ParameterRow text_row(std::string name, std::string type, std::string def,
                      std::vector<std::string> choices, std::string meaning, std::string group) {
  ParameterRow row;
  row.name = std::move(name);
  row.type = std::move(type);
  row.default_text = std::move(def);
  row.choices = std::move(choices);
  row.meaning = std::move(meaning);
  row.group = std::move(group);
  return row;
}

std::vector<ParameterRow> make_rows() {
  std::vector<ParameterRow> rows;
  rows.push_back(text_row("model", "string", "ranger", model_names(),
                          "the vehicle: geometry, limits, protocol profile", "vehicle"));
  std::vector<std::string> protocols = {"auto"};
  for (const auto& n : protocol_revision_names())
    protocols.push_back(n);
  rows.push_back(text_row("protocol", "string", "auto", protocols,
                          "auto: identified from the chassis before anything moves; a revision: "
                          "that preset with the model's own settings",
                          "protocol"));
  rows.push_back(text_row("commissioning_file", "string", "", {},
                          "a file written by ranger_can commission: its settings, forced",
                          "protocol"));
  for (const ProfileSetting& s : profile_settings()) {
    rows.push_back(text_row(std::string(s.name), "string", "",
                            std::vector<std::string>(s.values.begin(), s.values.end()),
                            std::string(s.description), "protocol"));
  }
  for (const DriverParameter& p : driver_parameters()) {
    ParameterRow row;
    row.name = std::string(p.name);
    row.type = p.type == ParameterType::kBool      ? "bool"
               : p.type == ParameterType::kInteger ? "int"
                                                   : "double";
    row.unit = std::string(p.unit);
    row.lo = p.range.lo;
    row.hi = p.range.hi;
    row.lo_open = p.range.lo_open;
    row.hi_open = p.range.hi_open;
    row.has_range = p.type != ParameterType::kBool;
    row.default_text = value_text(p, default_value(p));
    row.meaning = std::string(p.meaning);
    row.group = "driver";
    rows.push_back(std::move(row));
  }
  for (const GeometryRow& g : kGeometryRows)
    rows.push_back(number_row(g.name, "m", 0.0, g.hi, true, false, "", g.meaning, "vehicle"));
  const KinematicsLimits full;
  for (const LimitRow& l : kLimitRows) {
    const double hi = (l.field == &KinematicsLimits::max_linear_speed ||
                       l.field == &KinematicsLimits::max_speed_at_large_steering)
                          ? full.max_linear_speed
                          : full.*(l.field);
    rows.push_back(number_row(l.name, l.unit, 0.0, hi, true, false, "", l.meaning, "limits"));
  }
  for (const AxisRow& a : kAxisRows) {
    const std::string axis = a.axis, vel = std::string(a.unit) + "/s",
                      acc = std::string(a.unit) + "/s^2";
    rows.push_back(text_row(axis + "/has_velocity_limits", "bool", "false", {}, "", "limits"));
    rows.push_back(number_row(axis + "/max_velocity", vel, 0.0, kMaxAxisVelocity, false, false, "0",
                              "", "limits"));
    rows.push_back(number_row(axis + "/min_velocity", vel, -kMaxAxisVelocity, kMaxAxisVelocity,
                              false, false, "-max_velocity", "", "limits"));
    rows.push_back(text_row(axis + "/has_acceleration_limits", "bool", "false", {}, "", "limits"));
    rows.push_back(number_row(axis + "/max_acceleration", acc, 0.0, kMaxAxisAcceleration, true,
                              false, "0", "", "limits"));
    rows.push_back(number_row(axis + "/min_acceleration", acc, -kMaxAxisAcceleration, 0.0, false,
                              true, "-max_acceleration", "", "limits"));
  }
  rows.push_back(text_row("odometry_source", "string", "wheels", {"wheels", "motion"},
                          "wheels: the four wheels' fit; motion: 0x221 + 0x291 only", "odometry"));
  const sim::VirtualChassisConfig s;
  rows.push_back(number_row("sim/initial_soc", "%", 0.0, 100.0, false, false,
                            number_text(s.initial_soc), "battery at boot", "sim"));
  rows.push_back(number_row("sim/mode_switch_duration", "s", 0.0, 10.0, false, false,
                            number_text(seconds(s.mode_switch_duration)),
                            "how long a motion-mode switch takes", "sim"));
  rows.push_back(text_row("sim/boot_in_remote_mode", "bool", "false", {},
                          "boot with the remote control in charge", "sim"));
  rows.push_back(text_row("sim/firmware_version", "string", s.version, {},
                          "what the chassis answers the 0x4A1 version request with", "sim"));
  rows.push_back(number_row("sim/ultrasonic_range", "m", 0.0, 32.767, false, false,
                            number_text(s.ultrasonic[0] / 1000.0), "distance every sensor reports",
                            "sim"));
  rows.push_back(text_row("sim/errors", "string_list", "[]", {},
                          "0x211 error bits the virtual chassis boots with (names or indices)",
                          "sim"));
  return rows;
}

}  // namespace

const std::vector<ParameterRow>& parameter_rows() {
  static const std::vector<ParameterRow> rows = make_rows();
  return rows;
}

Result<Setup> make_setup(const std::string& port, const std::map<std::string, Value>& values,
                         const std::string& display_prefix) {
  Reader r(values, display_prefix);
  Setup setup;
  setup.port = port;
  check_port(r, port);
  auto& c = setup.driver.controller;
  auto& o = setup.driver.odometry;

  setup.model = r.text("model", setup.model);
  ModelPreset model = model_preset("ranger").value();
  if (auto m = model_preset(setup.model)) {
    model = *m;
  } else {
    r.fail("model", "= \"" + setup.model + "\": expected one of " + join(model_names()));
  }
  setup.model_display_name = model.display_name;
  c.limits = model.limits;
  setup.sim.chassis = sim::chassis_for_model(model, setup.sim.chassis);

  for (const DriverParameter& row : driver_parameters())
    r.driver_parameter(row, setup.driver);

  VehicleGeometry g = model.geometry;
  for (const GeometryRow& row : kGeometryRows)
    g.*(row.field) = r.number(row.name, g.*(row.field), 0.0, row.hi, true, false, "m");
  c.geometry = g;
  o.geometry = g;
  setup.sim.chassis.geometry = g;

  const KinematicsLimits full;
  for (const LimitRow& row : kLimitRows) {
    double& field = c.limits.*(row.field);
    const bool speed = row.field == &KinematicsLimits::max_linear_speed ||
                       row.field == &KinematicsLimits::max_speed_at_large_steering;
    field = r.number(row.name, field, 0.0, speed ? full.max_linear_speed : full.*(row.field), true,
                     false, row.unit);
  }
  for (const AxisRow& a : kAxisRows)
    c.*(a.field) = read_axis(r, a.axis, a.unit);

  const std::string source = r.text("odometry_source", std::string(to_string(o.source)));
  if (auto parsed = parse_odometry_source(source)) {
    o.source = *parsed;
  } else {
    r.fail("odometry_source", "= \"" + source + "\": expected \"wheels\" or \"motion\"");
  }
  read_sim(r, port, setup.sim);
  read_protocol(r, model, setup);
  r.report_unknown();

  std::vector<std::string> errors = r.errors();
  if (errors.empty()) {
    if (auto st = setup.driver.validate(); !st) {
      errors.push_back("parameters rejected: " + st.error().message);
    }
  }
  if (errors.empty()) return setup;
  return Error{Errc::kInvalidArgument, join(errors, "\n")};
}

}  // namespace ranger::python
