// What a Python program (and the ROS 2 node) configures a driver with: the port and parameters by
// name, the ROS 1 node's names and ranges. The driver's scalar settings are the library's
// parameter table (ranger_can/control/parameters.hpp) as it is; the rows the ROS 1 node reads
// beside it (model, protocol, geometry, limits, per-axis limits, odometry source, the virtual
// chassis) are listed here until the library's one parameter table covers them (issue 27,
// point 3): then this file becomes a call into it.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

namespace ranger::python {

// A parameter's value as Python gives it.
using Value = std::variant<bool, std::int64_t, double, std::string, std::vector<double>,
                           std::vector<std::string>>;

// One row: what a front end declares (ROS 2 descriptors) and documents.
struct ParameterRow {
  std::string name;
  std::string type;  // "bool", "int", "double", "string", "string_list"
  std::string unit;  // "s", "m/s", "" ...
  double lo = 0.0, hi = 0.0;
  bool lo_open = false, hi_open = false;
  bool has_range = false;            // numbers: lo/hi hold
  std::string default_text;          // as the README shows it ("" for the model's own)
  std::vector<std::string> choices;  // string rows with a closed set of values
  std::string meaning;
  std::string group;  // "driver", "vehicle", "protocol", "limits", "odometry", "sim"
};

// Every row the driver reads, in the ROS 1 node's README order.
const std::vector<ParameterRow>& parameter_rows();

// What the Python Driver (and the ROS 2 node) runs with.
struct Setup {
  std::string port = "sim";
  DriverConfig driver;
  sim::SimSourceOptions sim;
  std::string model = "ranger";
  std::string model_display_name = "RANGER";
  std::string protocol = "auto";
  // Where the protocol settings come from, as the ROS 1 node says it ("auto: identified from the
  // chassis, model ranger", "forced: protocol agx_v2, model ranger").
  std::string protocol_source;
  bool record_sent = false;  // queue every motion frame sent (cmd_vel_out)
};

// Checks every value and builds the setup; unknown names and every bad value are reported at
// once, one line each, naming the parameter, the value and the valid range (the ROS 1 node's
// messages, with `display_prefix` before each name).
Result<Setup> make_setup(const std::string& port, const std::map<std::string, Value>& values,
                         const std::string& display_prefix = "");

}  // namespace ranger::python
