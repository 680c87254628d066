// Scenarios (sim/scenario.hpp) and `ranger_can scenario`: the script parser and its errors (every
// bad line named, nothing run), driver parameters, the output format, and short runs of the
// driver against the virtual chassis in simulated time (no threads, no sleeping). The behaviour
// scripts themselves live in tests/scenarios/ (one ctest each).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_commands.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/sim/scenario.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/cli_run.hpp"

namespace ranger::sim {
namespace {

using namespace std::chrono_literals;
using Kind = ScenarioAction::Kind;

bool contains(const std::string& hay, const std::string& needle) {
  return hay.find(needle) != std::string::npos;
}

Scenario parse_ok(const std::string& text) {
  auto s = parse_scenario(text);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return s.ok() ? *s : Scenario{};
}

std::string parse_error(const std::string& text) {
  auto s = parse_scenario(text);
  EXPECT_FALSE(s.ok()) << "accepted: " << text;
  return s.ok() ? "" : s.error().message;
}

struct RunOutcome {
  ScenarioResult result;
  std::vector<ScenarioSample> samples;
  std::vector<std::string> failures;
  std::vector<std::string> notes;
};

RunOutcome run(const std::string& text, ScenarioOptions options = {}) {
  RunOutcome r;
  const Scenario scenario = parse_ok(text);
  auto runner = ScenarioRunner::create(options);
  EXPECT_TRUE(runner.ok()) << (runner.ok() ? "" : runner.error().message);
  if (!runner.ok()) return r;
  ScenarioOutput out;
  out.sample = [&](const ScenarioSample& s) { r.samples.push_back(s); };
  out.failure = [&](const std::string& f) { r.failures.push_back(f); };
  out.note = [&](const std::string& n) { r.notes.push_back(n); };
  r.result = (*runner)->run(scenario, out);
  return r;
}

// ---- parsing ------------------------------------------------------------------------------------

TEST(ScenarioParse, EveryActionWithItsLineNumber) {
  const Scenario s = parse_ok(
      "# a comment line\n"
      "\n"
      "cmd 0.5 -0.25 1e-1   # trailing comment\n"
      "cmd none\n"
      "resume\n"
      "mode spin\n"
      "mode auto\n"
      "clear-errors 0x0F\n"
      "clear-errors 9\n"
      "estop on\n"
      "  wait 1.25  \r\n"
      "expect refusal rearm_required\n"
      "expect truth.x >= -0.5\n"
      "expect moving\n"
      "expect no-fault over_current\n"
      "wait 0.001\n");
  ASSERT_EQ(s.actions.size(), 14u);
  const Kind kinds[] = {Kind::kCommand, Kind::kCommandNone, Kind::kResume,      Kind::kMode,
                        Kind::kMode,    Kind::kClearErrors, Kind::kClearErrors, Kind::kChassis,
                        Kind::kWait,    Kind::kExpect,      Kind::kExpect,      Kind::kExpect,
                        Kind::kExpect,  Kind::kWait};
  for (std::size_t i = 0; i < s.actions.size(); ++i)
    EXPECT_EQ(s.actions[i].kind, kinds[i]) << i;
  EXPECT_EQ(s.actions[0].line, 3u);
  EXPECT_EQ(s.actions[0].text, "cmd 0.5 -0.25 1e-1");
  EXPECT_EQ(s.actions[0].twist.vx, 0.5);
  EXPECT_EQ(s.actions[0].twist.vy, -0.25);
  EXPECT_EQ(s.actions[0].twist.wz, 0.1);
  EXPECT_EQ(s.actions[3].mode, protocol::MotionMode::kSpin);
  EXPECT_FALSE(s.actions[4].mode.has_value());
  EXPECT_EQ(s.actions[5].code, 0x0F);
  EXPECT_EQ(s.actions[6].code, 9);
  EXPECT_EQ(s.actions[8].line, 11u);
  EXPECT_EQ(s.actions[8].wait, 1250ms);
  EXPECT_EQ(s.actions[9].expect.kind, Expectation::Kind::kEquals);
  EXPECT_EQ(s.actions[9].expect.text, "rearm_required");
  EXPECT_EQ(s.actions[10].expect.kind, Expectation::Kind::kCompare);
  EXPECT_EQ(s.actions[10].expect.op, Expectation::Op::kGreaterEqual);
  EXPECT_EQ(s.actions[10].expect.number, -0.5);
  EXPECT_EQ(s.duration, 1251ms);
  EXPECT_EQ(s.expectations, 4u);
}

// Every name the driver can report, taken from the enums' name tables and the fault table (a new
// enumerator or fault is covered without touching this test), is a valid `expect` value that
// parses back to the same name.
TEST(ScenarioParse, EveryNameOfTheEnumsAndTheFaultTableIsAccepted) {
  std::vector<std::pair<std::string, std::string>> checks;  // field, name
  for (const auto& n : kMotionRefusalNames.names())
    checks.emplace_back("refusal", n);
  for (const auto& n : protocol::kControlModeNames.names())
    checks.emplace_back("control_mode", n);
  for (const auto& n : protocol::kMotionModeNames.names())
    checks.emplace_back("motion_mode", n);
  for (const auto& n : kControllerFaultNames.names())
    checks.emplace_back("fault", n);
  for (const protocol::FaultInfo& f : protocol::kFaultTable)
    checks.emplace_back("fault", std::string(f.name));
  checks.emplace_back("fault", "reserved_bit_31");
  for (const auto& [field, name] : checks) {
    EXPECT_NE(name, "unknown") << field;
    const Scenario s = parse_ok("expect " + field + " " + name + "\n");
    ASSERT_EQ(s.actions.size(), 1u) << field << " " << name;
    EXPECT_EQ(s.actions[0].expect.text, name) << field;
  }
  // `identifying` and `uart` among them, by name.
  EXPECT_EQ(parse_ok("expect refusal identifying\n").actions.size(), 1u);
  EXPECT_EQ(parse_ok("expect control_mode uart\n").actions.size(), 1u);
  EXPECT_EQ(parse_ok("expect fault steering_encoder_fault\n").actions.size(), 1u);
}

TEST(ScenarioParse, BadLinesNameTheLineAndTheProblem) {
  struct Case {
    std::string line;
    std::string mentions;
  };
  const Case cases[] = {
      {"drive 1 2 3", "unknown action 'drive'"},
      {"drive 1 2 3", "estop"},  // the valid ones are listed, chassis commands included
      {"cmd 1 2", "usage: cmd VX VY WZ"},
      {"cmd 1 2 3 4", "usage: cmd VX VY WZ"},
      {"cmd nan 0 0", "cmd VX: 'nan' is not a finite number"},
      {"cmd 0 inf 0", "cmd VY: 'inf'"},
      {"cmd 0 0 1e999", "cmd WZ"},
      {"cmd 0 0 fast", "'fast' is not a number"},
      {"cmd stop", "usage: cmd VX VY WZ  or  cmd none"},
      {"wait -1", "wait SEC: '-1' is negative"},
      {"wait -0.001", "is negative"},
      {"wait soon", "'soon' is not a number"},
      {"wait nan", "not a finite number"},
      {"wait 0.0005", "not a whole number of milliseconds"},
      {"wait 1e9", "longer than 3600 s"},
      {"wait", "usage: wait SEC"},
      {"wait 1 2", "usage: wait SEC"},
      {"resume now", "takes no argument"},
      {"mode sideways", "mode: unknown 'sideways'"},
      {"mode", "usage: mode"},
      {"clear-errors 0x11", "clear-errors CODE: '0x11' is outside [0, 16]"},
      {"clear-errors all", "'all' is not an integer"},
      {"estop maybe", "estop: expected 'on' or 'off', got 'maybe'"},
      {"pose 1 2", "usage: pose X Y YAW"},
      {"battery 150", "battery PCT"},
      {"expect", "expect: give one of"},
      {"expect refusal stopped", "expect refusal: unknown 'stopped'"},
      {"expect refusal", "usage: expect refusal"},
      {"expect control_mode manual", "unknown 'manual' (valid: standby, can, uart, remote, null)"},
      {"expect motion_mode crab", "unknown 'crab'"},
      {"expect rearm_required yes", "unknown 'yes' (valid: true, false)"},
      {"expect fault estop", "unknown fault 'estop'"},
      {"expect no-fault", "usage: expect no-fault NAME"},
      {"expect moving fast", "usage: expect moving"},
      {"expect truth.z > 1", "unknown check 'truth.z'"},
      {"expect truth.x >> 1", "unknown operator '>>'"},
      {"expect truth.x > far", "'far' is not a number"},
      {"expect truth.x > nan", "not a finite number"},
      {"expect truth.x 1", "usage: expect truth.x >|<|>=|<=|== NUMBER"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.line);
    const std::string message = parse_error("wait 1\n" + c.line + "\nwait 1\n");
    EXPECT_EQ(message.rfind("line 2: ", 0), 0u) << message;
    EXPECT_TRUE(contains(message, c.mentions)) << message;
  }
}

TEST(ScenarioParse, EveryBadLineIsReportedAndNothingIsReturned) {
  const std::string message = parse_error(
      "wait 1\n"
      "bogus\n"
      "cmd 1 2 3\n"
      "wait -2\n"
      "expect nothing\n");
  EXPECT_TRUE(contains(message, "line 2: unknown action 'bogus'")) << message;
  EXPECT_TRUE(contains(message, "line 4: wait SEC: '-2' is negative")) << message;
  EXPECT_TRUE(contains(message, "line 5: expect: unknown check 'nothing'")) << message;
  EXPECT_FALSE(contains(message, "line 1")) << message;
  EXPECT_FALSE(contains(message, "line 3")) << message;
}

TEST(ScenarioParse, ReportsAreBoundedAndCounted) {
  std::string text;
  for (int i = 0; i < 50; ++i)
    text += "nonsense\n";
  const std::string message = parse_error(text);
  EXPECT_EQ(test::lines_of(message).size(), 21u);
  EXPECT_TRUE(contains(message, "line 20: unknown action")) << message;
  EXPECT_FALSE(contains(message, "line 21:")) << message;
  EXPECT_TRUE(contains(message, "30 more bad line(s) not shown")) << message;
}

TEST(ScenarioParse, TheSimulatedTimeIsBounded) {
  const std::string message = parse_error("wait 3000\nwait 600\nwait 1\n");
  EXPECT_EQ(message, "line 3: the script runs past the 3600 s limit of simulated time");
  EXPECT_EQ(parse_ok("wait 3000\nwait 600\n").duration, 3600s);
}

TEST(ScenarioParse, HostileInputIsRefusedWithoutCrashing) {
  // A line without a newline far longer than any action.
  const std::string message = parse_error(std::string(1 << 20, 'x'));
  EXPECT_EQ(message, "line 1: longer than 4096 characters");
  // Binary bytes, NULs included.
  std::string binary;
  for (int i = 0; i < 4096; ++i)
    binary.push_back(static_cast<char>((i * 37) & 0xFF));
  const std::string binary_message = parse_error(binary);
  EXPECT_TRUE(contains(binary_message, "line 1: unknown action '\\x00%J")) << binary_message;
  for (char c : binary_message)
    EXPECT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7F)) << "unprintable byte in the message";
  // Too many lines (blank ones count).
  EXPECT_TRUE(
      contains(parse_error(std::string(kMaxScenarioLines + 1, '\n')), "longer than 100000 lines"));
  // Nothing at all is a valid, empty script.
  EXPECT_TRUE(parse_ok("").actions.empty());
  EXPECT_TRUE(parse_ok("# only a comment\n\n").actions.empty());
}

TEST(ScenarioParse, ParseMillisecondsIsStrict) {
  EXPECT_EQ(*parse_milliseconds("x", "0"), 0ms);
  EXPECT_EQ(*parse_milliseconds("x", "0.1"), 100ms);
  EXPECT_EQ(*parse_milliseconds("x", "2.5"), 2500ms);
  EXPECT_EQ(*parse_milliseconds("x", "3600"), 3600000ms);
  for (const char* bad : {"", "-0.1", "0.0001", "3600.001", "1s", "nan", "inf"})
    EXPECT_FALSE(parse_milliseconds("x", bad).ok()) << bad;
}

// ---- parameters and options ---------------------------------------------------------------------

TEST(ScenarioParams, SetTheDriverSettingsByName) {
  DriverConfig c;
  ASSERT_TRUE(apply_scenario_param(c, "steer_first_threshold=0").ok());
  EXPECT_EQ(c.controller.steer_first_threshold, 0.0);
  ASSERT_TRUE(apply_scenario_param(c, "cmd_vel_timeout=2.5").ok());
  EXPECT_EQ(c.controller.cmd_timeout, 2500ms);
  ASSERT_TRUE(apply_scenario_param(c, "auto_reclaim_after_remote=true").ok());
  EXPECT_TRUE(c.controller.auto_reclaim_after_remote);
  ASSERT_TRUE(apply_scenario_param(c, "mode_switch_timeout=0.5").ok());
  EXPECT_EQ(c.controller.mode_switch_timeout, 500ms);
  ASSERT_TRUE(apply_scenario_param(c, "low_battery_soc=20").ok());
  EXPECT_EQ(c.controller.low_battery_soc, 20.0);
  EXPECT_TRUE(c.validate().ok());
}

TEST(ScenarioParams, BadAssignmentsSayWhatIsWrong) {
  struct Case {
    const char* text;
    const char* mentions;
  };
  const Case cases[] = {
      {"steer_first_threshold", "expected NAME=VALUE"},
      {"=1", "expected NAME=VALUE"},
      {"steer_first=0", "unknown parameter 'steer_first' (valid: steer_first_threshold"},
      {"steer_first_threshold=2", "steer_first_threshold: '2' is outside [0, 1.5708]"},
      {"steer_first_threshold=", "steer_first_threshold: '' is not a number"},
      {"cmd_vel_timeout=0", "cmd_vel_timeout: '0' is outside [0.02, 60] s"},
      {"cmd_vel_timeout=nan", "not a finite number"},
      {"mode_switch_max_attempts=1.5", "mode_switch_max_attempts: '1.5' is outside [1, 100]"},
      {"auto_reclaim_after_remote=1", "expected true or false, got '1'"},
      {"low_battery_soc=101", "low_battery_soc"},
  };
  for (const Case& c : cases) {
    DriverConfig config;
    const Status st = apply_scenario_param(config, c.text);
    ASSERT_FALSE(st.ok()) << c.text;
    EXPECT_TRUE(contains(st.error().message, c.mentions)) << c.text << ": " << st.error().message;
  }
}

TEST(ScenarioOptionsCheck, AnUnknownVariantIsRefusedWithTheValidOnes) {
  ScenarioOptions o;
  o.variant = "agx_v9";
  const Status st = validate(o);
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(contains(st.error().message, "agx_v9")) << st.error().message;
  EXPECT_TRUE(contains(st.error().message, "manual")) << st.error().message;
  EXPECT_FALSE(ScenarioRunner::create(o).ok());
  o.variant = "manual";
  o.every = 0ms;
  EXPECT_FALSE(validate(o).ok());
}

// ---- output format ------------------------------------------------------------------------------

TEST(ScenarioOutput, FixedFormattingWithoutNegativeZero) {
  ScenarioSample s;
  s.t = 12345ms;
  s.truth = Pose2D{1.0 / 3.0, -1e-9, -0.0};
  s.truth_twist = BodyTwist{0.5, -0.25, 2.0};
  s.truth_speed = 0.5;
  s.odom = Pose2D{-1234.5678901, 0.0, M_PI};
  s.control_mode = "can";
  s.refusal = "rearm_required";
  s.faults = {"emergency_stop", "over_current"};
  s.rearm_required = true;
  s.latched = {"emergency_stop"};
  s.steer_first_factor = 0.25;
  EXPECT_EQ(to_json(s),
            "{\"t\":12.345,\"truth\":{\"x\":0.333333,\"y\":0.000000,\"yaw\":0.000000,"
            "\"vx\":0.500000,\"vy\":-0.250000,\"wz\":2.000000,\"speed\":0.500000},"
            "\"odom\":{\"x\":-1234.567890,\"y\":0.000000,\"yaw\":3.141593,\"vx\":0.000000,"
            "\"vy\":0.000000,\"wz\":0.000000},\"control_mode\":\"can\",\"motion_mode\":null,"
            "\"refusal\":\"rearm_required\",\"faults\":[\"emergency_stop\",\"over_current\"],"
            "\"rearm_required\":true,\"latched\":[\"emergency_stop\"],"
            "\"steer_first_factor\":0.250000,\"identification\":\"none\"}");
  // Checks compare the value as printed.
  EXPECT_EQ(*sample_number(s, "truth.x"), 0.333333);
  EXPECT_EQ(*sample_number(s, "truth.y"), 0.0);
  EXPECT_EQ(*sample_number(s, "t"), 12.345);
  EXPECT_FALSE(sample_number(s, "truth.z").has_value());
  for (const std::string& f : sample_number_fields())
    EXPECT_TRUE(sample_number(s, f).has_value()) << f;
}

// ---- runs ---------------------------------------------------------------------------------------

TEST(ScenarioRun, SamplesAtZeroAndEveryPeriodAfterTheActionsOfThatTime) {
  ScenarioOptions o;
  o.every = 250ms;
  const RunOutcome r = run("pose 1 2 0\nwait 1\nwait 0.1\n", o);
  ASSERT_EQ(r.samples.size(), 5u);  // 0, 0.25, 0.5, 0.75, 1.0 (1.1 is not a multiple)
  for (std::size_t i = 0; i < r.samples.size(); ++i)
    EXPECT_EQ(r.samples[i].t, std::chrono::milliseconds(250 * i));
  EXPECT_EQ(r.samples[0].truth.x, 1.0) << "the t = 0 sample follows the actions at t = 0";
  EXPECT_EQ(r.samples[0].refusal, "link_lost") << "nothing heard yet at t = 0";
  EXPECT_EQ(r.samples[4].control_mode, "can");
  EXPECT_EQ(r.samples[4].motion_mode, "ackermann");
  EXPECT_EQ(r.samples[4].refusal, "none") << "idle: nothing requested";
}

TEST(ScenarioRun, TheCommanderDrivesAndGoingQuietTimesOut) {
  const RunOutcome r =
      run("cmd 0.5 0 0\n"
          "wait 2\n"
          "expect moving\n"
          "expect truth.vx > 0.45\n"
          "expect odom.x > 0.3\n"
          "cmd none\n"
          "wait 1\n"
          "expect refusal cmd_timeout\n"
          "expect still\n");
  EXPECT_EQ(r.result.expectations, 5u);
  EXPECT_TRUE(r.result.passed()) << ::testing::PrintToString(r.failures);
}

TEST(ScenarioRun, TheCmdTimeoutParameterIsTheDriverOne) {
  ScenarioOptions o;
  ASSERT_TRUE(apply_scenario_param(o.driver, "cmd_vel_timeout=3").ok());
  const RunOutcome r =
      run("cmd 0.5 0 0\nwait 2\ncmd none\nwait 1\nexpect refusal none\nexpect moving\n", o);
  EXPECT_TRUE(r.result.passed()) << ::testing::PrintToString(r.failures);
}

TEST(ScenarioRun, AFailedCheckNamesItsLineWhatWasExpectedAndWhatCameAndTheRunGoesOn) {
  ScenarioOptions o;
  o.every = 500ms;
  const RunOutcome r =
      run("wait 1\n"
          "expect refusal estop\n"
          "expect truth.x > 1\n"
          "expect moving\n"
          "expect fault emergency_stop\n"
          "expect control_mode can\n"
          "wait 1\n",
          o);
  EXPECT_EQ(r.result.expectations, 5u);
  EXPECT_EQ(r.result.failures, 4u);
  ASSERT_EQ(r.failures.size(), 4u);
  EXPECT_EQ(r.failures[0], "line 2: expected refusal estop, got none (t=1.000 s)");
  EXPECT_EQ(r.failures[1], "line 3: expected truth.x > 1, got 0.000000 (t=1.000 s)");
  EXPECT_EQ(r.failures[2],
            "line 4: expected moving (truth.speed > 0.001), got truth.speed 0.000000 (t=1.000 s)");
  EXPECT_EQ(r.failures[3], "line 5: expected fault emergency_stop, got faults [] (t=1.000 s)");
  EXPECT_EQ(r.samples.size(), 5u) << "the run went on to the end";
}

TEST(ScenarioRun, RequestsAndChassisTextAreNotes) {
  const RunOutcome r =
      run("wait 0.5\n"
          "estop on\n"
          "wait 0.2\n"
          "resume\n"
          "status\n"
          "wait 0.2\n"
          "expect refusal estop\n");
  EXPECT_TRUE(r.result.passed()) << ::testing::PrintToString(r.failures);
  ASSERT_EQ(r.notes.size(), 2u);
  EXPECT_EQ(r.notes[0].rfind("line 5: control can", 0), 0u) << r.notes[0];
  EXPECT_EQ(r.notes[1].rfind("line 4: resume failed: ", 0), 0u) << r.notes[1];
  EXPECT_TRUE(contains(r.notes[1], "emergency_stop")) << r.notes[1];
}

TEST(ScenarioRun, TheSameScriptGivesTheSameBytes) {
  const std::string text =
      "cmd 0.8 0 0.4\nwait 1.5\ncmd 0 0.5 0\nwait 2\nestop on\nwait 0.5\nestop off\n"
      "cmd 0 0 0\nwait 0.3\nmode spin\ncmd 0 0 0.6\nwait 2\n";
  const Scenario s = parse_ok(text);
  ScenarioOptions o;
  o.every = 1ms;
  std::ostringstream out1, out2, err1, err2;
  ASSERT_TRUE(run_scenario(s, o, out1, err1).ok());
  ASSERT_TRUE(run_scenario(s, o, out2, err2).ok());
  EXPECT_EQ(test::lines_of(out1.str()).size(), 6301u);
  EXPECT_EQ(out1.str(), out2.str());
  EXPECT_EQ(err1.str(), err2.str());
}

// The driver's events ride on the next sample as "events":[{...}] after its other fields; a sample
// with none since the one before has no such field; an event after the last sample comes on a
// line of its own, {"t":...,"events":[...]}.
TEST(ScenarioRun, SamplesCarryTheDriverEventsSinceTheSampleBefore) {
  const Scenario s = parse_ok("wait 2\nestop on\nwait 0.1\n");
  ScenarioOptions o;
  o.every = 500ms;
  std::ostringstream out, err;
  ASSERT_TRUE(run_scenario(s, o, out, err).ok());
  const auto lines = test::lines_of(out.str());
  ASSERT_EQ(lines.size(), 6u) << out.str();  // t = 0, 0.5, ... 2.0, then the e-stop's events
  EXPECT_TRUE(contains(lines[0], "\"identification\":\"none\",\"events\":[{\"seq\":1,\"t\":0.000,"))
      << lines[0];
  EXPECT_EQ(lines[0].substr(lines[0].size() - 3), "}]}");
  EXPECT_FALSE(contains(lines[4], "\"events\"")) << lines[4];  // nothing new by t = 2
  EXPECT_EQ(lines[5].rfind("{\"t\":2.100,\"events\":[{\"seq\":", 0), 0u) << lines[5];
  EXPECT_TRUE(contains(lines[5], "emergency")) << lines[5];
}

// ---- the sub-command ----------------------------------------------------------------------------

test::CliOutcome cli(const cli::Args& args, const std::string& input = "") {
  return test::run_cli(cli::run_scenario, args, input);
}

TEST(CliScenario, RunsAScriptFromStandardInput) {
  // (the driver identifies the chassis first: --protocol auto, the default, about 3.6 s)
  const std::string script = "cmd 0.5 0 0\nwait 5\nexpect moving\n";
  const test::CliOutcome r = cli({"--every", "0.5"}, script);
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto lines = test::lines_of(r.out);
  ASSERT_EQ(lines.size(), 11u);
  EXPECT_EQ(lines[0].rfind("{\"t\":0.000,\"truth\":{", 0), 0u) << lines[0];
  EXPECT_EQ(lines[10].rfind("{\"t\":5.000,", 0), 0u) << lines[10];
  EXPECT_EQ(cli({"-", "--every", "0.5"}, script).out, r.out);
}

TEST(CliScenario, AFailedCheckIsExitStatusOne) {
  const test::CliOutcome r = cli({}, "wait 0.2\nexpect moving\nwait 0.1\n");
  EXPECT_EQ(r.rc, 1);
  EXPECT_TRUE(contains(r.err, "ranger_can scenario: line 2: expected moving")) << r.err;
  EXPECT_TRUE(contains(r.err, "ranger_can scenario: 1 of 1 expectation(s) failed")) << r.err;
  EXPECT_EQ(test::lines_of(r.out).size(), 4u);
}

TEST(CliScenario, ABadScriptRunsNothingAndIsExitStatusTwo) {
  const test::CliOutcome r = cli({}, "cmd 0.5 0 0\nwait 1\nwait -1\ncmd 1 nan 0\n");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.out, "") << "nothing ran";
  EXPECT_EQ(r.err,
            "ranger_can scenario: line 3: wait SEC: '-1' is negative\n"
            "ranger_can scenario: line 4: cmd VY: 'nan' is not a finite number\n");
}

TEST(CliScenario, BadOptionsAreUsageErrors) {
  struct Case {
    cli::Args args;
    std::string mentions;
  };
  const Case cases[] = {
      {{"--chassis-variant", "agx_v9"}, "'agx_v9' is not one of manual"},
      {{"--every", "0"}, "--every"},
      {{"--every", "0.0005"}, "whole number of milliseconds"},
      {{"--every", "-1"}, "negative"},
      {{"--param", "steer_first_threshold=9"}, "steer_first_threshold"},
      {{"--param", "nosuch=1"}, "unknown parameter 'nosuch'"},
      {{"--param", "cmd_timeout"}, "expected NAME=VALUE"},
      {{"a.scn", "b.scn"}, "b.scn"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.mentions);
    const test::CliOutcome r = cli(c.args, "wait 1\n");
    EXPECT_EQ(r.rc, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(contains(r.err, c.mentions)) << r.err;
  }
}

TEST(CliScenario, UnreadableOrEmptyInputIsExitStatusOne) {
  test::CliOutcome r = cli({"/nonexistent/script.scn"});
  EXPECT_EQ(r.rc, 1);
  EXPECT_TRUE(contains(r.err, "cannot open '/nonexistent/script.scn'")) << r.err;
  r = cli({"/"});
  EXPECT_EQ(r.rc, 1);
  EXPECT_TRUE(contains(r.err, "is a directory")) << r.err;
  r = cli({}, "# nothing to do\n");
  EXPECT_EQ(r.rc, 1);
  EXPECT_EQ(r.err, "ranger_can scenario: the script has no actions\n");
  EXPECT_EQ(r.out, "");
}

TEST(CliScenario, ParamsReachTheDriver) {
  // auto_reclaim_after_remote: the driver takes CAN mode back after the remote hands back.
  const std::string script =
      "cmd 0.5 0 0\nwait 1\nremote on\nwait 0.5\nremote off\nwait 2\n"
      "expect control_mode standby\n";
  EXPECT_EQ(cli({}, script).rc, 0);
  const test::CliOutcome r = cli({"--param", "auto_reclaim_after_remote=true"}, script);
  EXPECT_EQ(r.rc, 1);
  EXPECT_TRUE(contains(r.err, "line 7: expected control_mode standby, got can")) << r.err;
}

TEST(CliScenario, TheHelpDocumentsTheLanguage) {
  const test::CliOutcome r = cli({"--help"});
  EXPECT_EQ(r.rc, 0);
  for (const char* word : {"cmd VX VY WZ", "cmd none", "resume", "mode auto|ackermann",
                           "clear-errors CODE", "wait SEC", "expect refusal NAME", "estop on|off",
                           "remote on|can|off|lost", "expect FIELD OP NUMBER", "--every SEC",
                           "--chassis-variant VARIANT", "--param NAME=VALUE", "Exit status"}) {
    EXPECT_TRUE(contains(r.out, word)) << word;
  }
}

}  // namespace
}  // namespace ranger::sim

namespace ranger::sim {
namespace {

// --remote boots the chassis under its remote control: the identification (protocol auto) learns
// the wheels' reading from the remote's driving and waits for CAN command mode, saying so; the
// identification's phase is a check of its own.
TEST(ScenarioRun, TheChassisBootsUnderItsRemoteAndIdentificationIsChecked) {
  ScenarioOptions o;
  o.driver.protocol = ProtocolChoice::kAuto;
  o.chassis.boot_in_remote_mode = true;
  const RunOutcome r =
      run("expect identification listening\n"
          "remote sticks 0.2 -0.3\n"
          "wait 3\n"
          "expect control_mode remote\n"
          "expect identification awaiting_control\n"
          "expect odom.wz > 0.1\n"
          "remote sticks 0 0\n"
          "remote can\n"
          "wait 1\n"
          "expect identification awaiting_control\n"
          "expect refusal rearm_required\n"
          "resume\n"
          "wait 3\n"
          "expect identification decided\n",
          o);
  EXPECT_TRUE(r.result.passed()) << ::testing::PrintToString(r.failures);
  EXPECT_EQ(r.result.expectations, 7u);
  EXPECT_EQ(r.samples.front().identification, "listening");
  ScenarioOptions fixed;
  fixed.driver.protocol = ProtocolChoice::kForced;
  EXPECT_EQ(run("wait 0.1\n", fixed).samples.back().identification, "none");
  EXPECT_TRUE(contains(parse_error("expect identification maybe\n"), "decided"));
}

}  // namespace
}  // namespace ranger::sim
