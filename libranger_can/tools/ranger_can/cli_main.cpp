// The top level of `ranger_can`: the list of sub-commands, --help, --version, dispatch.
#include <algorithm>
#include <exception>
#include <ostream>
#include <string>

#include "cli_commands.hpp"
#include "cli_options.hpp"

#ifndef RANGER_CAN_VERSION
#define RANGER_CAN_VERSION "unknown"
#endif

namespace ranger::cli {

const std::vector<const CommandSpec*>& all_commands() {
  static const std::vector<const CommandSpec*> commands = {
      &decode_command(), &odom_command(),     &sim_command(),      &monitor_command(),
      &send_command(),   &scenario_command(), &identify_command(), &commission_command(),
  };
  return commands;
}

const char* version() {
  return RANGER_CAN_VERSION;
}

namespace {

void usage(std::ostream& os) {
  os << "usage: ranger_can COMMAND [ARGS...]\n"
        "       ranger_can --version\n"
        "\n"
        "The command-line companion of libranger_can: candump logs in and out, a virtual RANGER\n"
        "chassis, a live view and one-shot commands for a real one.\n"
        "\ncommands:\n";
  std::size_t width = 0;
  for (const auto* c : all_commands())
    width = std::max(width, c->name.size());
  for (const auto* c : all_commands())
    os << "  " << c->name << std::string(width + 2 - c->name.size(), ' ') << c->summary << "\n";
  os << "\n'ranger_can COMMAND --help' (or 'ranger_can help COMMAND') describes a command.\n"
        "Exit status: 0 success, 1 failure (the reason is on stderr), 2 usage error.\n";
}

const CommandSpec* find_command(const std::string& name) {
  for (const auto* c : all_commands())
    if (c->name == name) return c;
  return nullptr;
}

int unknown_command(const std::string& name, Io io) {
  io.err << "ranger_can: unknown command '" << name << "'\n\n";
  usage(io.err);
  return 2;
}

}  // namespace

int run_main(const Args& args, Io io) {
  if (args.empty()) {
    usage(io.err);
    return 2;
  }
  const std::string& name = args[0];
  if (name == "-h" || name == "--help") {
    usage(io.out);
    return 0;
  }
  if (name == "--version") {
    io.out << "ranger_can " << version() << "\n";
    return 0;
  }
  if (name == "help") {
    if (args.size() == 1) {
      usage(io.out);
      return 0;
    }
    const CommandSpec* c = find_command(args[1]);
    if (c == nullptr) return unknown_command(args[1], io);
    io.out << help_text(*c);
    return 0;
  }
  const CommandSpec* c = find_command(name);
  if (c == nullptr) return unknown_command(name, io);
  try {
    return run_command(*c, Args(args.begin() + 1, args.end()), io);
  } catch (const std::exception& e) {  // last line of defence: never die with a trace
    io.err << "ranger_can " << name << ": internal error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace ranger::cli
