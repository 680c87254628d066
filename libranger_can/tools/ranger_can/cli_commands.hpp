// The sub-commands of the `ranger_can` tool. Each lives in its own cmd_<name>.cpp and takes its
// arguments (after the sub-command name) and the streams to use, so tests drive them in-process.
// Exit codes: 0 success, 1 runtime failure (e.g. bus error), 2 usage error.
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

int run_decode(const Args& args, Io io);   // decode candump logs (text or --json)
int run_odom(const Args& args, Io io);     // replay a candump log through the odometry
int run_sim(const Args& args, Io io);      // run the virtual chassis on an interface
int run_monitor(const Args& args, Io io);  // live terminal view of a chassis
int run_send(const Args& args, Io io);     // one-shot commands: mode, clear-errors, ultrasonic...

}  // namespace ranger::cli
