// The node's parameters: the library's table of everything a node reads
// (ranger_can/frontend/node_parameters.hpp: the rows, their checks and the loader, shared with the
// ROS 2 node) read from the private namespace. What is here is the mapping: the parameter
// server's XmlRpc values as the library's ParameterValue. Every problem names the parameter and
// its valid range, and all of them are reported at once, so a bad launch file is fixed in one go;
// ranger_base/README.md's parameter rows are the table's (test_parameters checks them).
#pragma once

#include <xmlrpcpp/XmlRpcValue.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <ranger_can/frontend/node_parameters.hpp>

namespace ros {
class NodeHandle;
}

namespace ranger_base {

using ranger::known_parameter_names;
using ranger::load_parameters;
using ranger::NodeParameters;

ranger::ParameterValue from_xmlrpc(const XmlRpc::XmlRpcValue& value);

// The node's private namespace.
class NodeHandleParameterSource final : public ranger::ParameterSource {
 public:
  explicit NodeHandleParameterSource(const ros::NodeHandle& private_nh);
  std::optional<ranger::ParameterValue> get(const std::string& name) const override;
  std::string display_name(const std::string& name) const override;
  std::vector<std::string> names() const override;

 private:
  const ros::NodeHandle& nh_;
};

// Values as the parameter server holds them, without a ROS master (tests).
class MapParameterSource final : public ranger::ParameterSource {
 public:
  std::map<std::string, XmlRpc::XmlRpcValue> values;
  std::optional<ranger::ParameterValue> get(const std::string& name) const override;
  std::string display_name(const std::string& name) const override { return "~" + name; }
  std::vector<std::string> names() const override;
};

// Besides the table's rows, the node's namespace may hold diagnostic_updater's own
// `diagnostic_period`: not a typo (ranger::unknown_parameter_names' other names).
inline const std::vector<std::string> kAlsoRead = {"diagnostic_period"};

}  // namespace ranger_base
