// The driver's parameters as one table: name, type, unit, valid range, default and one line of
// meaning for every scalar setting of DriverConfig that a user may change. The ROS node's
// parameter parsing (ranger_base/src/parameters.cpp), `ranger_can scenario --param`, the
// scenario language and the parameter tables of ranger_base/README.md all read it (the README's
// rows are checked against markdown_row() by test_parameters.cpp), so a bound or a default is
// written once.
//
// Names are the ROS node's (ros_controllers' where they have one, e.g. cmd_vel_timeout); the
// default is the library's own (DriverConfig{}), read through the row's accessor.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

enum class ParameterType {
  kBool,     // true | false
  kInteger,  // a whole number in the range
  kNumber,   // a finite number in the range
  kSeconds,  // a duration, given in seconds
};
inline constexpr auto kParameterTypeNames = text::enum_names<ParameterType>({
    {ParameterType::kBool, "bool"},
    {ParameterType::kInteger, "int"},
    {ParameterType::kNumber, "double"},
    {ParameterType::kSeconds, "seconds"},
});
inline std::string_view to_string(ParameterType t) {
  return kParameterTypeNames.name(t);
}

struct ParameterRange {
  double lo = 0.0;
  double hi = 0.0;
  bool lo_open = false;
  bool hi_open = false;
  bool contains(double v) const;
};

struct DriverParameter {
  std::string_view name;  // "steer_first_threshold", "mode_selection/min_dwell"
  ParameterType type;
  std::string_view unit;  // "rad", "s", "m/s", "%", "" (bool, counts)
  ParameterRange range;   // bool: [0, 1]
  std::string_view meaning;
  double (*get)(const DriverConfig&);
  void (*set)(DriverConfig&, double);
};

// Every row, in the README's order.
const std::vector<DriverParameter>& driver_parameters();
const DriverParameter* find_driver_parameter(std::string_view name);
std::vector<std::string> driver_parameter_names();

// The library's default (DriverConfig{}).
double default_value(const DriverParameter& p);
// "[0, 1.5708] rad", "(0, 10] m/s", "[1, 100]", "bool": the valid values as messages show them.
std::string valid_text(const DriverParameter& p);
// A value as the README shows it: "true", "0.5", "0.174533 (10°)".
std::string value_text(const DriverParameter& p, double value);
// Whether `value` is valid (finite, in range, whole for kInteger, 0 or 1 for kBool).
Status check_value(const DriverParameter& p, double value);
// Parses `text` ("true", "0.5", "3") as the row's type, checks it and sets it in `config`. The
// error names the parameter, the value and the valid range.
Status set_driver_parameter(DriverConfig& config, std::string_view name, std::string_view text);
// "| `name` | default | valid | meaning |" — the row of ranger_base/README.md.
std::string markdown_row(const DriverParameter& p);

}  // namespace ranger
