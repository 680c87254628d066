// Parameters as one row type: name, type, unit, valid range (or values), default and one line of
// meaning. Here: the row type, how a value a front end hands over is checked against a row (the
// problem named with the row's range or values), and the driver's own rows — every scalar setting
// of DriverConfig that a user may change, with accessors into it. frontend/node_parameters.hpp
// adds the rows of a node (frames, publish rates, covariances, ultrasonic, the virtual chassis,
// protocol, model, commissioning) to one table: the ROS 1 node reads it in a loop, the ROS 2 node
// declares its parameters from it, and ranger_base/README.md's parameter rows are markdown_row()
// of its rows, character for character (test_parameters.cpp). `ranger_can scenario --param` and
// the scenario language take the driver's rows by the same names.
//
// Names are the ROS node's (ros_controllers' where they have one, e.g. cmd_vel_timeout); a driver
// row's default is the library's own (DriverConfig{}), read through its accessor.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

enum class ParameterType {
  kBool,        // true | false
  kInteger,     // a whole number in the range
  kNumber,      // a finite number in the range (an integer is a number)
  kSeconds,     // a duration, given in seconds
  kText,        // a string; one of `choices` when the row lists them
  kChoice,      // one of `choices`; a number or a bool is taken as its text (`tx_dlc: 8`)
  kNumberList,  // `size` numbers, each in the range
  kTextList,    // strings
};
inline constexpr auto kParameterTypeNames = text::enum_names<ParameterType>({
    {ParameterType::kBool, "bool"},
    {ParameterType::kInteger, "int"},
    {ParameterType::kNumber, "double"},
    {ParameterType::kSeconds, "seconds"},
    {ParameterType::kText, "string"},
    {ParameterType::kChoice, "choice"},
    {ParameterType::kNumberList, "double[]"},
    {ParameterType::kTextList, "string[]"},
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

// A value as a front end hands it over (a YAML scalar or list; the ROS parameter server's types).
struct ParameterValue {
  enum class Kind { kBool, kInteger, kNumber, kText, kList, kDictionary, kOther };
  Kind kind = Kind::kOther;
  bool boolean = false;
  std::int64_t integer = 0;
  double number = 0.0;
  std::string text;
  std::vector<ParameterValue> items;  // kList

  ParameterValue() = default;
  ParameterValue(bool v) : kind(Kind::kBool), boolean(v) {}
  ParameterValue(int v) : kind(Kind::kInteger), integer(v) {}
  ParameterValue(long v) : kind(Kind::kInteger), integer(v) {}
  ParameterValue(long long v) : kind(Kind::kInteger), integer(v) {}
  ParameterValue(double v) : kind(Kind::kNumber), number(v) {}
  ParameterValue(const char* v) : kind(Kind::kText), text(v) {}
  ParameterValue(std::string v) : kind(Kind::kText), text(std::move(v)) {}
  ParameterValue(std::vector<ParameterValue> v) : kind(Kind::kList), items(std::move(v)) {}
  static ParameterValue dictionary();

  // An integer or a number as a double; nullopt for anything else.
  std::optional<double> as_number() const;
};
// How messages show a value: "\"fast\"", "true", "5", "0.5", "a list of 5", "a dictionary".
std::string shown(const ParameterValue& v);

struct Parameter {
  std::string name;  // "steer_first_threshold", "mode_selection/min_dwell", "linear/x/max_velocity"
  ParameterType type = ParameterType::kNumber;
  std::string unit;      // "rad", "s", "m/s", "%", "" (bool, counts, text)
  ParameterRange range;  // numbers (each element of a kNumberList); bool: [0, 1]
  std::string meaning;
  ParameterValue default_value;      // what applies when the parameter is not set
  std::vector<std::string> choices;  // kChoice, and kText when it is one of a set of words
  std::size_t size = 0;              // kNumberList: how many numbers
  // The README's default and valid columns when they are not the value, the range or the
  // choices themselves ("the model's (RANGER 0.89)", "tf2 frame id").
  std::string default_note;
  std::string valid_note;
  // A driver setting: where its value lives in DriverConfig (nullptr for a node's own rows).
  double (*get)(const DriverConfig&) = nullptr;
  void (*set)(DriverConfig&, double) = nullptr;
};
using DriverParameter = Parameter;  // a row of driver_parameters()

// The driver's rows, in the README's order.
const std::vector<Parameter>& driver_parameters();
const Parameter* find_driver_parameter(std::string_view name);
std::vector<std::string> driver_parameter_names();

// A driver row's default: the library's own (DriverConfig{}).
double default_value(const Parameter& p);
// The valid values as messages show them: "[0, 1.5708] rad", "(0, 10] m/s", "[1, 100]", "bool",
// "wheels, motion", "text", "6 values in [0, inf)"; the row's valid_note when it has one.
std::string valid_text(const Parameter& p);
// A number of the row as the README shows it: "true", "0.5", "0.174533 (10°)".
std::string value_text(const Parameter& p, double value);
// Whether `value` is valid for a numeric row (finite, in range, whole for kInteger, 0 or 1 for
// kBool).
Status check_value(const Parameter& p, double value);
// `value` checked against the row: its type, range, choices and size. The result is the value in
// the row's type (an integer given for a number becomes a number; a kChoice's number or bool its
// text). The error's message is the problem as it follows the parameter's name in a report:
// "= -5 is out of range: valid (0, 50] Hz", "= \"fast\": expected a number in (0, 50] Hz".
Result<ParameterValue> check_parameter(const Parameter& p, const ParameterValue& value);
// Parses `text` ("true", "0.5", "3") as a driver row's type, checks it and sets it in `config`.
// The error names the parameter, the value and the valid range.
Status set_driver_parameter(DriverConfig& config, std::string_view name, std::string_view text);
// "| `name` | default | valid | meaning |": the row of ranger_base/README.md.
std::string markdown_row(const Parameter& p);

// Where a front end's parameter values come from: the ROS parameter server, a map in tests.
class ParameterSource {
 public:
  virtual ~ParameterSource() = default;
  // The value of `name` ('/'-separated, relative to the node's private namespace), or nullopt.
  virtual std::optional<ParameterValue> get(const std::string& name) const = 0;
  // How `name` is shown in messages (e.g. "/robot1/ranger_base_node/publish_rate").
  virtual std::string display_name(const std::string& name) const = 0;
  // Every name set (relative, '/'-separated).
  virtual std::vector<std::string> names() const = 0;
};

class MapParameterSource final : public ParameterSource {
 public:
  std::map<std::string, ParameterValue> values;
  std::optional<ParameterValue> get(const std::string& name) const override;
  std::string display_name(const std::string& name) const override { return "~" + name; }
  std::vector<std::string> names() const override;
};

}  // namespace ranger
