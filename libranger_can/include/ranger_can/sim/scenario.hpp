// Scenarios: the driver runtime (ranger::Driver, the same controller and odometry the ROS node
// runs) and the virtual chassis (lock-step SimBusSource) on the in-process bus under a simulated
// clock, driven by a script — `ranger_can scenario FILE` and the scripts of tests/scenarios/.
//
// A script is parsed (and fully checked) first, then run; a bad line runs nothing. One action per
// line, '#' starts a comment, blank lines are ignored:
//   driver side   cmd VX VY WZ          from now on the commander publishes this REP-103 body
//                                       twist (m/s, m/s, rad/s) every 50 ms, the first at once
//                 cmd none              the commander stops publishing
//                 resume                Driver::resume() (the explicit re-arm)
//                 mode auto|ackermann|oblique|spin|side_slip    Driver::set_motion_mode()
//                 park on|off           Driver::set_park()
//                 clear-errors CODE     Driver::clear_errors(): 0x441 code, 0-16 or 0x00-0x10
//   chassis side  every command of sim::parse_chassis_command (remote, estop, error, clear,
//                 battery, silent, garbage, stuck, ultrasonic, pose, status): applied to the
//                 virtual chassis at once; what a command prints (status) is a note
//   time          wait SEC              advance simulated time by SEC (whole milliseconds)
//   checks        expect ...            see scenario_language_help()
// Actions take effect at the current simulated time; what they post to the driver's mailbox is
// handled at the next 1 ms step, so an `expect` about the driver's reaction follows a `wait`.
//
// Time: t = 0 when the chassis boots (in standby) and the driver first steps. Every 1 ms step
// advances a ManualClock, publishes the commander's twist if due, steps the chassis, then the
// driver. A sample (ScenarioSample, one JSON line) is taken at t = 0, every, 2*every, ... up to
// the end of the script, after every action scheduled at that time. Everything is deterministic:
// the same script and options give the same bytes.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <istream>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"

namespace ranger::sim {

// The script language for help texts: the actions, the chassis commands, the checks.
const std::string& scenario_language_help();

// Bounds that keep any script finite (validated before anything runs).
inline constexpr std::size_t kMaxScenarioLines = 100000;
inline constexpr std::size_t kMaxScenarioLineLength = 4096;
inline constexpr std::chrono::seconds kMaxScenarioDuration{3600};  // of simulated time
// `expect moving` / `expect still`: the fastest point of the chassis (the body centre or a wheel's
// contact point, ground truth) is faster / not faster than this.
inline constexpr double kStillSpeed = 0.001;  // m/s

// One `expect` line, checked against the sample at the time it is reached.
struct Expectation {
  enum class Kind {
    kEquals,   // a text field equals `text` (refusal, control_mode, motion_mode, drive_mode, ...)
    kCompare,  // a numeric field compared with `number` (value as printed)
    kMoving,   // truth.speed > kStillSpeed
    kStill,    // truth.speed <= kStillSpeed
    kFault,    // `text` is among the faults
    kNoFault,  // `text` is not among the faults
    kNoFaults  // the faults list is empty
  };
  enum class Op { kGreater, kLess, kGreaterEqual, kLessEqual, kEqual };
  Kind kind = Kind::kEquals;
  std::string field;  // "refusal", "truth.x", ...
  Op op = Op::kEqual;
  double number = 0.0;
  // The wanted value ("rearm_required", "null", "true"), the fault name, or (kCompare) the number
  // as written.
  std::string text;
};

// The comparison operators, as a script writes them.
inline constexpr auto kOpNames = text::enum_names<Expectation::Op>({
    {Expectation::Op::kGreater, ">"},
    {Expectation::Op::kLess, "<"},
    {Expectation::Op::kGreaterEqual, ">="},
    {Expectation::Op::kLessEqual, "<="},
    {Expectation::Op::kEqual, "=="},
});

// One script line, checked.
struct ScenarioAction {
  enum class Kind {
    kCommand,      // cmd VX VY WZ
    kCommandNone,  // cmd none
    kResume,
    kMode,         // mode auto|ackermann|oblique|spin
    kClearErrors,  // clear-errors CODE
    kPark,         // park on|off
    kDriveMode,    // drive_mode current|voltage
    kChassis,      // a sim::parse_chassis_command line
    kWait,
    kExpect,
  };
  Kind kind = Kind::kWait;
  std::size_t line = 0;                      // 1-based line number in the script
  std::string text;                          // the line without its comment, trimmed
  BodyTwist twist;                           // kCommand
  std::optional<protocol::MotionMode> mode;  // kMode (nullopt: auto)
  std::uint8_t code = 0;                     // kClearErrors; kDriveMode: the drive mode
  bool enable = false;                       // kPark
  ChassisAction chassis;                     // kChassis
  std::chrono::milliseconds wait{0};         // kWait
  Expectation expect;                        // kExpect
};

struct Scenario {
  std::vector<ScenarioAction> actions;
  std::chrono::milliseconds duration{0};  // the sum of the waits
  std::size_t expectations = 0;
};

// Seconds of simulated time as typed in a script or an option: finite, >= 0, at most
// kMaxScenarioDuration, a whole number of milliseconds (the simulation steps 1 ms).
Result<std::chrono::milliseconds> parse_milliseconds(std::string_view what,
                                                     const std::string& text);

// Parses one line (without its newline) numbered `line`. nullopt for a blank or comment line.
// Errors name the problem ("unknown action 'foo' (valid: ...)", "wait: '-1' is negative").
Result<std::optional<ScenarioAction>> parse_scenario_line(std::string_view text, std::size_t line);
// Parses a whole script. On failure the message lists every bad line ("line N: problem", one per
// line, the first 20 then a count); nothing of the script should run then.
Result<Scenario> parse_scenario(std::istream& in);
Result<Scenario> parse_scenario(std::string_view text);

// The driver settings a scenario may change (`--param NAME=VALUE`): every row of the parameter
// table (control/parameters.hpp), by the ROS node's name, e.g. steer_first_threshold (rad, 0
// disables), cmd_vel_timeout (s), auto_reclaim_after_remote (true|false).
const std::vector<std::string>& scenario_param_names();
// Applies "NAME=VALUE" to `config`; the error names the parameter and the problem.
Status apply_scenario_param(DriverConfig& config, std::string_view assignment);

struct ScenarioOptions {
  std::string variant = "manual";  // the chassis: bus spec "sim:VARIANT"
  std::chrono::milliseconds every{100};
  DriverConfig driver;  // the library's defaults = the ROS node's defaults
  // The chassis before the variant applies (its model and profile: chassis_for_model).
  VirtualChassisConfig chassis;
  // Where every frame of the run goes, both ways, as a candump -L log in simulated time
  // (bus_recording.hpp); nullptr: not recorded. Must outlive the run.
  std::ostream* candump = nullptr;
};
// Checks the options (variant known, every >= 1 ms, the driver config valid).
Status validate(const ScenarioOptions& options);

// What one output line holds.
struct ScenarioSample {
  std::chrono::milliseconds t{0};
  Pose2D truth;            // ground truth pose (the `pose` command moves it)
  BodyTwist truth_twist;   // body frame, REP-103
  double truth_speed = 0;  // fastest point of the chassis (body centre or a wheel), m/s
  Pose2D odom;             // the driver's odometry
  BodyTwist odom_twist;
  std::optional<std::string> control_mode;  // as the driver knows it; nullopt: never reported
  std::optional<std::string> motion_mode;
  std::string refusal;              // to_string(MotionRefusal)
  std::vector<std::string> faults;  // the controller's fault names
  bool rearm_required = false;
  std::vector<std::string> latched;  // the latched stop causes
  double steer_first_factor = 1.0;
  std::string identification = "none";  // its phase under protocol auto, else "none"
  // The drive mode the chassis reports (0x291 byte 2, the RANGER MINI 3.0's); nullopt where its
  // protocol has none (then not printed).
  std::optional<std::string> drive_mode;
};

// The sample as one JSON object (no newline), with fixed formatting: seconds with 3 decimals,
// every other number with 6 (a negative zero is printed as 0), so equal samples give equal bytes.
std::string to_json(const ScenarioSample& sample);
// A numeric field of the sample by name ("t", "truth.x", "odom.yaw", "steer_first_factor"), as
// to_json prints it (rounded to its decimals); nullopt for an unknown name.
std::optional<double> sample_number(const ScenarioSample& sample, std::string_view field);
// The names sample_number knows.
const std::vector<std::string>& sample_number_fields();

struct ScenarioResult {
  std::size_t expectations = 0;  // checked
  std::size_t failures = 0;      // of which failed
  bool passed() const { return failures == 0; }
};

// Receives what a run produces, in order.
struct ScenarioOutput {
  std::function<void(const ScenarioSample&)> sample;  // every `every`
  // A failed expectation: "line N: expected X, got Y (t=S s)".
  std::function<void(const std::string&)> failure;
  // Something worth knowing that is no failure: a chassis command's text (status), a driver
  // request that failed or was answered ("line N: resume failed: ... (t=S s)").
  std::function<void(const std::string&)> note;
  // Every event of the driver (control/driver_events.hpp), in order, as the step that made it ends.
  std::function<void(const DriverEvent&)> event;
};

class ScenarioRunner {
 public:
  // The options should pass validate(); a variant the simulator does not know is an error here.
  static Result<std::unique_ptr<ScenarioRunner>> create(const ScenarioOptions& options);
  ~ScenarioRunner();
  ScenarioRunner(const ScenarioRunner&) = delete;
  ScenarioRunner& operator=(const ScenarioRunner&) = delete;

  // Runs the whole script from the current time (a runner runs one script).
  ScenarioResult run(const Scenario& scenario, const ScenarioOutput& output);

  // The state now, and the simulated time (t = 0 at creation).
  ScenarioSample sample() const;
  std::chrono::milliseconds now() const;

 private:
  struct Impl;
  explicit ScenarioRunner(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Runs `scenario` with `options`: the JSON lines to `out`; failed expectations (the first 20, then
// a count) and notes to `err`, each line after `prefix`. An error only when the options are bad.
Result<ScenarioResult> run_scenario(const Scenario& scenario, const ScenarioOptions& options,
                                    std::ostream& out, std::ostream& err,
                                    std::string_view prefix = "");

}  // namespace ranger::sim
