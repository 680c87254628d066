// The control language of `ranger_can sim`: one command per line (stdin or a FIFO) that injects
// a fault or changes the virtual chassis's world. Kept apart from the sub-command so that tests
// drive it against a VirtualChassis directly.
#pragma once

#include <string>
#include <string_view>

#include "ranger_can/result.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"

namespace ranger::cli {

// The help text listing every command (also part of `ranger_can sim --help`).
extern const char* const kSimControlHelp;

// Looks up a 0x211 error bit by index ("9") or name ("host_communication_lost"); the error says
// which names exist.
Result<int> parse_error_bit(const std::string& text);

// Applies one command line to `chassis`. Returns what to print (may be empty), or an error naming
// the problem (unknown command, bad argument). Blank lines and '#' comments do nothing.
// "quit", "help" and "wait" are handled by the caller (they concern the session, not the chassis).
Result<std::string> apply_sim_command(std::string_view line, sim::VirtualChassis& chassis);

// A one-paragraph description of the chassis's state (the `status` command).
std::string describe_chassis(const sim::ChassisSnapshot& s);

}  // namespace ranger::cli
