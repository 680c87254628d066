#include "ranger_can/control/parameters.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "ranger_can/parse.hpp"

namespace ranger {
namespace {

using Seconds = std::chrono::duration<double>;

double secs(std::chrono::nanoseconds d) {
  return Seconds(d).count();
}
std::chrono::nanoseconds from_secs(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Seconds(s));
}

// Accessors of one DriverConfig field: a number, a whole number, a flag or a duration.
#define RANGER_NUMBER(path)                                                    \
  [](const DriverConfig& c) -> double { return static_cast<double>(c.path); }, \
      [](DriverConfig& c, double v) { c.path = v; }
#define RANGER_INTEGER(path)                                                   \
  [](const DriverConfig& c) -> double { return static_cast<double>(c.path); }, \
      [](DriverConfig& c, double v) { c.path = static_cast<int>(std::lround(v)); }
#define RANGER_FLAG(path)                                             \
  [](const DriverConfig& c) -> double { return c.path ? 1.0 : 0.0; }, \
      [](DriverConfig& c, double v) { c.path = v != 0.0; }
#define RANGER_SECONDS(path)                                    \
  [](const DriverConfig& c) -> double { return secs(c.path); }, \
      [](DriverConfig& c, double v) { c.path = from_secs(v); }

constexpr ParameterRange kFlag{0.0, 1.0};
constexpr ParameterRange closed(double lo, double hi) {
  return {lo, hi, false, false};
}

using T = ParameterType;

const std::vector<DriverParameter> kParameters = {
    // ---- connection
    {"reconnect_interval", T::kSeconds, "s", closed(0.05, 60.0),
     "how often a missing interface is retried", RANGER_SECONDS(reconnect_interval)},
    // ---- control
    {"cmd_vel_timeout", T::kSeconds, "s", closed(0.02, 60.0),
     "no `cmd_vel` for this long → zero command", RANGER_SECONDS(controller.cmd_timeout)},
    {"auto_command_mode", T::kBool, "", kFlag,
     "request CAN command mode (0x421) by itself when the chassis is in standby",
     RANGER_FLAG(controller.auto_command_mode)},
    {"auto_reclaim_after_remote", T::kBool, "", kFlag,
     "true: request CAN command mode again by itself after the remote control had the chassis; "
     "false: only after `resume` (motion needs the re-arm either way)",
     RANGER_FLAG(controller.auto_reclaim_after_remote)},
    {"link_timeout", T::kSeconds, "s", closed(0.02, 10.0),
     "chassis considered silent after this long without 0x211",
     RANGER_SECONDS(controller.link_timeout)},
    {"min_command_interval", T::kSeconds, "s", closed(0.001, 0.02),
     "a changed command goes out at once, but never sooner than this after the previous changed "
     "command (keep-alives do not count; bounds the bus load under a `cmd_vel` flood)",
     RANGER_SECONDS(controller.min_command_interval)},
    {"mode_switch_timeout", T::kSeconds, "s", closed(0.1, 30.0),
     "resend 0x141 if the switch is not confirmed (0x291) in this time",
     RANGER_SECONDS(controller.mode_switch_timeout)},
    {"mode_switch_max_attempts", T::kInteger, "", closed(1.0, 100.0),
     "attempts before a switch is reported failed",
     RANGER_INTEGER(controller.mode_switch_max_attempts)},
    {"standstill_speed", T::kNumber, "m/s", closed(0.0, 1.0),
     "every wheel slower than this = at rest (mode switches wait for it)",
     RANGER_NUMBER(controller.standstill_speed)},
    {"steer_first_threshold", T::kNumber, "rad", closed(0.0, M_PI / 2),
     "steer first: full speed while every wheel is within this of its commanded angle, zero "
     "beyond twice it, linear in between (0 disables)",
     RANGER_NUMBER(controller.steer_first_threshold)},
    {"low_battery_soc", T::kNumber, "%", closed(0.0, 100.0),
     "BMS state of charge below which motion is refused (the chassis cuts the drives at 10 %)",
     RANGER_NUMBER(controller.low_battery_soc)},
    // ---- protocol
    {"identify_timeout", T::kSeconds, "s", closed(1.0, 600.0),
     "`protocol: auto` only: a chassis not identified within this stays at rest, and the node "
     "says what to set",
     RANGER_SECONDS(identification.timeout)},
    // ---- automatic motion-mode selection
    {"mode_selection/lateral_enter", T::kNumber, "m/s", closed(0.0, 10.0),
     "\\|vy\\| above which oblique is chosen",
     RANGER_NUMBER(controller.mode_selection.lateral_enter)},
    {"mode_selection/lateral_exit", T::kNumber, "m/s", closed(0.0, 10.0),
     "\\|vy\\| below which oblique may be left",
     RANGER_NUMBER(controller.mode_selection.lateral_exit)},
    {"mode_selection/linear_enter", T::kNumber, "m/s", closed(0.0, 10.0),
     "\\|(vx, vy)\\| below which a rotation is a spin",
     RANGER_NUMBER(controller.mode_selection.linear_enter)},
    {"mode_selection/linear_exit", T::kNumber, "m/s", closed(0.0, 10.0),
     "\\|(vx, vy)\\| above which spin is left",
     RANGER_NUMBER(controller.mode_selection.linear_exit)},
    {"mode_selection/rotation_enter", T::kNumber, "rad/s", closed(0.0, 10.0),
     "\\|wz\\| above which a rotation counts",
     RANGER_NUMBER(controller.mode_selection.rotation_enter)},
    {"mode_selection/rotation_exit", T::kNumber, "rad/s", closed(0.0, 10.0),
     "\\|wz\\| below which a rotation no longer counts",
     RANGER_NUMBER(controller.mode_selection.rotation_exit)},
    {"mode_selection/min_linear_speed", T::kNumber, "m/s", closed(0.0, 1.0),
     "a twist whose every component is below this and `min_yaw_rate` is below the chassis's "
     "resolution: refused as `below_minimum` (never dropped silently)",
     RANGER_NUMBER(controller.mode_selection.min_linear_speed)},
    {"mode_selection/min_yaw_rate", T::kNumber, "rad/s", closed(0.0, 1.0), "see `min_linear_speed`",
     RANGER_NUMBER(controller.mode_selection.min_yaw_rate)},
    {"mode_selection/confirm_time", T::kSeconds, "s", closed(0.0, 10.0),
     "a new mode must be asked for this long",
     RANGER_SECONDS(controller.mode_selection.confirm_time)},
    {"mode_selection/min_dwell", T::kSeconds, "s", closed(0.0, 60.0),
     "least time in a mode before the next switch",
     RANGER_SECONDS(controller.mode_selection.min_dwell)},
    {"mode_selection/oblique_side_band",
     T::kNumber,
     "rad",
     {0.0, M_PI / 2, false, true},
     "oblique: within this of ±90° the wheels keep their side (no 180° swing on a noisy vx)",
     RANGER_NUMBER(controller.mode_selection.oblique_side_band)},
    // ---- odometry
    {"wheel_data_timeout", T::kSeconds, "s", closed(0.02, 5.0),
     "per-wheel frames older than this count as missing",
     RANGER_SECONDS(odometry.wheel_data_timeout)},
    {"pose_variance_per_meter", T::kNumber, "m^2/m", closed(0.0, 1e3),
     "x/y variance growth per metre travelled", RANGER_NUMBER(odometry.pose_variance_per_meter)},
    {"yaw_variance_per_radian", T::kNumber, "rad^2/rad", closed(0.0, 1e3),
     "yaw variance growth per radian turned", RANGER_NUMBER(odometry.yaw_variance_per_radian)},
    {"yaw_variance_per_meter", T::kNumber, "rad^2/m", closed(0.0, 1e3),
     "yaw variance growth per metre travelled", RANGER_NUMBER(odometry.yaw_variance_per_meter)},
};

#undef RANGER_NUMBER
#undef RANGER_INTEGER
#undef RANGER_FLAG
#undef RANGER_SECONDS

}  // namespace

bool ParameterRange::contains(double v) const {
  return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
}

const std::vector<DriverParameter>& driver_parameters() {
  return kParameters;
}

const DriverParameter* find_driver_parameter(std::string_view name) {
  for (const DriverParameter& p : kParameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::vector<std::string> driver_parameter_names() {
  std::vector<std::string> out;
  for (const DriverParameter& p : kParameters)
    out.emplace_back(p.name);
  return out;
}

double default_value(const DriverParameter& p) {
  return p.get(DriverConfig{});
}

std::string valid_text(const DriverParameter& p) {
  if (p.type == ParameterType::kBool) return "bool";
  const ParameterRange& r = p.range;
  std::string out = std::string(r.lo_open ? "(" : "[") + number_text(r.lo) + ", " +
                    number_text(r.hi) + (r.hi_open ? ")" : "]");
  if (!p.unit.empty()) out += " " + std::string(p.unit);
  return out;
}

std::string value_text(const DriverParameter& p, double value) {
  if (p.type == ParameterType::kBool) return value != 0.0 ? "true" : "false";
  std::string out = number_text(value);
  if (p.unit == "rad" && value != 0.0) {
    out += " (" + number_text(std::round(rad_to_deg(value) * 100.0) / 100.0) + "°)";
  }
  return out;
}

Status check_value(const DriverParameter& p, double value) {
  const bool whole = p.type != ParameterType::kInteger || value == std::round(value);
  if (!std::isfinite(value) || !p.range.contains(value) || !whole) {
    return Error{Errc::kOutOfRange, std::string(p.name) + " = " + number_text(value) +
                                        " is out of range: valid " + valid_text(p)};
  }
  return ok_status();
}

Status set_driver_parameter(DriverConfig& config, std::string_view name, std::string_view text) {
  const DriverParameter* p = find_driver_parameter(name);
  if (p == nullptr) {
    // The names closest to the one given (the longest common prefix) first.
    auto common = [name](std::string_view n) {
      std::size_t i = 0;
      while (i < n.size() && i < name.size() && n[i] == name[i])
        ++i;
      return i;
    };
    std::vector<std::string_view> names;
    for (const DriverParameter& q : kParameters)
      names.push_back(q.name);
    std::stable_sort(names.begin(), names.end(), [&](std::string_view a, std::string_view b) {
      return common(a) > common(b);
    });
    std::string valid;
    for (std::string_view n : names)
      valid += (valid.empty() ? "" : ", ") + std::string(n);
    return Error{Errc::kInvalidArgument,
                 "unknown parameter '" + std::string(name) + "' (valid: " + valid + ")"};
  }
  const std::string s(text);
  double value = 0.0;
  if (p->type == ParameterType::kBool) {
    if (s != "true" && s != "false") {
      return Error{Errc::kInvalidArgument,
                   std::string(name) + ": expected true or false, got '" + s + "'"};
    }
    value = s == "true" ? 1.0 : 0.0;
  } else {
    Result<double> v = parse_double(name, s);
    if (!v) return v.error();
    value = *v;
    if (!p->range.contains(value) ||
        (p->type == ParameterType::kInteger && value != std::round(value))) {
      return Error{Errc::kOutOfRange,
                   std::string(name) + ": '" + s + "' is outside " + valid_text(*p)};
    }
  }
  if (Status st = check_value(*p, value); !st) return st;
  p->set(config, value);
  return ok_status();
}

std::string markdown_row(const DriverParameter& p) {
  return "| `" + std::string(p.name) + "` | " + value_text(p, default_value(p)) + " | " +
         valid_text(p) + " | " + std::string(p.meaning) + " |";
}

}  // namespace ranger
