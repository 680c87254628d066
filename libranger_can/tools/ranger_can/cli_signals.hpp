// SIGINT/SIGTERM as a flag the long-running sub-commands (sim, monitor) poll, so they leave
// through their normal path (stop the chassis thread, flush files, restore the terminal).
#pragma once

#include <csignal>

namespace ranger::cli {

class StopSignals {
 public:
  StopSignals();   // installs the handlers
  ~StopSignals();  // restores the previous ones
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // True once SIGINT or SIGTERM arrived since construction.
  static bool requested();
  // The signal number that arrived (0 if none).
  static int signal_number();

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

}  // namespace ranger::cli
