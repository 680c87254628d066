// The diagnostics rules, from hand-made snapshots.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>

#include <ranger_can/wire/protocol.hpp>

#include "ranger_base/diagnostics.hpp"

namespace ranger_base {
namespace {

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;
using namespace std::chrono_literals;
namespace protocol = ranger::protocol;

LinkSnapshot healthy() {
  LinkSnapshot s;
  s.port_name = "can0";
  s.bus_open = true;
  s.has_controller = true;
  s.controller.link = ranger::LinkState::kConnected;
  s.controller.control_mode = protocol::ControlMode::kCan;
  s.controller.refusal = ranger::MotionRefusal::kNone;
  return s;
}

std::string value(const DiagnosticStatusWrapper& d, const std::string& key) {
  for (const auto& kv : d.values) {
    if (kv.key == key) return kv.value;
  }
  return "<missing>";
}

TEST(Diagnostics, MissingAdapterIsAnErrorNamingThePort) {
  LinkSnapshot s;
  s.port_name = "can0";
  s.bus_error = "can0: no such interface";
  DiagnosticStatusWrapper d;
  diagnose_link(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::ERROR);
  EXPECT_NE(d.message.find("can0: no such interface"), std::string::npos) << d.message;
}

TEST(Diagnostics, InterfaceDownIsAnError) {
  auto s = healthy();
  s.bus.state = ranger::BusState::kDown;
  s.bus.detail = "link down";
  DiagnosticStatusWrapper d;
  diagnose_link(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::ERROR);
}

TEST(Diagnostics, HealthyLinkIsOk) {
  auto s = healthy();
  DiagnosticStatusWrapper d;
  diagnose_link(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::OK) << d.message;
  s.controller.link = ranger::LinkState::kStale;
  DiagnosticStatusWrapper stale;
  diagnose_link(s, stale);
  EXPECT_EQ(stale.level, DiagnosticStatus::ERROR);
}

TEST(Diagnostics, RemoteControlIsAWarning) {
  auto s = healthy();
  s.controller.control_mode = protocol::ControlMode::kRemote;
  s.controller.refusal = ranger::MotionRefusal::kRemote;
  DiagnosticStatusWrapper d;
  diagnose_control(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::WARN);
  EXPECT_EQ(value(d, "Control mode"), "remote");
}

TEST(Diagnostics, IdleAfterCmdVelTimeoutIsOk) {
  auto s = healthy();
  s.controller.refusal = ranger::MotionRefusal::kCmdTimeout;
  DiagnosticStatusWrapper d;
  diagnose_control(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::OK);
}

TEST(Diagnostics, FaultsAreListedByNameAndStoppingOnesAreErrors) {
  auto s = healthy();
  s.controller.faults = {"motor_driver_1_communication_fault"};
  DiagnosticStatusWrapper warn;
  diagnose_errors(s, warn);
  EXPECT_EQ(warn.level, DiagnosticStatus::WARN);
  EXPECT_EQ(value(warn, "motor_driver_1_communication_fault"), "active");
  s.controller.estop = true;
  s.controller.faults.push_back("emergency_stop");
  DiagnosticStatusWrapper error;
  diagnose_errors(s, error);
  EXPECT_EQ(error.level, DiagnosticStatus::ERROR);
  DiagnosticStatusWrapper none;
  diagnose_errors(healthy(), none);
  EXPECT_EQ(none.level, DiagnosticStatus::OK);
}

TEST(Diagnostics, LowBatteryIsAnError) {
  auto s = healthy();
  ranger::BmsData d;
  d.soc = 8.0;
  s.controller.feedback.bms[0] = ranger::Stamped<ranger::BmsData>{d, 1s, 1s};
  s.controller.low_battery = true;
  DiagnosticStatusWrapper out;
  diagnose_battery(s, out);
  EXPECT_EQ(out.level, DiagnosticStatus::ERROR);
}

TEST(Diagnostics, FrameRatesFromCountsOverTheLinkClock) {
  FrameRateMonitor monitor;
  auto s = healthy();
  s.now = ranger::Timestamp(10s);
  s.frames_by_id[protocol::kSystemStatusId] = 100;
  DiagnosticStatusWrapper first;
  monitor.diagnose(s, first);
  s.now = ranger::Timestamp(12s);
  s.frames_by_id[protocol::kSystemStatusId] = 200;  // 50 Hz
  DiagnosticStatusWrapper second;
  monitor.diagnose(s, second);
  EXPECT_EQ(second.level, DiagnosticStatus::OK) << second.message;
  EXPECT_EQ(std::stod(value(second, "0x211 system_status (Hz)")), 50.0);
  s.now = ranger::Timestamp(14s);
  s.frames_by_id[protocol::kSystemStatusId] = 210;  // 5 Hz: frames lost
  DiagnosticStatusWrapper third;
  monitor.diagnose(s, third);
  EXPECT_EQ(third.level, DiagnosticStatus::WARN);
}

}  // namespace
}  // namespace ranger_base
