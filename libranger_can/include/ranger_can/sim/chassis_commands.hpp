// The chassis-side control language of the virtual chassis: one command per line that injects a
// fault or changes the chassis's world ("estop on", "remote lost", "battery 8", ...). One
// language for `ranger_can sim` (stdin or a FIFO), `ranger_can scenario` scripts and the ROS
// node's `sim/inject` topic. A line is parsed (and fully checked) first, then applied, so a
// script can be validated before anything runs.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/result.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"

namespace ranger::sim {

// The help text listing every command.
extern const char* const kChassisCommandHelp;
// The command words ("remote", "estop", ...), for messages that list what is valid.
const std::vector<std::string>& chassis_command_names();

// A checked command, ready to apply; returns what to print (may be empty). Blank lines and '#'
// comments parse to an action that does nothing.
using ChassisAction = std::function<std::string(VirtualChassis&)>;

// Parses one line. Errors name the problem (unknown command and the valid ones, bad argument).
// "quit", "help" and "wait" are not chassis commands: callers handle them first.
Result<ChassisAction> parse_chassis_command(std::string_view line);
// parse_chassis_command, then the action.
Result<std::string> apply_chassis_command(std::string_view line, VirtualChassis& chassis);

// Looks up a 0x211 error bit of `layout` by index ("9") or by its fault-table name
// ("host_communication_lost"); the error says which names the layout has.
Result<int> parse_error_bit(const std::string& text, ErrorWordLayout layout);
// parse_error_bit in the first layout that accepts `text` (a check before the layout is known).
Result<int> check_error_bit(const std::string& text);

// A one-paragraph description of the chassis's state (the `status` command); error names of
// `layout`.
std::string describe_chassis(const ChassisSnapshot& s, ErrorWordLayout layout);

}  // namespace ranger::sim
