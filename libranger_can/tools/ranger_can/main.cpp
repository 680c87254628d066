// ranger_can: command-line companion of libranger_can, in the spirit of can-utils (small
// sub-commands, candump logs as the common format).
#include <cstring>
#include <iostream>
#include <string>

#include "cli_commands.hpp"

namespace {

struct SubCommand {
  const char* name;
  int (*run)(const ranger::cli::Args&, ranger::cli::Io);
  const char* summary;
};

constexpr SubCommand kCommands[] = {
    {"decode", ranger::cli::run_decode, "decode a candump log (file or stdin), text or --json"},
    {"odom", ranger::cli::run_odom, "replay a candump log through the odometry, print poses"},
    {"sim", ranger::cli::run_sim, "run the virtual RANGER chassis on a CAN interface"},
    {"monitor", ranger::cli::run_monitor, "live view of a chassis on a CAN interface"},
    {"send", ranger::cli::run_send, "send one command: mode, control, clear-errors, ultrasonic"},
};

void usage(std::ostream& os) {
  os << "usage: ranger_can <command> [options]\n\ncommands:\n";
  for (const auto& c : kCommands)
    os << "  " << c.name << std::string(10 - std::strlen(c.name), ' ') << c.summary << "\n";
  os << "\n'ranger_can <command> --help' describes a command.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "-h" || name == "--help" || name == "help") {
    usage(std::cout);
    return 0;
  }
  for (const auto& c : kCommands) {
    if (name == c.name) {
      ranger::cli::Args args(argv + 2, argv + argc);
      ranger::cli::Io io{std::cin, std::cout, std::cerr};
      try {
        return c.run(args, io);
      } catch (const std::exception& e) {  // last line of defence: never die with a trace
        std::cerr << "ranger_can " << name << ": internal error: " << e.what() << "\n";
        return 1;
      }
    }
  }
  std::cerr << "ranger_can: unknown command '" << name << "'\n\n";
  usage(std::cerr);
  return 2;
}
