#include "ranger_can/control/parameters.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "ranger_can/parse.hpp"
#include "ranger_can/text.hpp"

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

// A driver row: its default is what DriverConfig{} holds.
Parameter row(const char* name, T type, const char* unit, ParameterRange range, const char* meaning,
              double (*get)(const DriverConfig&), void (*set)(DriverConfig&, double)) {
  Parameter p;
  p.name = name;
  p.type = type;
  p.unit = unit;
  p.range = range;
  p.meaning = meaning;
  p.get = get;
  p.set = set;
  const double d = get(DriverConfig{});
  if (type == T::kBool) {
    p.default_value = d != 0.0;
  } else if (type == T::kInteger) {
    p.default_value = static_cast<long long>(std::lround(d));
  } else {
    p.default_value = d;
  }
  return p;
}

const std::vector<Parameter> kParameters = {
    // ---- connection
    row("reconnect_interval", T::kSeconds, "s", closed(0.05, 60.0),
        "how often a missing interface is retried", RANGER_SECONDS(reconnect_interval)),
    // ---- control
    row("cmd_vel_timeout", T::kSeconds, "s", closed(0.02, 60.0),
        "no `cmd_vel` for this long → zero command", RANGER_SECONDS(controller.cmd_timeout)),
    row("auto_command_mode", T::kBool, "", kFlag,
        "request CAN command mode (0x421) by itself when the chassis is in standby",
        RANGER_FLAG(controller.auto_command_mode)),
    row("auto_reclaim_after_remote", T::kBool, "", kFlag,
        "true: request CAN command mode again by itself after the remote control had the "
        "chassis; false: only after `resume` (motion needs the re-arm either way)",
        RANGER_FLAG(controller.auto_reclaim_after_remote)),
    row("rearm_on_zero_twist", T::kBool, "", kFlag,
        "true: a zero `cmd_vel` re-arms too after a stop the commander did not ask for, once its "
        "cause has cleared, as `resume` does. Hazard: a navigation stack publishes zero twists by "
        "itself (at a goal, in recovery), so a released e-stop would restart the robot without "
        "anyone deciding to; only for a teleop-only robot whose operator sees it. false: only "
        "`resume` re-arms",
        RANGER_FLAG(controller.rearm_on_zero_twist)),
    row("link_timeout", T::kSeconds, "s", closed(0.02, 10.0),
        "chassis considered silent after this long without 0x211",
        RANGER_SECONDS(controller.link_timeout)),
    row("min_command_interval", T::kSeconds, "s", closed(0.001, 0.02),
        "a changed command goes out at once, but never sooner than this after the previous "
        "changed command (keep-alives do not count; bounds the bus load under a `cmd_vel` flood)",
        RANGER_SECONDS(controller.min_command_interval)),
    row("mode_switch_timeout", T::kSeconds, "s", closed(0.1, 30.0),
        "resend 0x141 if the switch is not confirmed (0x291) in this time",
        RANGER_SECONDS(controller.mode_switch_timeout)),
    row("mode_switch_max_attempts", T::kInteger, "", closed(1.0, 100.0),
        "attempts before a switch is reported failed",
        RANGER_INTEGER(controller.mode_switch_max_attempts)),
    row("mode_switch_blind_time", T::kSeconds, "s", closed(0.05, 10.0),
        "a mode switch is complete once 0x291 reports the new mode and the wheels (0x271) stand "
        "at its angles, never on 0x291's flag alone; without 0x271 (or with wheels that settle "
        "off their angles) this long after its 0x141: the chassis's own switch time (a RANGER MINI "
        "3.0 was seen to take at most 0.57 s, docs/FIELD_FACTS.md)",
        RANGER_SECONDS(controller.mode_switch_blind_time)),
    row("mode_switch_min_time", T::kSeconds, "s", closed(0.001, 10.0),
        "a mode switch is never complete sooner than this after its 0x141, whatever 0x291 and the "
        "wheels say (the field's shortest switch: 0.08 s)",
        RANGER_SECONDS(controller.mode_switch_min_time)),
    row("mode_switch_wheel_tolerance", T::kNumber, "rad", closed(0.001, 0.5),
        "the wheels stand at the new mode's angles when each is within this of its angle (0x271) "
        "and still",
        RANGER_NUMBER(controller.mode_switch_wheel_tolerance)),
    row("standstill_speed", T::kNumber, "m/s", closed(0.0, 1.0),
        "every wheel slower than this = at rest (mode switches wait for it)",
        RANGER_NUMBER(controller.standstill_speed)),
    row("steer_first_threshold", T::kNumber, "rad", closed(0.0, M_PI / 2),
        "steer first: full speed while every wheel is within this of its commanded angle, zero "
        "beyond twice it, linear in between (0 disables)",
        RANGER_NUMBER(controller.steer_first_threshold)),
    row("low_battery_soc", T::kNumber, "%", closed(0.0, 100.0),
        "BMS state of charge below which motion is refused (the chassis cuts the drives at 10 %)",
        RANGER_NUMBER(controller.low_battery_soc)),
    // ---- protocol
    row("identify_timeout", T::kSeconds, "s", closed(1.0, 600.0),
        "`protocol: auto` only: a chassis not identified within this stays at rest, and the node "
        "says what to set",
        RANGER_SECONDS(identification.timeout)),
    // ---- automatic motion-mode selection
    row("mode_selection/lateral_enter", T::kNumber, "m/s", closed(0.0, 10.0),
        "\\|vy\\| above which oblique is chosen",
        RANGER_NUMBER(controller.mode_selection.lateral_enter)),
    row("mode_selection/lateral_exit", T::kNumber, "m/s", closed(0.0, 10.0),
        "\\|vy\\| below which oblique may be left",
        RANGER_NUMBER(controller.mode_selection.lateral_exit)),
    row("mode_selection/linear_enter", T::kNumber, "m/s", closed(0.0, 10.0),
        "\\|(vx, vy)\\| below which a rotation is a spin",
        RANGER_NUMBER(controller.mode_selection.linear_enter)),
    row("mode_selection/linear_exit", T::kNumber, "m/s", closed(0.0, 10.0),
        "\\|(vx, vy)\\| above which spin is left",
        RANGER_NUMBER(controller.mode_selection.linear_exit)),
    row("mode_selection/rotation_enter", T::kNumber, "rad/s", closed(0.0, 10.0),
        "\\|wz\\| above which a rotation counts",
        RANGER_NUMBER(controller.mode_selection.rotation_enter)),
    row("mode_selection/rotation_exit", T::kNumber, "rad/s", closed(0.0, 10.0),
        "\\|wz\\| below which a rotation no longer counts",
        RANGER_NUMBER(controller.mode_selection.rotation_exit)),
    row("mode_selection/min_linear_speed", T::kNumber, "m/s", closed(0.0, 1.0),
        "a twist whose every component is below this and `min_yaw_rate` is below the chassis's "
        "resolution: refused as `below_minimum` (never dropped silently)",
        RANGER_NUMBER(controller.mode_selection.min_linear_speed)),
    row("mode_selection/min_yaw_rate", T::kNumber, "rad/s", closed(0.0, 1.0),
        "see `min_linear_speed`", RANGER_NUMBER(controller.mode_selection.min_yaw_rate)),
    row("mode_selection/confirm_time", T::kSeconds, "s", closed(0.0, 10.0),
        "a new mode must be asked for this long",
        RANGER_SECONDS(controller.mode_selection.confirm_time)),
    row("mode_selection/min_dwell", T::kSeconds, "s", closed(0.0, 60.0),
        "least time in a mode before the next switch",
        RANGER_SECONDS(controller.mode_selection.min_dwell)),
    row("mode_selection/oblique_side_band", T::kNumber, "rad", {0.0, M_PI / 2, false, true},
        "oblique: within this of ±90° the wheels keep their side (no 180° swing on a noisy vx)",
        RANGER_NUMBER(controller.mode_selection.oblique_side_band)),
    // ---- odometry
    row("wheel_data_timeout", T::kSeconds, "s", closed(0.02, 5.0),
        "per-wheel frames older than this count as missing",
        RANGER_SECONDS(odometry.wheel_data_timeout)),
    row("pose_variance_per_meter", T::kNumber, "m^2/m", closed(0.0, 1e3),
        "x/y variance growth per metre travelled", RANGER_NUMBER(odometry.pose_variance_per_meter)),
    row("yaw_variance_per_radian", T::kNumber, "rad^2/rad", closed(0.0, 1e3),
        "yaw variance growth per radian turned", RANGER_NUMBER(odometry.yaw_variance_per_radian)),
    row("yaw_variance_per_meter", T::kNumber, "rad^2/m", closed(0.0, 1e3),
        "yaw variance growth per metre travelled", RANGER_NUMBER(odometry.yaw_variance_per_meter)),
};

#undef RANGER_NUMBER
#undef RANGER_INTEGER
#undef RANGER_FLAG
#undef RANGER_SECONDS

std::string range_text(const ParameterRange& r, const std::string& unit) {
  std::string out = std::string(r.lo_open ? "(" : "[") + number_text(r.lo) + ", " +
                    number_text(r.hi) + (r.hi_open ? ")" : "]");
  if (!unit.empty()) out += " " + unit;
  return out;
}

// "= 1: ..." problems name the valid range; an angle's in degrees too ("(40 deg)").
std::string range_problem(const Parameter& p) {
  std::string out = valid_text(p);
  if (p.unit == "rad" && p.valid_note.empty() && p.range.hi > 0.0 && std::isfinite(p.range.hi)) {
    out += " (" + number_text(std::round(rad_to_deg(p.range.hi))) + " deg)";
  }
  return out;
}

// "one of a, b, c"; two choices read "\"a\" or \"b\"" (kText rows).
std::string choices_problem(const Parameter& p) {
  if (p.type == T::kText && p.choices.size() == 2) {
    return "\"" + p.choices[0] + "\" or \"" + p.choices[1] + "\"";
  }
  return "one of " + text::join(p.choices);
}

Error problem(std::string message) {
  return Error{Errc::kInvalidArgument, std::move(message)};
}

Result<ParameterValue> check_number(const Parameter& p, const ParameterValue& v,
                                    const std::string& prefix) {
  const auto n = v.as_number();
  if (!n) return problem(prefix + shown(v) + ": expected a number in " + range_problem(p));
  if (!std::isfinite(*n) || !p.range.contains(*n)) {
    return problem(prefix + shown(v) + " is out of range: valid " + range_problem(p));
  }
  return ParameterValue(*n);
}

Result<ParameterValue> check_integer(const Parameter& p, const ParameterValue& v) {
  if (v.kind != ParameterValue::Kind::kInteger) {
    return problem("= " + shown(v) + ": expected an integer in " + valid_text(p));
  }
  if (!p.range.contains(static_cast<double>(v.integer))) {
    return problem("= " + shown(v) + " is out of range: valid " + valid_text(p));
  }
  return v;
}

Result<ParameterValue> check_choice(const Parameter& p, const ParameterValue& v) {
  using K = ParameterValue::Kind;
  const std::string word = v.kind == K::kText ? v.text : shown(v);
  const bool scalar =
      v.kind == K::kText || (p.type == T::kChoice &&
                             (v.kind == K::kBool || v.kind == K::kInteger || v.kind == K::kNumber));
  if (!scalar) {
    return problem("= " + shown(v) + ": expected " +
                   (p.type == T::kText ? std::string("a string") : choices_problem(p)));
  }
  if (p.choices.empty() || std::find(p.choices.begin(), p.choices.end(), word) != p.choices.end()) {
    return ParameterValue(word);
  }
  std::string message = "= \"" + word + "\": expected " + choices_problem(p);
  if (p.type == T::kChoice) message += " (" + p.meaning + ")";
  return problem(message);
}

Result<ParameterValue> check_list(const Parameter& p, const ParameterValue& v) {
  const bool numbers = p.type == T::kNumberList;
  const std::string expected = numbers ? ": expected a list of " + std::to_string(p.size) +
                                             " numbers in " + range_text(p.range, p.unit)
                                       : ": expected a list of strings";
  if (v.kind != ParameterValue::Kind::kList || (numbers && v.items.size() != p.size)) {
    return problem("= " + shown(v) + expected);
  }
  std::vector<ParameterValue> out;
  for (std::size_t i = 0; i < v.items.size(); ++i) {
    const std::string at = "[" + std::to_string(i) + "] = ";
    const ParameterValue& item = v.items[i];
    if (!numbers) {
      if (item.kind != ParameterValue::Kind::kText) {
        return problem(at + shown(item) + ": expected a string");
      }
      out.push_back(item);
      continue;
    }
    const auto n = item.as_number();
    if (!n || !std::isfinite(*n) || !p.range.contains(*n)) {
      return problem(at + shown(item) + expected);
    }
    out.emplace_back(*n);
  }
  return ParameterValue(std::move(out));
}

// A value in the README's default column.
std::string default_text(const Parameter& p) {
  if (!p.default_note.empty()) return p.default_note;
  const ParameterValue& v = p.default_value;
  switch (p.type) {
    case T::kBool:
      return v.boolean ? "true" : "false";
    case T::kInteger:
      return std::to_string(v.integer);
    case T::kNumber:
    case T::kSeconds:
      return value_text(p, v.number);
    case T::kText:
    case T::kChoice:
      return v.text.empty() ? "`\"\"`" : "`" + v.text + "`";
    case T::kNumberList:
    case T::kTextList: {
      std::vector<std::string> items;
      for (const ParameterValue& item : v.items)
        items.push_back(p.type == T::kTextList ? "`" + item.text + "`" : number_text(item.number));
      return "[" + text::join(items) + "]";
    }
  }
  return "";
}

}  // namespace

bool ParameterRange::contains(double v) const {
  return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
}

ParameterValue ParameterValue::dictionary() {
  ParameterValue v;
  v.kind = Kind::kDictionary;
  return v;
}

std::optional<double> ParameterValue::as_number() const {
  if (kind == Kind::kNumber) return number;
  if (kind == Kind::kInteger) return static_cast<double>(integer);
  return std::nullopt;
}

std::string shown(const ParameterValue& v) {
  using K = ParameterValue::Kind;
  switch (v.kind) {
    case K::kText:
      return "\"" + v.text + "\"";
    case K::kBool:
      return v.boolean ? "true" : "false";
    case K::kInteger:
      return std::to_string(v.integer);
    case K::kNumber: {
      std::ostringstream out;
      out << v.number;
      return out.str();
    }
    case K::kList:
      return "a list of " + std::to_string(v.items.size());
    case K::kDictionary:
      return "a dictionary";
    case K::kOther:
      break;
  }
  return "a value of another type";
}

const std::vector<Parameter>& driver_parameters() {
  return kParameters;
}

const Parameter* find_driver_parameter(std::string_view name) {
  for (const Parameter& p : kParameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::vector<std::string> driver_parameter_names() {
  std::vector<std::string> out;
  for (const Parameter& p : kParameters)
    out.push_back(p.name);
  return out;
}

double default_value(const Parameter& p) {
  return p.get != nullptr ? p.get(DriverConfig{}) : p.default_value.as_number().value_or(0.0);
}

std::string valid_text(const Parameter& p) {
  if (!p.valid_note.empty()) return p.valid_note;
  switch (p.type) {
    case T::kBool:
      return "bool";
    case T::kText:
    case T::kChoice:
      return p.choices.empty() ? "text" : text::join(p.choices);
    case T::kNumberList:
      return std::to_string(p.size) + " values in " + range_text(p.range, p.unit);
    case T::kTextList:
      return "list of text";
    case T::kInteger:
    case T::kNumber:
    case T::kSeconds:
      break;
  }
  return range_text(p.range, p.unit);
}

std::string value_text(const Parameter& p, double value) {
  if (p.type == T::kBool) return value != 0.0 ? "true" : "false";
  std::string out = number_text(value);
  if (p.unit == "rad" && value != 0.0) {
    out += " (" + number_text(std::round(rad_to_deg(value) * 100.0) / 100.0) + "°)";
  }
  return out;
}

Status check_value(const Parameter& p, double value) {
  const bool whole = p.type != T::kInteger || value == std::round(value);
  if (!std::isfinite(value) || !p.range.contains(value) || !whole) {
    return Error{Errc::kOutOfRange,
                 p.name + " = " + number_text(value) + " is out of range: valid " + valid_text(p)};
  }
  return ok_status();
}

Result<ParameterValue> check_parameter(const Parameter& p, const ParameterValue& v) {
  switch (p.type) {
    case T::kBool:
      if (v.kind != ParameterValue::Kind::kBool) {
        return problem("= " + shown(v) + ": expected true or false");
      }
      return v;
    case T::kInteger:
      return check_integer(p, v);
    case T::kNumber:
    case T::kSeconds:
      return check_number(p, v, "= ");
    case T::kText:
    case T::kChoice:
      return check_choice(p, v);
    case T::kNumberList:
    case T::kTextList:
      return check_list(p, v);
  }
  return v;
}

Status set_driver_parameter(DriverConfig& config, std::string_view name, std::string_view text) {
  const Parameter* p = find_driver_parameter(name);
  if (p == nullptr) {
    // The names closest to the one given (the longest common prefix) first.
    auto common = [name](std::string_view n) {
      std::size_t i = 0;
      while (i < n.size() && i < name.size() && n[i] == name[i])
        ++i;
      return i;
    };
    std::vector<std::string_view> names;
    for (const Parameter& q : kParameters)
      names.push_back(q.name);
    std::stable_sort(names.begin(), names.end(),
                     [&](std::string_view a, std::string_view b) { return common(a) > common(b); });
    return Error{Errc::kInvalidArgument, "unknown parameter '" + std::string(name) +
                                             "' (valid: " + text::join(names) + ")"};
  }
  const std::string s(text);
  double value = 0.0;
  if (p->type == T::kBool) {
    if (s != "true" && s != "false") {
      return Error{Errc::kInvalidArgument,
                   std::string(name) + ": expected true or false, got '" + s + "'"};
    }
    value = s == "true" ? 1.0 : 0.0;
  } else {
    Result<double> v = parse_double(name, s);
    if (!v) return v.error();
    value = *v;
    if (!p->range.contains(value) || (p->type == T::kInteger && value != std::round(value))) {
      return Error{Errc::kOutOfRange,
                   std::string(name) + ": '" + s + "' is outside " + valid_text(*p)};
    }
  }
  if (Status st = check_value(*p, value); !st) return st;
  p->set(config, value);
  return ok_status();
}

std::string markdown_row(const Parameter& p) {
  std::string valid = valid_text(p);
  if (p.valid_note.empty() && !p.choices.empty()) {
    std::vector<std::string> quoted;
    for (const std::string& c : p.choices)
      quoted.push_back("`" + c + "`");
    valid = text::join(quoted);
  }
  return "| `" + p.name + "` | " + default_text(p) + " | " + valid + " | " + p.meaning + " |";
}

std::optional<ParameterValue> MapParameterSource::get(const std::string& name) const {
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

}  // namespace ranger
