// `ranger_base_node --check-parameters`: the parameters as one XML-RPC struct (what
// ranger_bringup's scripts/check_launch.py sends), checked by the node's own rules.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "ranger_base/parameter_check.hpp"

namespace ranger_base {
namespace {

// An XML-RPC <value> struct of `members` (each "<member>...</member>").
std::string xml(const std::string& members) {
  return "<?xml version='1.0'?>\n<params><param><value><struct>" + members +
         "</struct></value></param></params>";
}
std::string member(const std::string& name, const std::string& value) {
  return "<member><name>" + name + "</name><value>" + value + "</value></member>";
}

int check(const std::string& text, std::string& err) {
  std::istringstream in(text);
  std::ostringstream out;
  const int status = check_parameters(in, out);
  err = out.str();
  return status;
}

TEST(ParameterCheck, GoodParametersPassAndNestedOnesAreNamesWithSlashes) {
  const auto source = parameters_from_xml(xml(
      member("port_name", "<string>sim</string>") +
      member("linear", "<struct>" +
                           member("x", "<struct>" + member("max_velocity", "<double>1.0</double>") +
                                           "</struct>") +
                           "</struct>")));
  ASSERT_TRUE(source.ok()) << source.error().message;
  EXPECT_TRUE(source->get("linear/x/max_velocity").has_value());
  std::string err;
  EXPECT_EQ(check(xml(member("port_name", "<string>sim</string>") +
                      member("publish_rate", "<int>20</int>")),
                  err),
            0)
      << err;
  EXPECT_EQ(err, "");
}

TEST(ParameterCheck, EveryProblemIsNamedAndTheStatusIsTwo) {
  std::string err;
  EXPECT_EQ(check(xml(member("protocol", "<string>xyz</string>") +
                      member("publish_rate", "<string>abc</string>") +
                      member("odom_frame_id", "<string>odom</string>")),
                  err),
            2);
  EXPECT_NE(err.find("parameter ~protocol = \"xyz\": expected one of auto, manual, agx_v2"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("parameter ~publish_rate = \"abc\""), std::string::npos) << err;
  EXPECT_NE(err.find("parameter ~odom_frame_id is not one ranger_base_node reads"),
            std::string::npos)
      << err;
  EXPECT_EQ(check("not xml", err), 2);
  EXPECT_NE(err.find("no XML-RPC <value>"), std::string::npos) << err;
}

}  // namespace
}  // namespace ranger_base
