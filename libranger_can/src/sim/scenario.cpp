#include "ranger_can/sim/scenario.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <sstream>
#include <utility>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/control/rearm.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

namespace {
const char* const kActionsHelp =
    "script (one action per line; '#' starts a comment; blank lines are ignored):\n"
    "  cmd VX VY WZ             from now on publish this REP-103 body twist (m/s, m/s, rad/s)\n"
    "                           every 50 ms of simulated time, the first at once\n"
    "  cmd none                 stop publishing (the driver's cmd_timeout then stops the chassis)\n"
    "  resume                   the re-arm after a stop the commander did not ask for (the only\n"
    "                           one: a zero twist re-arms only with --param\n"
    "                           rearm_on_zero_twist=true); refused while a stop cause is active\n"
    "  mode auto|ackermann|oblique|spin|side_slip\n"
    "                           force the motion mode of later commands (auto: chosen per twist;\n"
    "                           side_slip where the mode numbering has it: mini_v1, agx_v2)\n"
    "  park on|off              Driver::set_park(): park (motion refused, \"parked\") or release\n"
    "  clear-errors CODE        the driver sends 0x441 CODE (0-16, or 0x00-0x10)\n"
    "  wait SEC                 advance simulated time by SEC (whole milliseconds, >= 0)\n"
    "  expect ...               a check of the state now (below); a failed one is reported and\n"
    "                           the run goes on to the end (exit status 1)\n"
    "\n"
    "chassis side, applied to the virtual chassis at once (what `status` prints goes to stderr):\n";

// The checks, with the names each accepts (from the enums' `all` lists).
std::string expect_help();
}  // namespace

namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;

constexpr std::size_t kMaxReportedErrors = 20;
constexpr std::chrono::milliseconds kPublishPeriod{50};
constexpr std::chrono::milliseconds kStep{1};
// The simulated clock's epoch (t = 0): far from zero, like a real monotonic clock.
constexpr Timestamp kEpoch = std::chrono::seconds(1000);
constexpr int kDecimals = 6;

Error problem(const std::string& what) {
  return Error{Errc::kParseError, what};
}

using text::join;

std::vector<std::string> split(std::string_view text) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i])) != 0)
      ++i;
    std::size_t j = i;
    while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j])) == 0)
      ++j;
    if (j > i) words.emplace_back(text.substr(i, j - i));
    i = j;
  }
  return words;
}

std::string_view strip(std::string_view text) {
  const auto hash = text.find('#');
  if (hash != std::string_view::npos) text = text.substr(0, hash);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())) != 0)
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())) != 0)
    text.remove_suffix(1);
  return text;
}

// The text with every byte a terminal would not print as itself written as \xNN: an error message
// quotes what it refuses, and that may be binary.
std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", u);
      out += buf;
    }
  }
  return out;
}

// ---- names the checks accept ----

const std::vector<std::string>& refusal_names() {
  static const std::vector<std::string> names = text::names_of(kAllMotionRefusals);
  return names;
}

// An `all` list's names and "null" (the field has no value yet).
template <typename Enum, std::size_t N>
std::vector<std::string> names_or_null(const Enum (&all)[N]) {
  std::vector<std::string> names = text::names_of(all);
  names.emplace_back("null");
  return names;
}

const std::vector<std::string>& control_mode_names() {
  static const std::vector<std::string> names = names_or_null(protocol::kAllControlModes);
  return names;
}

// The identification's phases (protocol auto), and "none" for a protocol that was given.
const std::vector<std::string>& identification_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out = text::names_of(kAllIdentificationPhases);
    out.emplace_back("none");
    return out;
  }();
  return names;
}

const std::vector<std::string>& motion_mode_names() {
  static const std::vector<std::string> names = names_or_null(protocol::kAllMotionModes);
  return names;
}

// The fault table's names (protocol::kFaultTable), in its order.
std::vector<std::string> fault_table_names() {
  std::vector<std::string> n;
  for (const protocol::FaultInfo& f : protocol::kFaultTable)
    n.emplace_back(f.name);
  return n;
}

// Every name ControllerState::faults can hold: the controller's own, the fault table's (either
// layout) and a reserved bit's "reserved_bit_N".
const std::vector<std::string>& fault_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = text::names_of(kAllControllerFaults);
    for (auto& name : fault_table_names())
      n.push_back(std::move(name));
    for (int bit = 0; bit < 32; ++bit)
      n.push_back("reserved_bit_" + std::to_string(bit));
    return n;
  }();
  return names;
}

const std::vector<std::string>& bool_names() {
  static const std::vector<std::string> names = {"true", "false"};
  return names;
}

// One help entry: `head` in the first 27 columns, then `text` wrapped at 100 columns, its
// continuation lines indented to column 27.
std::string help_entry(const std::string& head, const std::string& text) {
  constexpr std::size_t kIndent = 27;
  std::string out;
  std::string line =
      head.size() < kIndent ? head + std::string(kIndent - head.size(), ' ') : head + " ";
  const std::size_t start = line.size();
  std::istringstream words(text);
  std::string w;
  while (words >> w) {
    if (line.size() > start && line.size() + 1 + w.size() > 100) {
      out += line + "\n";
      line = std::string(kIndent, ' ');
    } else if (line.size() > start || line.size() > kIndent) {
      if (line.back() != ' ') line += ' ';
    }
    line += w;
  }
  while (!line.empty() && line.back() == ' ')
    line.pop_back();
  return out + line + "\n";
}

std::string expect_help() {
  return "\n"
         "checks:\n" +
         help_entry("  expect refusal NAME", "why motion is refused: " + join(refusal_names())) +
         help_entry("  expect control_mode " + join(control_mode_names(), "|"), "") +
         help_entry("  expect motion_mode " + join(motion_mode_names(), "|"),
                    "(the chassis's 0x291)") +
         help_entry("  expect rearm_required true|false", "") +
         help_entry("  expect identification NAME",
                    "the identification's phase: " + join(identification_names()) +
                        " (none: the protocol was given)") +
         help_entry("  expect moving | still",
                    "ground truth: the fastest point of the chassis (body centre or a wheel) is "
                    "faster than 1 mm/s | not faster") +
         help_entry("  expect fault NAME | no-fault NAME | no-faults", "") +
         help_entry("", "NAME as in the output's faults: the driver's (" +
                            join(text::names_of(kAllControllerFaults)) +
                            "), a 0x211 fault of either error-word layout (" +
                            join(fault_table_names()) + ") or reserved_bit_N") +
         help_entry("  expect FIELD OP NUMBER",
                    "FIELD: t, truth.x|y|yaw|vx|vy|wz|speed, odom.x|y|yaw|vx|vy|wz, "
                    "steer_first_factor; OP: > < >= <= ==; the value as printed");
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

Error not_one_of(const std::string& what, const std::string& got,
                 const std::vector<std::string>& valid) {
  return problem(what + ": unknown '" + got + "' (valid: " + join(valid) + ")");
}

// ---- numbers as printed ----

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // -0.000
  return s;
}

double as_printed(double v, int decimals) {
  return std::strtod(fixed(v, decimals).c_str(), nullptr);
}

std::string seconds_text(std::chrono::milliseconds t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%lld.%03lld", static_cast<long long>(t.count() / 1000),
                static_cast<long long>(t.count() % 1000));
  return buf;
}

void append_string(std::string& out, std::string_view s) {
  out += '"';
  out += text::json_escape(s);
  out += '"';
}

void append_list(std::string& out, const std::vector<std::string>& items) {
  out += '[';
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ',';
    append_string(out, items[i]);
  }
  out += ']';
}

void append_optional(std::string& out, const std::optional<std::string>& v) {
  if (v) {
    append_string(out, *v);
  } else {
    out += "null";
  }
}

// ---- parsing ----

const std::vector<std::string>& driver_action_names() {
  static const std::vector<std::string> names = {"cmd",  "resume", "mode", "clear-errors",
                                                 "wait", "expect", "park"};
  return names;
}

const char* op_text(Expectation::Op op) {
  switch (op) {
    case Expectation::Op::kGreater:
      return ">";
    case Expectation::Op::kLess:
      return "<";
    case Expectation::Op::kGreaterEqual:
      return ">=";
    case Expectation::Op::kLessEqual:
      return "<=";
    case Expectation::Op::kEqual:
      return "==";
  }
  return "?";
}

std::optional<Expectation::Op> parse_op(const std::string& text) {
  for (auto op : {Expectation::Op::kGreater, Expectation::Op::kLess, Expectation::Op::kGreaterEqual,
                  Expectation::Op::kLessEqual, Expectation::Op::kEqual}) {
    if (text == op_text(op)) return op;
  }
  return std::nullopt;
}

Result<Expectation> parse_expect(const std::vector<std::string>& w) {
  // w[0] == "expect"
  const std::string usage =
      "expect: give one of: refusal NAME, control_mode NAME, motion_mode NAME, rearm_required "
      "true|false, identification PHASE, moving, still, fault NAME, no-fault NAME, no-faults, "
      "FIELD OP NUMBER";
  if (w.size() < 2) return problem(usage);
  const std::string& what = w[1];
  Expectation e;
  e.field = what;
  auto need = [&](std::size_t n, const std::string& form) -> Status {
    if (w.size() != n) return problem("usage: expect " + form);
    return ok_status();
  };
  if (what == "moving" || what == "still" || what == "no-faults") {
    if (auto st = need(2, what); !st) return st.error();
    e.kind = what == "moving"  ? Expectation::Kind::kMoving
             : what == "still" ? Expectation::Kind::kStill
                               : Expectation::Kind::kNoFaults;
    return e;
  }
  if (what == "fault" || what == "no-fault") {
    if (auto st = need(3, what + " NAME"); !st) return st.error();
    if (!contains(fault_names(), w[2])) {
      return problem("expect " + what + ": unknown fault '" + w[2] +
                     "' (the driver's: link_lost, emergency_stop, vehicle_abnormal, low_battery, "
                     "motion_mode_switch_failed, ...; or a 0x211 error bit's name, e.g. "
                     "over_current)");
    }
    e.kind = what == "fault" ? Expectation::Kind::kFault : Expectation::Kind::kNoFault;
    e.text = w[2];
    return e;
  }
  const struct {
    const char* field;
    const std::vector<std::string>& valid;
  } text_fields[] = {{"refusal", refusal_names()},
                     {"control_mode", control_mode_names()},
                     {"motion_mode", motion_mode_names()},
                     {"rearm_required", bool_names()},
                     {"identification", identification_names()}};
  for (const auto& f : text_fields) {
    if (what != f.field) continue;
    if (auto st = need(3, what + " " + join(f.valid, "|")); !st) return st.error();
    if (!contains(f.valid, w[2])) return not_one_of("expect " + what, w[2], f.valid);
    e.kind = Expectation::Kind::kEquals;
    e.text = w[2];
    return e;
  }
  if (contains(sample_number_fields(), what)) {
    if (w.size() != 4) return problem("usage: expect " + what + " >|<|>=|<=|== NUMBER");
    const auto op = parse_op(w[2]);
    if (!op) {
      return problem("expect " + what + ": unknown operator '" + w[2] +
                     "' (valid: >, <, >=, <=, ==)");
    }
    auto number = parse_double("expect " + what, w[3]);
    if (!number) return number.error();
    e.kind = Expectation::Kind::kCompare;
    e.op = *op;
    e.number = *number;
    e.text = w[3];  // as written, for messages
    return e;
  }
  return problem("expect: unknown check '" + what + "' (" + usage.substr(8) +
                 "; FIELD: " + join(sample_number_fields()) + ")");
}

// "name=value" pieces of --param.
std::optional<std::pair<std::string, std::string>> split_assignment(std::string_view text) {
  const auto eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0) return std::nullopt;
  return std::make_pair(std::string(text.substr(0, eq)), std::string(text.substr(eq + 1)));
}

}  // namespace

// ---- parsing: public ----

Result<std::chrono::milliseconds> parse_milliseconds(std::string_view what,
                                                     const std::string& text) {
  auto sec = parse_double(what, text);
  if (!sec) return sec.error();
  const std::string head = std::string(what) + ": '" + text + "' ";
  if (*sec < 0.0) return problem(head + "is negative");
  const double max = seconds(kMaxScenarioDuration);
  if (*sec > max) return problem(head + "is longer than " + number_text(max) + " s");
  const double ms = *sec * 1000.0;
  const double whole = std::round(ms);
  if (std::fabs(ms - whole) > 1e-6) {
    return problem(head + "is not a whole number of milliseconds (the simulation steps 1 ms)");
  }
  return std::chrono::milliseconds(static_cast<long long>(whole));
}

Result<std::optional<ScenarioAction>> parse_scenario_line(std::string_view raw, std::size_t line) {
  const std::string_view text = strip(raw);
  if (text.empty()) return std::optional<ScenarioAction>();
  const auto w = split(text);
  ScenarioAction a;
  a.line = line;
  a.text = std::string(text);
  const std::string& verb = w[0];
  if (verb == "cmd") {
    if (w.size() == 2 && w[1] == "none") {
      a.kind = ScenarioAction::Kind::kCommandNone;
      return std::optional<ScenarioAction>(std::move(a));
    }
    if (w.size() != 4) return problem("usage: cmd VX VY WZ  or  cmd none");
    double v[3];
    const char* names[3] = {"cmd VX", "cmd VY", "cmd WZ"};
    for (int i = 0; i < 3; ++i) {
      auto n = parse_double(names[i], w[1 + i]);
      if (!n) return n.error();
      v[i] = *n;
    }
    a.kind = ScenarioAction::Kind::kCommand;
    a.twist = BodyTwist{v[0], v[1], v[2]};
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (verb == "resume") {
    if (w.size() != 1) return problem("usage: resume (takes no argument)");
    a.kind = ScenarioAction::Kind::kResume;
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (verb == "park") {
    if (w.size() != 2 || (w[1] != "on" && w[1] != "off")) return problem("usage: park on|off");
    a.kind = ScenarioAction::Kind::kPark;
    a.enable = w[1] == "on";
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (verb == "mode") {
    const std::string usage = "usage: mode auto|ackermann|oblique|spin|side_slip";
    if (w.size() != 2) return problem(usage);
    a.kind = ScenarioAction::Kind::kMode;
    if (w[1] == "auto") return std::optional<ScenarioAction>(std::move(a));
    for (MotionMode m :
         {MotionMode::kAckermann, MotionMode::kOblique, MotionMode::kSpin, MotionMode::kSideSlip}) {
      if (w[1] == protocol::to_string(m)) {
        a.mode = m;
        return std::optional<ScenarioAction>(std::move(a));
      }
    }
    return problem("mode: unknown '" + w[1] +
                   "' (valid: auto, ackermann, oblique, spin, side_slip)");
  }
  if (verb == "clear-errors") {
    if (w.size() != 2) return problem("usage: clear-errors CODE (0-16 or 0x00-0x10)");
    auto code = parse_integer("clear-errors CODE", w[1], 0, protocol::kMaxErrorClearCode);
    if (!code) return code.error();
    a.kind = ScenarioAction::Kind::kClearErrors;
    a.code = static_cast<std::uint8_t>(*code);
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (verb == "wait") {
    if (w.size() != 2) return problem("usage: wait SEC");
    auto ms = parse_milliseconds("wait SEC", w[1]);
    if (!ms) return ms.error();
    a.kind = ScenarioAction::Kind::kWait;
    a.wait = *ms;
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (verb == "expect") {
    auto e = parse_expect(w);
    if (!e) return e.error();
    a.kind = ScenarioAction::Kind::kExpect;
    a.expect = std::move(*e);
    return std::optional<ScenarioAction>(std::move(a));
  }
  if (contains(chassis_command_names(), verb)) {
    auto action = parse_chassis_command(text);
    if (!action) return action.error();
    a.kind = ScenarioAction::Kind::kChassis;
    a.chassis = std::move(*action);
    return std::optional<ScenarioAction>(std::move(a));
  }
  return problem("unknown action '" + verb + "' (valid: " + join(driver_action_names()) + "; " +
                 "chassis: " + join(chassis_command_names()) + ")");
}

Result<Scenario> parse_scenario(std::istream& in) {
  Scenario scenario;
  std::vector<std::string> errors;
  std::size_t error_count = 0;
  auto report = [&](std::size_t line, const std::string& message) {
    ++error_count;
    if (errors.size() < kMaxReportedErrors) {
      errors.push_back("line " + std::to_string(line) + ": " + printable(message));
    }
  };

  std::streambuf* buf = in.rdbuf();
  std::string text;
  bool too_long = false;
  std::size_t line = 0;
  bool at_end = buf == nullptr;
  while (!at_end) {
    text.clear();
    too_long = false;
    bool got_any = false;
    for (;;) {
      const int c = buf->sbumpc();
      if (c == std::char_traits<char>::eof()) {
        at_end = true;
        break;
      }
      got_any = true;
      if (c == '\n') break;
      if (text.size() < kMaxScenarioLineLength) {
        text.push_back(static_cast<char>(c));
      } else {
        too_long = true;
      }
    }
    if (at_end && !got_any) break;
    ++line;
    if (line > kMaxScenarioLines) {
      report(line, "the script is longer than " + std::to_string(kMaxScenarioLines) + " lines");
      break;
    }
    if (too_long) {
      report(line, "longer than " + std::to_string(kMaxScenarioLineLength) + " characters");
      continue;
    }
    auto action = parse_scenario_line(text, line);
    if (!action) {
      report(line, action.error().message);
      continue;
    }
    if (!*action) continue;
    if ((*action)->kind == ScenarioAction::Kind::kWait) {
      const auto total = scenario.duration + (*action)->wait;
      if (total > kMaxScenarioDuration) {
        report(line, "the script runs past the " + std::to_string(kMaxScenarioDuration.count()) +
                         " s limit of simulated time");
        continue;
      }
      scenario.duration = total;
    }
    if ((*action)->kind == ScenarioAction::Kind::kExpect) ++scenario.expectations;
    scenario.actions.push_back(std::move(**action));
  }
  if (in.bad()) report(line + 1, "read error");
  if (error_count > 0) {
    std::string message = join(errors, "\n");
    if (error_count > errors.size()) {
      message += "\n" + std::to_string(error_count - errors.size()) + " more bad line(s) not shown";
    }
    return Error{Errc::kParseError, message};
  }
  return scenario;
}

Result<Scenario> parse_scenario(std::string_view text) {
  std::istringstream in{std::string(text)};
  return parse_scenario(in);
}

// ---- parameters ----

const std::vector<std::string>& scenario_param_names() {
  static const std::vector<std::string> names = driver_parameter_names();
  return names;
}

Status apply_scenario_param(DriverConfig& config, std::string_view assignment) {
  const auto kv = split_assignment(assignment);
  if (!kv) {
    return problem("expected NAME=VALUE, got '" + std::string(assignment) +
                   "' (NAME: " + join(scenario_param_names()) + ")");
  }
  const auto& [name, value] = *kv;
  return set_driver_parameter(config, name, value);
}

Status validate(const ScenarioOptions& options) {
  if (auto v = apply_variant(options.variant, options.chassis); !v) return v.error();
  if (options.every < 1ms) {
    return Error{Errc::kInvalidArgument, "the output period must be at least 1 ms"};
  }
  return options.driver.validate();
}

// ---- samples ----

const std::vector<std::string>& sample_number_fields() {
  static const std::vector<std::string> names = {
      "t",        "truth.x",  "truth.y",     "truth.yaw", "truth.vx",
      "truth.vy", "truth.wz", "truth.speed", "odom.x",    "odom.y",
      "odom.yaw", "odom.vx",  "odom.vy",     "odom.wz",   "steer_first_factor"};
  return names;
}

std::optional<double> sample_number(const ScenarioSample& s, std::string_view field) {
  if (field == "t") return static_cast<double>(s.t.count()) / 1000.0;
  const struct {
    std::string_view name;
    double value;
  } fields[] = {{"truth.x", s.truth.x},         {"truth.y", s.truth.y},
                {"truth.yaw", s.truth.yaw},     {"truth.vx", s.truth_twist.vx},
                {"truth.vy", s.truth_twist.vy}, {"truth.wz", s.truth_twist.wz},
                {"truth.speed", s.truth_speed}, {"odom.x", s.odom.x},
                {"odom.y", s.odom.y},           {"odom.yaw", s.odom.yaw},
                {"odom.vx", s.odom_twist.vx},   {"odom.vy", s.odom_twist.vy},
                {"odom.wz", s.odom_twist.wz},   {"steer_first_factor", s.steer_first_factor}};
  for (const auto& f : fields) {
    if (f.name == field) return as_printed(f.value, kDecimals);
  }
  return std::nullopt;
}

std::string to_json(const ScenarioSample& s) {
  std::string out;
  out.reserve(512);
  auto num = [&](const char* key, double v) {
    out += '"';
    out += key;
    out += "\":";
    out += fixed(v, kDecimals);
  };
  out += "{\"t\":" + seconds_text(s.t);
  out += ",\"truth\":{";
  num("x", s.truth.x);
  out += ',';
  num("y", s.truth.y);
  out += ',';
  num("yaw", s.truth.yaw);
  out += ',';
  num("vx", s.truth_twist.vx);
  out += ',';
  num("vy", s.truth_twist.vy);
  out += ',';
  num("wz", s.truth_twist.wz);
  out += ',';
  num("speed", s.truth_speed);
  out += "},\"odom\":{";
  num("x", s.odom.x);
  out += ',';
  num("y", s.odom.y);
  out += ',';
  num("yaw", s.odom.yaw);
  out += ',';
  num("vx", s.odom_twist.vx);
  out += ',';
  num("vy", s.odom_twist.vy);
  out += ',';
  num("wz", s.odom_twist.wz);
  out += "},\"control_mode\":";
  append_optional(out, s.control_mode);
  out += ",\"motion_mode\":";
  append_optional(out, s.motion_mode);
  out += ",\"refusal\":";
  append_string(out, s.refusal);
  out += ",\"faults\":";
  append_list(out, s.faults);
  out += ",\"rearm_required\":";
  out += s.rearm_required ? "true" : "false";
  out += ",\"latched\":";
  append_list(out, s.latched);
  out += ',';
  num("steer_first_factor", s.steer_first_factor);
  out += ",\"identification\":";
  append_string(out, s.identification);
  out += '}';
  return out;
}

// ---- the runner ----

struct ScenarioRunner::Impl {
  ScenarioOptions options;
  ManualClock clock{kEpoch};
  std::shared_ptr<SimBusSource> sim;  // before the driver: destroyed after it
  std::unique_ptr<Driver> driver;
  std::chrono::milliseconds t{0};

  std::optional<BodyTwist> publishing;  // the commander's twist
  std::chrono::milliseconds next_publish{0};

  struct Pending {
    std::uint64_t id;
    std::size_t line;
  };
  std::vector<Pending> pending;  // requests whose outcome is not known yet

  void step(const ScenarioOutput& output) {
    clock.advance(kStep);
    t += kStep;
    if (publishing && t >= next_publish) {
      publish();
      next_publish += kPublishPeriod;
    }
    sim->step(clock.now());
    driver->step(clock.now());
    if (!pending.empty()) report_requests(output);
    if (output.event && driver->last_event_sequence() > events_seen) report_events(output);
  }

  std::uint64_t events_seen = 0;  // read after every step: none is missed
  std::vector<DriverEvent> events;
  void report_events(const ScenarioOutput& output) {
    events.clear();
    driver->events_since(events_seen, events);
    for (const DriverEvent& e : events) {
      events_seen = e.sequence;
      output.event(e);
    }
  }

  void publish() { (void)driver->command(MotionRequest{*publishing, std::nullopt}); }

  void report_requests(const ScenarioOutput& output) {
    const auto snap = driver->snapshot();
    auto done = [&](const Pending& p) {
      const RequestOutcome* r = snap->request(p.id);
      std::string text;
      if (r == nullptr) {
        text = "outcome unknown (no longer tracked)";
      } else if (r->state == RequestOutcome::State::kAnswered ||
                 r->state == RequestOutcome::State::kFailed) {
        text = r->what + " " + std::string(to_string(r->state));
        if (!r->message.empty()) text += ": " + r->message;
      } else {
        return false;
      }
      if (output.note) {
        output.note("line " + std::to_string(p.line) + ": " + text + " (t=" + seconds_text(t) +
                    " s)");
      }
      return true;
    };
    pending.erase(std::remove_if(pending.begin(), pending.end(), done), pending.end());
  }

  ScenarioSample sample() const {
    ScenarioSample s;
    s.t = t;
    const ChassisSnapshot truth = sim->snapshot();
    s.truth = truth.pose;
    s.truth_twist = truth.twist;
    double speed = std::hypot(truth.twist.vx, truth.twist.vy);
    for (const WheelState& w : truth.wheels)
      speed = std::max(speed, std::fabs(w.speed));
    s.truth_speed = speed;
    const auto snap = driver->snapshot();
    s.odom = snap->odometry.pose;
    s.odom_twist = snap->odometry.twist;
    const ControllerState& c = snap->controller;
    if (c.control_mode) s.control_mode = std::string(protocol::to_string(*c.control_mode));
    if (c.chassis_mode) s.motion_mode = std::string(protocol::to_string(*c.chassis_mode));
    s.refusal = std::string(to_string(c.refusal));
    s.faults = c.faults;
    s.rearm_required = c.rearm_required();
    const std::string latched = describe(c.latched_causes);
    std::size_t start = 0;
    while (start < latched.size()) {
      const auto comma = latched.find(',', start);
      const auto end = comma == std::string::npos ? latched.size() : comma;
      s.latched.push_back(latched.substr(start, end - start));
      start = end + 1;
    }
    s.steer_first_factor = c.steer_first_factor;
    s.identification =
        snap->identification ? std::string(to_string(snap->identification->phase)) : "none";
    return s;
  }

  // Checks `e` against the state now; the "got ..." text on failure.
  std::optional<std::string> check(const Expectation& e) const {
    const ScenarioSample s = sample();
    switch (e.kind) {
      case Expectation::Kind::kEquals: {
        std::string got;
        if (e.field == "refusal") got = s.refusal;
        if (e.field == "control_mode") got = s.control_mode.value_or("null");
        if (e.field == "motion_mode") got = s.motion_mode.value_or("null");
        if (e.field == "rearm_required") got = s.rearm_required ? "true" : "false";
        if (e.field == "identification") got = s.identification;
        if (got == e.text) return std::nullopt;
        return got;
      }
      case Expectation::Kind::kCompare: {
        const double v = *sample_number(s, e.field);
        bool ok = false;
        switch (e.op) {
          case Expectation::Op::kGreater:
            ok = v > e.number;
            break;
          case Expectation::Op::kLess:
            ok = v < e.number;
            break;
          case Expectation::Op::kGreaterEqual:
            ok = v >= e.number;
            break;
          case Expectation::Op::kLessEqual:
            ok = v <= e.number;
            break;
          case Expectation::Op::kEqual:
            ok = v == e.number;
            break;
        }
        if (ok) return std::nullopt;
        return e.field == "t" ? seconds_text(s.t) : fixed(v, kDecimals);
      }
      case Expectation::Kind::kMoving:
      case Expectation::Kind::kStill: {
        const double v = *sample_number(s, "truth.speed");
        const bool moving = v > kStillSpeed;
        if (moving == (e.kind == Expectation::Kind::kMoving)) return std::nullopt;
        return "truth.speed " + fixed(v, kDecimals);
      }
      case Expectation::Kind::kFault:
      case Expectation::Kind::kNoFault:
      case Expectation::Kind::kNoFaults: {
        const bool present = contains(s.faults, e.text);
        if (e.kind == Expectation::Kind::kFault && present) return std::nullopt;
        if (e.kind == Expectation::Kind::kNoFault && !present) return std::nullopt;
        if (e.kind == Expectation::Kind::kNoFaults && s.faults.empty()) return std::nullopt;
        return "faults [" + join(s.faults) + "]";
      }
    }
    return std::string("?");
  }
};

namespace {

std::string describe_expectation(const Expectation& e) {
  switch (e.kind) {
    case Expectation::Kind::kEquals:
      return e.field + " " + e.text;
    case Expectation::Kind::kCompare: {
      return e.field + " " + op_text(e.op) + " " + e.text;
    }
    case Expectation::Kind::kMoving:
      return "moving (truth.speed > " + number_text(kStillSpeed) + ")";
    case Expectation::Kind::kStill:
      return "still (truth.speed <= " + number_text(kStillSpeed) + ")";
    case Expectation::Kind::kFault:
      return "fault " + e.text;
    case Expectation::Kind::kNoFault:
      return "no fault " + e.text;
    case Expectation::Kind::kNoFaults:
      return "no faults";
  }
  return "?";
}

}  // namespace

ScenarioRunner::ScenarioRunner(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ScenarioRunner::~ScenarioRunner() = default;

Result<std::unique_ptr<ScenarioRunner>> ScenarioRunner::create(const ScenarioOptions& options) {
  if (Status st = validate(options); !st) return st.error();
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  SimSourceOptions sim;
  sim.lock_step = true;
  sim.chassis = options.chassis;
  auto source = open_bus_source("sim:" + options.variant, impl->clock, sim);
  if (!source) return source.error();
  impl->sim = std::static_pointer_cast<SimBusSource>(*source);
  impl->driver = std::make_unique<Driver>(options.driver, *source, impl->clock);
  // t = 0: the chassis has booted (in standby); the driver opens its bus.
  impl->sim->step(impl->clock.now());
  impl->driver->step(impl->clock.now());
  return std::unique_ptr<ScenarioRunner>(new ScenarioRunner(std::move(impl)));
}

ScenarioSample ScenarioRunner::sample() const {
  return impl_->sample();
}

std::chrono::milliseconds ScenarioRunner::now() const {
  return impl_->t;
}

ScenarioResult ScenarioRunner::run(const Scenario& scenario, const ScenarioOutput& output) {
  Impl& m = *impl_;
  ScenarioResult result;
  std::optional<std::chrono::milliseconds> sampled;
  // The sample of time t goes out once everything scheduled at t has been done.
  auto sample_if_due = [&] {
    if (m.t.count() % m.options.every.count() != 0 || sampled == m.t) return;
    sampled = m.t;
    if (output.sample) output.sample(m.sample());
  };
  auto note = [&](std::size_t line, const std::string& text) {
    if (output.note) {
      output.note("line " + std::to_string(line) + ": " + text + " (t=" + seconds_text(m.t) +
                  " s)");
    }
  };

  if (output.event) m.report_events(output);  // those of t = 0
  for (const ScenarioAction& a : scenario.actions) {
    switch (a.kind) {
      case ScenarioAction::Kind::kCommand:
        m.publishing = a.twist;
        m.publish();
        m.next_publish = m.t + kPublishPeriod;
        break;
      case ScenarioAction::Kind::kCommandNone:
        m.publishing.reset();
        break;
      case ScenarioAction::Kind::kResume:
        m.pending.push_back({m.driver->resume(), a.line});
        break;
      case ScenarioAction::Kind::kMode:
        if (Status st = m.driver->set_motion_mode(a.mode); !st) note(a.line, st.error().message);
        break;
      case ScenarioAction::Kind::kPark:
        m.pending.push_back({m.driver->set_park(a.enable), a.line});
        break;
      case ScenarioAction::Kind::kClearErrors: {
        auto id = m.driver->clear_errors(a.code);
        if (id) {
          m.pending.push_back({*id, a.line});
        } else {
          note(a.line, id.error().message);
        }
        break;
      }
      case ScenarioAction::Kind::kChassis: {
        const std::string text =
            m.sim->with_chassis([&](VirtualChassis& c) { return a.chassis(c); });
        if (!text.empty()) note(a.line, text);
        break;
      }
      case ScenarioAction::Kind::kWait:
        for (auto i = a.wait.count(); i > 0; --i) {
          sample_if_due();
          m.step(output);
        }
        break;
      case ScenarioAction::Kind::kExpect: {
        ++result.expectations;
        if (auto got = m.check(a.expect)) {
          ++result.failures;
          if (output.failure) {
            output.failure("line " + std::to_string(a.line) + ": expected " +
                           describe_expectation(a.expect) + ", got " + *got +
                           " (t=" + seconds_text(m.t) + " s)");
          }
        }
        break;
      }
    }
  }
  sample_if_due();
  return result;
}

Result<ScenarioResult> run_scenario(const Scenario& scenario, const ScenarioOptions& options,
                                    std::ostream& out, std::ostream& err, std::string_view prefix) {
  auto runner = ScenarioRunner::create(options);
  if (!runner) return runner.error();
  std::size_t failures_shown = 0;
  std::string line;
  std::string events;  // the driver's events since the last sample: ,{...},{...}
  ScenarioOutput output;
  output.event = [&](const DriverEvent& e) { events += "," + to_json(e, kEpoch); };
  // A sample carries the events since the one before ("events":[...], only when there are).
  const auto with_events = [&](std::string json) {
    if (!events.empty()) json.insert(json.size() - 1, ",\"events\":[" + events.substr(1) + "]");
    events.clear();
    return json + '\n';
  };
  output.sample = [&](const ScenarioSample& s) {
    line = with_events(to_json(s));
    out << line;
  };
  output.failure = [&](const std::string& text) {
    if (failures_shown < kMaxReportedErrors) err << prefix << text << "\n";
    ++failures_shown;
  };
  output.note = [&](const std::string& text) { err << prefix << text << "\n"; };
  const ScenarioResult result = (*runner)->run(scenario, output);
  // Events after the last sample (a script that ends between samples).
  if (!events.empty()) out << with_events("{\"t\":" + seconds_text((*runner)->now()) + "}");
  out.flush();
  if (result.failures > kMaxReportedErrors) {
    err << prefix << (result.failures - kMaxReportedErrors)
        << " more failed expectation(s) not shown\n";
  }
  return result;
}

const std::string& scenario_language_help() {
  static const std::string text = [] {
    std::string chassis = kChassisCommandHelp;
    chassis.erase(0, chassis.find('\n') + 1);  // its own "commands (one per line):" heading
    return std::string(kActionsHelp) + chassis + expect_help();
  }();
  return text;
}

}  // namespace ranger::sim
