#include "options.hpp"

#include <utility>

#include "ranger_can/text.hpp"

namespace ranger::python {
namespace {

// The values a Python program gives, as the library reads parameters.
class DictSource final : public ParameterSource {
 public:
  DictSource(std::map<std::string, ParameterValue> values, std::string prefix)
      : values_(std::move(values)), prefix_(std::move(prefix)) {}
  std::optional<ParameterValue> get(const std::string& name) const override {
    const auto it = values_.find(name);
    if (it == values_.end()) return std::nullopt;
    return it->second;
  }
  std::string display_name(const std::string& name) const override { return prefix_ + name; }
  std::vector<std::string> names() const override {
    std::vector<std::string> out;
    for (const auto& kv : values_)
      out.push_back(kv.first);
    return out;
  }

 private:
  std::map<std::string, ParameterValue> values_;
  std::string prefix_;
};

}  // namespace

Result<Setup> make_setup(const std::string& port, std::map<std::string, ParameterValue> values,
                         const std::string& display_prefix) {
  values.emplace("port_name", port);  // a port_name given among the values wins (the ROS 2 node)
  const DictSource source(std::move(values), display_prefix);
  std::vector<std::string> errors;
  Setup setup;
  if (auto loaded = load_parameters(source)) {
    setup.node = std::move(*loaded);
  } else {
    errors.push_back(loaded.error().message);
  }
  for (const std::string& name : unknown_parameter_names(source)) {
    errors.push_back("parameter " + display_prefix + name +
                     " unknown (ranger_can.parameters() lists the names)");
  }
  if (errors.empty()) return setup;
  return Error{Errc::kInvalidArgument, text::join(errors, "\n")};
}

Result<ParameterValue> check_value(const std::string& name, const ParameterValue& value) {
  const Parameter* row = find_node_parameter(name);
  if (!row) {
    return Error{Errc::kInvalidArgument,
                 "parameter " + name + " unknown (ranger_can.parameters() lists the names)"};
  }
  auto checked = check_parameter(*row, value);
  if (!checked) {
    return Error{Errc::kInvalidArgument, "parameter " + name + " " + checked.error().message};
  }
  return checked;
}

std::string python_type(ParameterType type) {
  switch (type) {
    case ParameterType::kBool:
      return "bool";
    case ParameterType::kInteger:
      return "int";
    case ParameterType::kNumber:
    case ParameterType::kSeconds:
      return "double";
    case ParameterType::kText:
    case ParameterType::kChoice:
      return "string";
    case ParameterType::kNumberList:
      return "double_list";
    case ParameterType::kTextList:
      return "string_list";
  }
  return "string";
}

}  // namespace ranger::python
