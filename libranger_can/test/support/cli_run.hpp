// Running a `ranger_can` sub-command in-process for the CLI tests: arguments and standard input
// in, exit status and both output streams out.
#pragma once

#include <string>
#include <vector>

#include "cli_commands.hpp"

namespace ranger::test {

struct CliOutcome {
  int rc = 0;  // exit status
  std::string out, err;
};

using CliCommand = int (*)(const cli::Args&, cli::Io);

CliOutcome run_cli(CliCommand command, const cli::Args& args, const std::string& input = "");

// `text` split at newlines (the last line's newline is optional).
std::vector<std::string> lines_of(const std::string& text);

}  // namespace ranger::test
