// Placeholder until the sub-command is implemented.
#include <ostream>

#include "cli_commands.hpp"

namespace ranger::cli {

int run_odom(const Args&, Io io) {
  io.err << "ranger_can odom: not implemented yet\n";
  return 2;
}

}  // namespace ranger::cli
