// `ranger_can scenario [FILE]`: runs a script against the driver runtime and the virtual chassis
// in lock-step, in simulated time, and prints the state as JSON lines. Everything it does lives in
// libranger_can (sim/scenario.hpp): this file is only the command line around it.
#include <fstream>
#include <istream>
#include <memory>
#include <ostream>
#include <string>

#include "cli_commands.hpp"
#include "cli_input.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/sim/scenario.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/text.hpp"

namespace ranger::cli {

namespace {

constexpr const char* kName = "scenario";

Status check_every(const std::string& text) {
  auto ms = sim::parse_milliseconds("SEC", text);
  if (!ms) return ms.error();
  if (ms->count() < 1) return Error{Errc::kInvalidArgument, "must be at least 0.001 s"};
  return ok_status();
}

// "steer_first_threshold=RAD [0, 1.5708], ..., auto_reclaim_after_remote=true|false".
std::string param_help() {
  std::string out;
  for (const DriverParameter& p : driver_parameters()) {
    out += (out.empty() ? "" : ", ") + std::string(p.name) + "=";
    out += p.type == ParameterType::kBool ? std::string("true|false") : valid_text(p);
  }
  return out;
}

Status check_param(const std::string& text) {
  DriverConfig scratch;
  if (Status st = sim::apply_scenario_param(scratch, text); !st) return st;
  return scratch.validate();
}

int scenario_main(const ParsedArgs& args, Io io) {
  sim::ScenarioOptions options;
  options.every = *sim::parse_milliseconds("--every", args.get_or("--every", "0.1"));
  options.variant = args.get_or("--chassis-variant", options.variant);
  // --model, --protocol and --set: the driver's vehicle, and the chassis's before its variant.
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(scenario_command(), io, vehicle.error().message);
  if (vehicle->model) options.chassis = sim::chassis_for_model(*vehicle->model);
  options.chassis.profile = vehicle->profile;
  options.chassis.boot_in_remote_mode = args.has("--remote");
  apply_vehicle(*vehicle, options.driver);
  // auto (the default, as in the node): the driver identifies the chassis before it moves.
  if (protocol_is_auto(args)) options.driver.protocol = ProtocolChoice::kAuto;
  for (const std::string& p : args.all("--param")) {
    if (Status st = sim::apply_scenario_param(options.driver, p); !st) {
      return usage_error(scenario_command(), io, "--param: " + st.error().message);
    }
  }
  if (Status st = sim::validate(options); !st) {
    return usage_error(scenario_command(), io, st.error().message);
  }
  std::unique_ptr<std::ofstream> candump;  // --candump: every frame of the run
  if (const auto path = args.get("--candump")) {
    candump = std::make_unique<std::ofstream>(*path);
    if (!*candump) {
      io.err << "ranger_can " << kName << ": cannot write " << *path << "\n";
      return 1;
    }
    options.candump = candump.get();
  }
  return with_input(args.get("FILE"), kName, io, [&](std::istream& in) {
    auto script = sim::parse_scenario(in);
    if (!script) {
      // Every bad line, one per line; nothing has run.
      std::string::size_type start = 0;
      const std::string& message = script.error().message;
      while (start < message.size()) {
        auto end = message.find('\n', start);
        if (end == std::string::npos) end = message.size();
        io.err << "ranger_can " << kName << ": " << message.substr(start, end - start) << "\n";
        start = end + 1;
      }
      return 2;
    }
    if (script->actions.empty()) {
      io.err << "ranger_can " << kName << ": the script has no actions\n";
      return 1;
    }
    const std::string prefix = std::string("ranger_can ") + kName + ": ";
    auto result = sim::run_scenario(*script, options, io.out, io.err, prefix);
    if (!result) {
      io.err << prefix << result.error().message << "\n";
      return 1;
    }
    if (!result->passed()) {
      io.err << prefix << result->failures << " of " << result->expectations
             << " expectation(s) failed\n";
      return 1;
    }
    return 0;
  });
}

}  // namespace

const CommandSpec& scenario_command() {
  static const CommandSpec spec{
      kName,
      "run a script against the driver and the virtual chassis in simulated time (JSON lines)",
      "Runs the driver runtime (ranger::Driver with the library's defaults: the controller and\n"
      "odometry the ROS node runs with its default parameters) against the virtual chassis on the\n"
      "in-process bus, in lock-step under a simulated clock (1 ms steps: the chassis, then the\n"
      "driver), driven by a script: the commander's twists and requests, faults injected into\n"
      "the chassis, waits, and `expect` checks that make a script self-checking. The whole script\n"
      "is checked before anything runs. The chassis boots in standby at t = 0 (--remote: under "
      "its\n"
      "remote control).\n"
      "\n"
      "Prints one JSON object per line at t = 0, SEC, 2*SEC, ... (--every) until the script ends:\n"
      "  {\"t\":s,\"truth\":{\"x\",\"y\",\"yaw\",\"vx\",\"vy\",\"wz\",\"speed\"},\n"
      "   \"odom\":{\"x\",\"y\",\"yaw\",\"vx\",\"vy\",\"wz\"},\"control_mode\":\"can\",\n"
      "   \"motion_mode\":\"ackermann\",\"refusal\":\"none\",\"faults\":[...],\n"
      "   \"rearm_required\":false,\"latched\":[...],\"steer_first_factor\":1.0,\n"
      "   \"identification\":\"decided\"}\n"
      "truth: the chassis's ground truth (m, rad; velocities in the body frame, REP-103; speed:\n"
      "its fastest point, body centre or a wheel); odom: the driver's odometry; the modes as the\n"
      "driver knows them (null: never reported); refusal: why the requested motion is not driven\n"
      "(\"none\" while it is); identification: its phase under --protocol auto (\"none\" when the\n"
      "protocol is given). A sample also carries \"events\":[...] when the driver had any since\n"
      "the previous sample: each {\"seq\",\"t\",\"event\",\"severity\",\"text\",...} (the lines "
      "the\n"
      "ROS node logs; events after the last sample come on a line {\"t\":s,\"events\":[...]}).\n"
      "Numbers have fixed decimals (t 3, others 6): the same script gives the same bytes.",
      {optional_arg("FILE", "the script; standard input when absent or '-'", any_text())},
      {
          option("--every", "SEC",
                 "output period, seconds of simulated time, whole milliseconds (default 0.1)",
                 checked_by(check_every)),
          option("--chassis-variant", "VARIANT",
                 "the virtual chassis (bus spec sim:VARIANT), one of: " +
                     text::join(sim::variant_names(), ", ") +
                     " (default manual); it applies over --model, --protocol and --set, which "
                     "configure the driver and the chassis alike",
                 one_of(sim::variant_names())),
          flag("--remote",
               "the chassis boots under its remote control (remote mode from the first frame; "
               "`remote swd` and `remote sticks` drive it)"),
          model_option(),
          protocol_option(),
          set_option(),
          option("--candump", "FILE",
                 "write every frame of the run, both ways, to FILE as a candump -L log in "
                 "simulated time (seconds since t = 0; `ranger_can decode FILE` reads it)"),
          option("--param", "NAME=VALUE",
                 "a driver setting, by the ROS node's parameter name (ranger_base/README.md): " +
                     param_help(),
                 checked_by(check_param))
              .repeated(),
      },
      sim::scenario_language_help() +
          "\n"
          "An action's effect on the driver shows at the next 1 ms step: `expect` the driver's\n"
          "reaction after a `wait`. Requests (resume, clear-errors) report their outcome on\n"
          "stderr as 'line N: resume answered (t=S s)'; a failed check prints\n"
          "'line N: expected X, got Y (t=S s)' on stderr and the run goes on.\n"
          "\n"
          "Example (tests/scenarios/ has more):\n"
          "  cmd 0.5 0 0\n"
          "  wait 2\n"
          "  expect moving\n"
          "  estop on\n"
          "  wait 1\n"
          "  expect still\n"
          "  expect refusal estop\n"
          "\n"
          "Exit status: 0 the script ran and every check passed; 1 a check failed, the script has\n"
          "no actions, or FILE cannot be read; 2 a usage error or a bad script (every bad line is\n"
          "reported as 'line N: problem' and nothing runs).",
      scenario_main,
  };
  return spec;
}

int run_scenario(const Args& args, Io io) {
  return run_command(scenario_command(), args, io);
}

}  // namespace ranger::cli
