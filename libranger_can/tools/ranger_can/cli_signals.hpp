// SIGINT/SIGTERM as a flag the long-running sub-commands (sim, monitor) poll, so they leave
// through their normal path (stop the chassis thread, flush files, restore the terminal).
// Several instances may live at once (tests run sub-commands on threads of one process): the
// handlers are installed by the first and restored by the last.
#pragma once

namespace ranger::cli {

class StopSignals {
 public:
  StopSignals();   // installs the handlers (first instance) - a fresh flag
  ~StopSignals();  // restores the previous handlers (last instance)
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // True once SIGINT or SIGTERM arrived while handlers were installed.
  static bool requested();
  // The signal number that arrived (0 if none).
  static int signal_number();
};

}  // namespace ranger::cli
