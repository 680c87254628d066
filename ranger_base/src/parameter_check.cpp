#include "ranger_base/parameter_check.hpp"

#include <iostream>
#include <iterator>
#include <sstream>

namespace ranger_base {
namespace {

void flatten(const std::string& prefix, const XmlRpc::XmlRpcValue& value, MapParameterSource& out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    out.values[prefix] = value;
    return;
  }
  for (const auto& [name, child] : value) {
    flatten(prefix.empty() ? name : prefix + "/" + name, child, out);
  }
}

}  // namespace

ranger::Result<MapParameterSource> parameters_from_xml(const std::string& xml) {
  int offset = static_cast<int>(xml.find("<value>"));
  if (offset < 0) {
    return ranger::Error{ranger::Errc::kInvalidArgument, "no XML-RPC <value> in the input"};
  }
  const XmlRpc::XmlRpcValue value(xml, &offset);
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return ranger::Error{ranger::Errc::kInvalidArgument,
                         "the input is not an XML-RPC struct of parameters"};
  }
  MapParameterSource source;
  flatten("", value, source);
  return source;
}

int check_parameters(std::istream& in, std::ostream& err) {
  const std::string xml{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto source = parameters_from_xml(xml);
  if (!source) {
    err << "ranger_base_node --check-parameters: " << source.error().message << "\n";
    return 2;
  }
  const auto problems = ranger::parameter_problems(*source, kAlsoRead);
  for (const auto& problem : problems)
    err << problem << "\n";
  return problems.empty() ? 0 : 2;
}

}  // namespace ranger_base
