#include "ranger_base/parameters.hpp"

#include <ros/node_handle.h>
#include <ros/param.h>

namespace ranger_base {

ranger::ParameterValue from_xmlrpc(const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue v = value;  // the accessors are not const
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool&>(v);
    case XmlRpc::XmlRpcValue::TypeInt:
      return static_cast<int&>(v);
    case XmlRpc::XmlRpcValue::TypeDouble:
      return static_cast<double&>(v);
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string&>(v);
    case XmlRpc::XmlRpcValue::TypeArray: {
      std::vector<ranger::ParameterValue> items;
      for (int i = 0; i < v.size(); ++i)
        items.push_back(from_xmlrpc(v[i]));
      return items;
    }
    case XmlRpc::XmlRpcValue::TypeStruct:
      return ranger::ParameterValue::dictionary();
    default:
      return {};
  }
}

NodeHandleParameterSource::NodeHandleParameterSource(const ros::NodeHandle& private_nh)
    : nh_(private_nh) {}

std::optional<ranger::ParameterValue> NodeHandleParameterSource::get(
    const std::string& name) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(name, v)) return std::nullopt;
  return from_xmlrpc(v);
}

std::string NodeHandleParameterSource::display_name(const std::string& name) const {
  return nh_.resolveName(name);
}

std::vector<std::string> NodeHandleParameterSource::names() const {
  std::vector<std::string> all, out;
  if (!ros::param::getParamNames(all)) return out;
  std::string prefix = nh_.getNamespace();
  if (prefix.empty() || prefix.back() != '/') prefix += '/';
  for (const auto& n : all) {
    if (n.compare(0, prefix.size(), prefix) == 0) out.push_back(n.substr(prefix.size()));
  }
  return out;
}

std::optional<ranger::ParameterValue> MapParameterSource::get(const std::string& name) const {
  const auto it = values.find(name);
  if (it == values.end()) return std::nullopt;
  return from_xmlrpc(it->second);
}

std::vector<std::string> MapParameterSource::names() const {
  std::vector<std::string> out;
  for (const auto& kv : values)
    out.push_back(kv.first);
  return out;
}

}  // namespace ranger_base
