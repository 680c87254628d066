// What a Python program (and the ROS 2 node) configures a driver with: the port and parameters by
// name, read through the library's one parameter table (ranger_can/frontend/node_parameters.hpp:
// the ROS 1 node's rows, ranges, defaults and messages). Nothing here checks a value: a
// ParameterSource over the values Python gives, and ranger::load_parameters.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "ranger_can/control/parameters.hpp"
#include "ranger_can/frontend/node_parameters.hpp"
#include "ranger_can/result.hpp"

namespace ranger::python {

// What the Python Driver (and the ROS 2 node) runs with.
struct Setup {
  NodeParameters node;       // every row of the table, checked (port_name, driver, sim, ...)
  bool record_sent = false;  // queue every motion frame sent (cmd_vel_out)
};

// Checks every value (`port` is port_name unless the values give port_name) and builds the setup;
// unknown names and every bad value are reported at once, one line each, naming the parameter
// (after `display_prefix`), the value and the valid range: the library's messages.
Result<Setup> make_setup(const std::string& port, std::map<std::string, ParameterValue> values,
                         const std::string& display_prefix = "");

// A value for the row `name` checked against it (the ROS 2 node's run-time parameter changes); the
// error names the parameter, the value and the valid range.
Result<ParameterValue> check_value(const std::string& name, const ParameterValue& value);

// The Python spelling of a row's type: bool, int, double (also seconds), string (also a choice),
// double_list, string_list.
std::string python_type(ParameterType type);

}  // namespace ranger::python
