// The sub-commands of the `ranger_can` tool. Each lives in its own cmd_<name>.cpp, declares its
// arguments in a CommandSpec (cli_options.hpp: the one option table, parser and help generator),
// and takes its arguments (after the sub-command name) and the streams to use, so tests drive it
// in-process.
// Exit codes: 0 success (the input held what the command needs), 1 runtime failure (bus error,
// unreadable input, input without what the command needs), 2 usage error.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace ranger::cli {

struct Io {
  std::istream& in;
  std::ostream& out;
  std::ostream& err;
};
using Args = std::vector<std::string>;

struct CommandSpec;

int run_decode(const Args& args, Io io);      // decode candump logs (text or --json)
int run_odom(const Args& args, Io io);        // replay a candump log through the odometry
int run_sim(const Args& args, Io io);         // run the virtual chassis on an interface
int run_monitor(const Args& args, Io io);     // live terminal view of a chassis
int run_send(const Args& args, Io io);        // one-shot commands: mode, control, motion...
int run_scenario(const Args& args, Io io);    // a script: driver + virtual chassis, simulated time
int run_identify(const Args& args, Io io);    // identify the protocol settings of a chassis
int run_commission(const Args& args, Io io);  // guided first start on blocks: decide every setting

// The option tables, for the top-level help and the tests.
const CommandSpec& decode_command();
const CommandSpec& odom_command();
const CommandSpec& sim_command();
const CommandSpec& monitor_command();
const CommandSpec& send_command();
const CommandSpec& scenario_command();
const CommandSpec& identify_command();
const CommandSpec& commission_command();

// Every sub-command, in the order `ranger_can --help` lists them.
const std::vector<const CommandSpec*>& all_commands();

// The tool's version (the CMake project version of libranger_can).
const char* version();

// `ranger_can ARGS...` (ARGS without the program name): the top level (--help, --version,
// `help COMMAND`) and the dispatch to a sub-command.
int run_main(const Args& args, Io io);

}  // namespace ranger::cli
