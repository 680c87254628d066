// ranger_can: command-line companion of libranger_can, in the spirit of can-utils (small
// sub-commands, candump logs as the common format). Everything but this entry point lives in
// the ranger_can_cli library (cli_main.cpp), where the tests run it with string streams.
#include <iostream>

#include "cli_commands.hpp"

int main(int argc, char** argv) {
  const ranger::cli::Args args(argv + 1, argv + argc);
  return ranger::cli::run_main(args, ranger::cli::Io{std::cin, std::cout, std::cerr});
}
