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
#include "ranger_can/json.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/sim/bus_recording.hpp"
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
    "  drive_mode current|voltage\n"
    "                           Driver::set_drive_mode(): 0x423 (the RANGER MINI 3.0's)\n"
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

// The line without its comment, trimmed.
std::string_view strip(std::string_view line) {
  return text::trim(line.substr(0, line.find('#')));
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
      out += text::format("\\x%02X", u);
    }
  }
  return out;
}

// ---- names the checks accept ----

const std::vector<std::string>& refusal_names() {
  static const std::vector<std::string> names = kMotionRefusalNames.names();
  return names;
}

// An enum's names and "null" (the field has no value yet).
template <typename Enum, std::size_t N>
std::vector<std::string> names_or_null(const text::EnumNames<Enum, N>& table) {
  std::vector<std::string> names = table.names();
  names.emplace_back("null");
  return names;
}

const std::vector<std::string>& control_mode_names() {
  static const std::vector<std::string> names = names_or_null(protocol::kControlModeNames);
  return names;
}

// The identification's phases (protocol auto), and "none" for a protocol that was given.
const std::vector<std::string>& identification_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out = kIdentificationPhaseNames.names();
    out.emplace_back("none");
    return out;
  }();
  return names;
}

const std::vector<std::string>& motion_mode_names() {
  static const std::vector<std::string> names = names_or_null(protocol::kMotionModeNames);
  return names;
}

const std::vector<std::string>& drive_mode_names() {
  static const std::vector<std::string> names = names_or_null(protocol::kDriveModeNames);
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
    std::vector<std::string> n = kControllerFaultNames.names();
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
         help_entry("  expect drive_mode " + join(drive_mode_names(), "|"),
                    "(0x291 byte 2, the RANGER MINI 3.0's; null elsewhere)") +
         help_entry("  expect identification NAME",
                    "the identification's phase: " + join(identification_names()) +
                        " (none: the protocol was given)") +
         help_entry("  expect moving | still",
                    "ground truth: the fastest point of the chassis (body centre or a wheel) is "
                    "faster than 1 mm/s | not faster") +
         help_entry("  expect fault NAME | no-fault NAME | no-faults", "") +
         help_entry("", "NAME as in the output's faults: the driver's (" +
                            join(kControllerFaultNames.names()) +
                            "), a 0x211 fault of any error-word layout (" +
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

// `v` as the samples print it: kDecimals decimals, no sign on a zero, null if not finite.
std::string printed(double v) {
  std::string out;
  append_json_fixed(out, v, kDecimals);
  return out;
}

double as_printed(double v) {
  return std::strtod(printed(v).c_str(), nullptr);
}

std::string seconds_text(std::chrono::milliseconds t) {
  return text::fixed(static_cast<double>(t.count()) / 1000.0, 3);
}

// ---- parsing ----

using Kind = Expectation::Kind;

// The text fields a check compares: the values each may hold, and its value in a sample.
struct TextField {
  std::string_view name;
  const std::vector<std::string>& (*valid)();
  std::string (*value)(const ScenarioSample&);
};
const TextField kTextFields[] = {
    {"refusal", refusal_names, [](const ScenarioSample& s) { return s.refusal; }},
    {"control_mode", control_mode_names,
     [](const ScenarioSample& s) { return s.control_mode.value_or("null"); }},
    {"motion_mode", motion_mode_names,
     [](const ScenarioSample& s) { return s.motion_mode.value_or("null"); }},
    {"rearm_required", bool_names,
     [](const ScenarioSample& s) { return std::string(s.rearm_required ? "true" : "false"); }},
    {"identification", identification_names,
     [](const ScenarioSample& s) { return s.identification; }},
    {"drive_mode", drive_mode_names,
     [](const ScenarioSample& s) { return s.drive_mode.value_or("null"); }},
};
const TextField* find_text_field(std::string_view name) {
  for (const TextField& f : kTextFields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

// The checks that take no argument, and those that name a fault.
constexpr auto kBareChecks = text::enum_names<Kind>({
    {Kind::kMoving, "moving"},
    {Kind::kStill, "still"},
    {Kind::kNoFaults, "no-faults"},
});
constexpr auto kFaultChecks = text::enum_names<Kind>({
    {Kind::kFault, "fault"},
    {Kind::kNoFault, "no-fault"},
});

const char* const kExpectUsage =
    "expect: give one of: refusal NAME, control_mode NAME, motion_mode NAME, rearm_required "
    "true|false, identification PHASE, drive_mode NAME, moving, still, fault NAME, no-fault NAME, "
    "no-faults, FIELD OP NUMBER";

Status need_words(const std::vector<std::string>& w, std::size_t n, const std::string& form) {
  if (w.size() != n) return problem("usage: " + form);
  return ok_status();
}

// expect fault NAME | no-fault NAME
Status parse_fault_check(const std::vector<std::string>& w, Expectation& e) {
  const std::string& what = w[1];
  if (auto st = need_words(w, 3, "expect " + what + " NAME"); !st) return st;
  if (!contains(fault_names(), w[2])) {
    return problem("expect " + what + ": unknown fault '" + w[2] +
                   "' (the driver's: link_lost, emergency_stop, vehicle_abnormal, low_battery, "
                   "motion_mode_switch_failed, ...; or a 0x211 error bit's name, e.g. "
                   "over_current)");
  }
  e.kind = *kFaultChecks.parse(what);
  e.text = w[2];
  return ok_status();
}

// expect FIELD NAME (a text field)
Status parse_text_check(const std::vector<std::string>& w, const TextField& f, Expectation& e) {
  const std::string& what = w[1];
  const std::vector<std::string>& valid = f.valid();
  if (auto st = need_words(w, 3, "expect " + what + " " + join(valid, "|")); !st) return st;
  if (!contains(valid, w[2])) return not_one_of("expect " + what, w[2], valid);
  e.kind = Kind::kEquals;
  e.text = w[2];
  return ok_status();
}

// expect FIELD OP NUMBER (a number field)
Status parse_compare(const std::vector<std::string>& w, Expectation& e) {
  const std::string& what = w[1];
  if (w.size() != 4) {
    return problem("usage: expect " + what + " " + join(kOpNames.names(), "|") + " NUMBER");
  }
  const auto op = kOpNames.parse(w[2]);
  if (!op) {
    return problem("expect " + what + ": unknown operator '" + w[2] +
                   "' (valid: " + join(kOpNames.names()) + ")");
  }
  auto number = parse_double("expect " + what, w[3]);
  if (!number) return number.error();
  e.kind = Kind::kCompare;
  e.op = *op;
  e.number = *number;
  e.text = w[3];  // as written, for messages
  return ok_status();
}

Result<Expectation> parse_expect(const std::vector<std::string>& w) {
  // w[0] == "expect"
  if (w.size() < 2) return problem(kExpectUsage);
  const std::string& what = w[1];
  Expectation e;
  e.field = what;
  Status st = ok_status();
  if (const auto kind = kBareChecks.parse(what)) {
    st = need_words(w, 2, "expect " + what);
    e.kind = *kind;
  } else if (kFaultChecks.parse(what)) {
    st = parse_fault_check(w, e);
  } else if (const TextField* f = find_text_field(what)) {
    st = parse_text_check(w, *f, e);
  } else if (contains(sample_number_fields(), what)) {
    st = parse_compare(w, e);
  } else {
    return problem("expect: unknown check '" + what + "' (" + std::string(kExpectUsage).substr(8) +
                   "; FIELD: " + join(sample_number_fields()) + ")");
  }
  if (!st) return st.error();
  return e;
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

namespace {

// ---- the driver's actions: one parser per verb ----

using Words = std::vector<std::string>;

Status parse_cmd(const Words& w, ScenarioAction& a) {
  if (w.size() == 2 && w[1] == "none") {
    a.kind = ScenarioAction::Kind::kCommandNone;
    return ok_status();
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
  return ok_status();
}

Status parse_resume(const Words& w, ScenarioAction& a) {
  if (w.size() != 1) return problem("usage: resume (takes no argument)");
  a.kind = ScenarioAction::Kind::kResume;
  return ok_status();
}

Status parse_drive_mode(const Words& w, ScenarioAction& a) {
  const std::string usage = "drive_mode " + join(protocol::kDriveModeNames.names(), "|");
  if (w.size() != 2) return problem("usage: " + usage);
  const auto mode = protocol::kDriveModeNames.parse(w[1]);
  if (!mode) return not_one_of("drive_mode", w[1], protocol::kDriveModeNames.names());
  a.kind = ScenarioAction::Kind::kDriveMode;
  a.code = static_cast<std::uint8_t>(*mode);
  return ok_status();
}

Status parse_park(const Words& w, ScenarioAction& a) {
  if (w.size() != 2 || (w[1] != "on" && w[1] != "off")) return problem("usage: park on|off");
  a.kind = ScenarioAction::Kind::kPark;
  a.enable = w[1] == "on";
  return ok_status();
}

// `mode`'s words: auto and every mode a commander may pin (park has an action of its own).
const std::vector<std::string>& mode_words() {
  static const std::vector<std::string> words = [] {
    std::vector<std::string> out = {"auto"};
    for (const auto& [mode, name] : protocol::kMotionModeNames) {
      if (mode != MotionMode::kPark) out.emplace_back(name);
    }
    return out;
  }();
  return words;
}

Status parse_mode(const Words& w, ScenarioAction& a) {
  if (w.size() != 2) return problem("usage: mode " + join(mode_words(), "|"));
  if (!contains(mode_words(), w[1])) return not_one_of("mode", w[1], mode_words());
  a.kind = ScenarioAction::Kind::kMode;
  a.mode = protocol::kMotionModeNames.parse(w[1]);  // nullopt: auto
  return ok_status();
}

Status parse_clear_errors(const Words& w, ScenarioAction& a) {
  if (w.size() != 2) return problem("usage: clear-errors CODE (0-16 or 0x00-0x10)");
  auto code = parse_integer("clear-errors CODE", w[1], 0, protocol::kMaxErrorClearCode);
  if (!code) return code.error();
  a.kind = ScenarioAction::Kind::kClearErrors;
  a.code = static_cast<std::uint8_t>(*code);
  return ok_status();
}

Status parse_wait(const Words& w, ScenarioAction& a) {
  if (w.size() != 2) return problem("usage: wait SEC");
  auto ms = parse_milliseconds("wait SEC", w[1]);
  if (!ms) return ms.error();
  a.kind = ScenarioAction::Kind::kWait;
  a.wait = *ms;
  return ok_status();
}

Status parse_expect_action(const Words& w, ScenarioAction& a) {
  auto e = parse_expect(w);
  if (!e) return e.error();
  a.kind = ScenarioAction::Kind::kExpect;
  a.expect = std::move(*e);
  return ok_status();
}

struct Verb {
  std::string_view word;
  Status (*parse)(const Words& w, ScenarioAction& a);
};
const Verb kVerbs[] = {
    {"cmd", parse_cmd},   {"resume", parse_resume},
    {"mode", parse_mode}, {"clear-errors", parse_clear_errors},
    {"wait", parse_wait}, {"expect", parse_expect_action},
    {"park", parse_park}, {"drive_mode", parse_drive_mode},
};

const std::vector<std::string>& driver_action_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Verb& v : kVerbs)
      out.emplace_back(v.word);
    return out;
  }();
  return names;
}

}  // namespace

Result<std::optional<ScenarioAction>> parse_scenario_line(std::string_view raw, std::size_t line) {
  const std::string_view text = strip(raw);
  if (text.empty()) return std::optional<ScenarioAction>();
  const auto w = text::split_words(text);
  ScenarioAction a;
  a.line = line;
  a.text = std::string(text);
  const std::string& verb = w[0];
  for (const Verb& v : kVerbs) {
    if (verb != v.word) continue;
    if (Status st = v.parse(w, a); !st) return st.error();
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
    if (f.name == field) return as_printed(f.value);
  }
  return std::nullopt;
}

namespace {

// The sample's fields, into an object `w` has begun.
void write_sample(JsonWriter& w, const ScenarioSample& s) {
  auto pose = [&](const Pose2D& p, const BodyTwist& v) {
    w.key("x").fixed(p.x, kDecimals).key("y").fixed(p.y, kDecimals);
    w.key("yaw").fixed(p.yaw, kDecimals);
    w.key("vx").fixed(v.vx, kDecimals).key("vy").fixed(v.vy, kDecimals);
    w.key("wz").fixed(v.wz, kDecimals);
  };
  w.key("t").fixed(static_cast<double>(s.t.count()) / 1000.0, 3);
  w.key("truth").begin_object();
  pose(s.truth, s.truth_twist);
  w.key("speed").fixed(s.truth_speed, kDecimals).end_object();
  w.key("odom").begin_object();
  pose(s.odom, s.odom_twist);
  w.end_object();
  w.key("control_mode").string_or_null(s.control_mode);
  w.key("motion_mode").string_or_null(s.motion_mode);
  w.key("refusal").string(s.refusal);
  w.key("faults").strings(s.faults);
  w.key("rearm_required").boolean(s.rearm_required);
  w.key("latched").strings(s.latched);
  w.key("steer_first_factor").fixed(s.steer_first_factor, kDecimals);
  w.key("identification").string(s.identification);
  if (s.drive_mode) w.key("drive_mode").string(*s.drive_mode);
}

// "events":[...] of the driver's events (each one JSON object), none when there are none.
void write_events(JsonWriter& w, const std::vector<std::string>& events) {
  if (events.empty()) return;
  w.key("events").begin_array();
  for (const std::string& e : events)
    w.raw(e);
  w.end_array();
}

}  // namespace

std::string to_json(const ScenarioSample& s) {
  std::string out;
  out.reserve(512);
  JsonWriter w(out);
  w.begin_object();
  write_sample(w, s);
  w.end_object();
  return out;
}

// ---- the runner ----

namespace {
// `v OP number`.
bool holds(double v, Expectation::Op op, double number) {
  switch (op) {
    case Expectation::Op::kGreater:
      return v > number;
    case Expectation::Op::kLess:
      return v < number;
    case Expectation::Op::kGreaterEqual:
      return v >= number;
    case Expectation::Op::kLessEqual:
      return v <= number;
    case Expectation::Op::kEqual:
      return v == number;
  }
  return false;
}
}  // namespace

struct ScenarioRunner::Impl {
  ScenarioOptions options;
  ManualClock clock{kEpoch};
  std::shared_ptr<SimBusSource> sim;  // before the driver: destroyed after it
  std::unique_ptr<Driver> driver;
  std::unique_ptr<CandumpRecording> recording;  // --candump
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
    if (recording) recording->drain();
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
    s.latched = text::split(describe(c.latched_causes), ',');
    s.steer_first_factor = c.steer_first_factor;
    s.identification =
        snap->identification ? std::string(to_string(snap->identification->phase)) : "none";
    if (snap->drive_mode) s.drive_mode = std::string(protocol::to_string(*snap->drive_mode));
    return s;
  }

  // Checks `e` against the state now; the "got ..." text on failure.
  std::optional<std::string> check(const Expectation& e) const {
    const ScenarioSample s = sample();
    switch (e.kind) {
      case Kind::kEquals: {
        std::string got = find_text_field(e.field)->value(s);
        if (got == e.text) return std::nullopt;
        return got;
      }
      case Kind::kCompare: {
        const double v = *sample_number(s, e.field);
        if (holds(v, e.op, e.number)) return std::nullopt;
        return e.field == "t" ? seconds_text(s.t) : printed(v);
      }
      case Kind::kMoving:
      case Kind::kStill: {
        const double v = *sample_number(s, "truth.speed");
        const bool moving = v > kStillSpeed;
        if (moving == (e.kind == Kind::kMoving)) return std::nullopt;
        return "truth.speed " + printed(v);
      }
      case Kind::kFault:
      case Kind::kNoFault:
      case Kind::kNoFaults: {
        const bool present = contains(s.faults, e.text);
        if (e.kind == Kind::kFault && present) return std::nullopt;
        if (e.kind == Kind::kNoFault && !present) return std::nullopt;
        if (e.kind == Kind::kNoFaults && s.faults.empty()) return std::nullopt;
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
      return e.field + " " + std::string(kOpNames.name(e.op)) + " " + e.text;
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
  if (options.candump) {
    auto tap = impl->sim->open();
    if (!tap) return tap.error();
    impl->recording = std::make_unique<CandumpRecording>(std::move(*tap), *options.candump, kEpoch);
  }
  // t = 0: the chassis has booted (in standby); the driver opens its bus.
  impl->sim->step(impl->clock.now());
  impl->driver->step(impl->clock.now());
  if (impl->recording) impl->recording->drain();
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
      case ScenarioAction::Kind::kDriveMode:
        m.pending.push_back(
            {m.driver->set_drive_mode(static_cast<protocol::DriveMode>(a.code)), a.line});
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
  std::vector<std::string> events;  // the driver's events since the last sample
  ScenarioOutput output;
  output.event = [&](const DriverEvent& e) { events.push_back(to_json(e, kEpoch)); };
  // A sample carries the events since the one before ("events":[...], only when there are).
  output.sample = [&](const ScenarioSample& s) {
    line.clear();
    JsonWriter w(line);
    w.begin_object();
    write_sample(w, s);
    write_events(w, events);
    w.end_object();
    events.clear();
    out << line << '\n';
  };
  output.failure = [&](const std::string& text) {
    if (failures_shown < kMaxReportedErrors) err << prefix << text << "\n";
    ++failures_shown;
  };
  output.note = [&](const std::string& text) { err << prefix << text << "\n"; };
  const ScenarioResult result = (*runner)->run(scenario, output);
  // Events after the last sample (a script that ends between samples).
  if (!events.empty()) {
    line.clear();
    JsonWriter w(line);
    w.begin_object().key("t").fixed(static_cast<double>((*runner)->now().count()) / 1000.0, 3);
    write_events(w, events);
    w.end_object();
    out << line << '\n';
  }
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
