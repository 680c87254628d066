// /diagnostics is the library's groups (ranger_can/control/diagnostics.hpp, tested there) mapped
// one to one: each group's level, message and key/values become the status's.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>

#include "ranger_base/diagnostics.hpp"

namespace ranger_base {
namespace {

using diagnostic_msgs::DiagnosticStatus;

TEST(Diagnostics, AGroupBecomesAStatusOneToOne) {
  static_assert(static_cast<int>(ranger::DiagnosticLevel::kOk) == DiagnosticStatus::OK);
  static_assert(static_cast<int>(ranger::DiagnosticLevel::kWarn) == DiagnosticStatus::WARN);
  static_assert(static_cast<int>(ranger::DiagnosticLevel::kError) == DiagnosticStatus::ERROR);
  static_assert(static_cast<int>(ranger::DiagnosticLevel::kStale) == DiagnosticStatus::STALE);
  ranger::DriverSnapshot s;
  s.bus_name = "can0";
  s.bus_error = "can0: no such interface";
  const ranger::DiagnosticGroup group = ranger::diagnose_link(s);
  diagnostic_updater::DiagnosticStatusWrapper out;
  to_status(group, out);
  EXPECT_EQ(out.level, DiagnosticStatus::ERROR);
  EXPECT_EQ(out.message, group.message);
  ASSERT_EQ(out.values.size(), group.values.size());
  for (std::size_t i = 0; i < group.values.size(); ++i) {
    EXPECT_EQ(out.values[i].key, group.values[i].first);
    EXPECT_EQ(out.values[i].value, group.values[i].second);
  }
}

}  // namespace
}  // namespace ranger_base
