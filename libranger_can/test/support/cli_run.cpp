#include "support/cli_run.hpp"

#include <sstream>

namespace ranger::test {

CliOutcome run_cli(CliCommand command, const cli::Args& args, const std::string& input) {
  std::istringstream in(input);
  std::ostringstream out, err;
  const int rc = command(args, cli::Io{in, out, err});
  return {rc, out.str(), err.str()};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    lines.push_back(l);
  return lines;
}

}  // namespace ranger::test
