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

DriverSnapshot healthy() {
  DriverSnapshot s;
  s.bus_name = "can0";
  s.bus_open = true;
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
  DriverSnapshot s;
  s.bus_name = "can0";
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

TEST(Diagnostics, ReArmRequiredIsAWarningNamingTheCause) {
  auto s = healthy();
  s.controller.refusal = ranger::MotionRefusal::kRearmRequired;
  s.controller.latched_causes = 0u | ranger::StopCause::kEstop;
  DiagnosticStatusWrapper d;
  diagnose_control(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::WARN);
  EXPECT_NE(d.message.find("rearm_required after emergency_stop"), std::string::npos) << d.message;
  EXPECT_EQ(value(d, "Re-arm required"), "yes");
  EXPECT_EQ(value(d, "Latched stop causes"), "emergency_stop");
}

TEST(Diagnostics, ReclaimBlockedAfterRemoteSaysToCallResume) {
  auto s = healthy();
  s.controller.control_mode = protocol::ControlMode::kStandby;
  s.controller.refusal = ranger::MotionRefusal::kStandby;
  s.controller.reclaim_blocked = true;
  DiagnosticStatusWrapper d;
  diagnose_control(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::WARN);
  EXPECT_EQ(d.message, "remote control had the chassis: call resume to take CAN control");
}

TEST(Diagnostics, SteerFirstAndBelowMinimumAreShown) {
  auto s = healthy();
  s.controller.steer_first_factor = 0.5;
  DiagnosticStatusWrapper steering;
  diagnose_control(s, steering);
  EXPECT_EQ(steering.level, DiagnosticStatus::OK);
  EXPECT_NE(steering.message.find("steering first"), std::string::npos) << steering.message;
  s.controller.steer_first_factor = 1.0;
  s.controller.refusal = ranger::MotionRefusal::kBelowMinimum;
  DiagnosticStatusWrapper below;
  diagnose_control(s, below);
  EXPECT_EQ(below.level, DiagnosticStatus::WARN);
  EXPECT_NE(below.message.find("below_minimum"), std::string::npos) << below.message;
}

TEST(Diagnostics, AnInvalidCommandIsAWarningNamingTheField) {
  auto s = healthy();
  s.controller.refusal = ranger::MotionRefusal::kInvalidCommand;
  s.controller.invalid_command = "linear.z is NaN";
  s.controller.counters.invalid_commands = 12;
  DiagnosticStatusWrapper d;
  diagnose_control(s, d);
  EXPECT_EQ(d.level, DiagnosticStatus::WARN);
  EXPECT_NE(d.message.find("linear.z is NaN"), std::string::npos) << d.message;
  EXPECT_EQ(value(d, "cmd_vel refused (NaN or inf)"), "12");
}

TEST(Diagnostics, TheOdometrysGapIsShown) {
  auto s = healthy();
  s.odometry.gaps = 2;
  s.odometry.last_gap = 2040ms;
  DiagnosticStatusWrapper d;
  diagnose_link(s, d);
  EXPECT_EQ(value(d, "Odometry gaps"), "2");
  EXPECT_EQ(value(d, "Last odometry gap (s)"), "2.04");
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
  s.controller.active_causes = 0u | ranger::StopCause::kEstop;
  s.controller.faults.push_back("emergency_stop");
  DiagnosticStatusWrapper error;
  diagnose_errors(s, error);
  EXPECT_EQ(error.level, DiagnosticStatus::ERROR);
  DiagnosticStatusWrapper none;
  diagnose_errors(healthy(), none);
  EXPECT_EQ(none.level, DiagnosticStatus::OK);
}

TEST(Diagnostics, BatteryShowsTheManualsPack) {
  DiagnosticStatusWrapper out;
  diagnose_battery(healthy(), out);
  EXPECT_EQ(value(out, "Technology"), "LiFePO4");
  EXPECT_EQ(std::stod(value(out, "Nominal voltage (V)")), 48.0);
  EXPECT_EQ(value(out, "Normal voltage range (V)"), "46-50");
}

TEST(Diagnostics, LowBatteryIsAnError) {
  auto s = healthy();
  ranger::BmsData d;
  d.soc = 8.0;
  s.feedback.bms[0] = ranger::Stamped<ranger::BmsData>{d, 1s, 1s};
  s.controller.active_causes = 0u | ranger::StopCause::kLowBattery;
  DiagnosticStatusWrapper out;
  diagnose_battery(s, out);
  EXPECT_EQ(out.level, DiagnosticStatus::ERROR);
}

TEST(Diagnostics, FrameRatesPerIdFromTheSnapshotAndRejectsWarn) {
  FrameRateMonitor monitor;
  auto s = healthy();
  // 50 Hz of 0x211 over the stats' window, as the driver records them.
  for (int i = 0; i < 100; ++i) {
    s.frames.record(protocol::kSystemStatusId, ranger::Timestamp(10s) + i * 20ms, true, 0);
  }
  s.now = ranger::Timestamp(10s) + 2s;
  DiagnosticStatusWrapper ok;
  monitor.diagnose(s, ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK) << ok.message;
  EXPECT_NEAR(std::stod(value(ok, "0x211 system_status (Hz)")), 50.0, 5.0);
  // A padded frame is counted and shown; a rejected one turns the status to WARN once.
  s.frames.record(protocol::kMotionFeedbackId, s.now, true, 2);
  s.frames.record(protocol::kMotionFeedbackId, s.now, false, 0);
  DiagnosticStatusWrapper rejected;
  monitor.diagnose(s, rejected);
  EXPECT_EQ(rejected.level, DiagnosticStatus::WARN) << rejected.message;
  EXPECT_EQ(value(rejected, "0x221 longer than its layout"), "1");
  EXPECT_EQ(value(rejected, "0x221 rejected"), "1");
  DiagnosticStatusWrapper later;
  monitor.diagnose(s, later);
  EXPECT_EQ(later.level, DiagnosticStatus::OK) << later.message;  // nothing new rejected
}

// ---- Protocol: the settings, the identification, the plausibility monitors -----------------

std::shared_ptr<ranger::IdentificationStatus> identification(ranger::IdentificationPhase phase) {
  ranger::IdentificationStatus id;
  id.phase = phase;
  id.revision = "manual";
  id.message = "steering probe";
  return std::make_shared<ranger::IdentificationStatus>(std::move(id));
}

TEST(ProtocolDiagnostics, ForcedSettingsAreOkAndListed) {
  auto s = healthy();
  s.profile.spin_sign = -1;
  DiagnosticStatusWrapper d;
  diagnose_protocol(s, {"forced: protocol manual, model ranger", "can0"}, d);
  EXPECT_EQ(d.level, DiagnosticStatus::OK) << d.message;
  EXPECT_NE(d.message.find("manual with spin_sign=cw"), std::string::npos) << d.message;
  EXPECT_EQ(value(d, "Settings from"), "forced: protocol manual, model ranger");
  EXPECT_EQ(value(d, "spin_sign"), "cw");
  EXPECT_EQ(value(d, "steering_unit_111"), "centideg");
  EXPECT_EQ(value(d, "Identification"), "<missing>");
}

TEST(ProtocolDiagnostics, IdentifyingIsOkAndDecidedShowsTheEvidence) {
  auto s = healthy();
  s.protocol = ranger::ProtocolChoice::kAuto;
  const auto status = identification(ranger::IdentificationPhase::kSteerProbe);
  s.identification = status;
  DiagnosticStatusWrapper probing;
  diagnose_protocol(s, {"auto: identified from the chassis, model ranger", "can0"}, probing);
  EXPECT_EQ(probing.level, DiagnosticStatus::OK) << probing.message;
  EXPECT_NE(probing.message.find("identifying the chassis (steer_probe)"), std::string::npos)
      << probing.message;

  auto& id = *status;
  id.phase = ranger::IdentificationPhase::kDecided;
  id.evidence = {"no frame only the vendor's revision sends: preset manual",
                 "spin position at standstill: the unit is centideg"};
  id.decided = {{"steering_unit_271", "centideg", "spin position 57.8 deg"}};
  id.undecided = {"spin_field", "spin_sign"};
  id.confidence = 0.97;
  DiagnosticStatusWrapper decided;
  diagnose_protocol(s, {"auto", "can0"}, decided);
  EXPECT_EQ(decided.level, DiagnosticStatus::OK) << decided.message;
  EXPECT_EQ(decided.message, "identified: manual");
  EXPECT_EQ(value(decided, "Identification"), "decided");
  EXPECT_EQ(value(decided, "Evidence 2"), "spin position at standstill: the unit is centideg");
  EXPECT_EQ(value(decided, "Decided steering_unit_271"), "centideg (spin position 57.8 deg)");
  EXPECT_EQ(value(decided, "Undecided (the preset's value, checked while driving)"),
            "spin_field, spin_sign");
}

TEST(ProtocolDiagnostics, AFailedIdentificationIsAnErrorNamingWhatToSetAndTheCommissioning) {
  auto s = healthy();
  s.protocol = ranger::ProtocolChoice::kAuto;
  const auto failed = identification(ranger::IdentificationPhase::kFailed);
  failed->message = ranger::unidentified_message("no 0x271 answer", 10s);
  s.identification = failed;
  DiagnosticStatusWrapper d;
  diagnose_protocol(s, {"auto", "can1"}, d);
  EXPECT_EQ(d.level, DiagnosticStatus::ERROR);
  for (const char* expected : {"identify_timeout", "protocol: manual", "steering_unit_111",
                               "commissioning_file", "ranger_can commission IFACE --wheels-lifted",
                               "ranger_can commission can1 --wheels-lifted"}) {
    EXPECT_NE(d.message.find(expected), std::string::npos) << expected << " in " << d.message;
  }
  // Control mode says why motion is refused, pointing at Protocol.
  s.controller.refusal = ranger::MotionRefusal::kIdentifying;
  s.controller.identifying = ranger::IdentificationPhase::kFailed;
  DiagnosticStatusWrapper control;
  diagnose_control(s, control);
  EXPECT_EQ(control.level, DiagnosticStatus::ERROR) << control.message;
}

TEST(ProtocolDiagnostics, WarningsAreWarnWithTheValueToTryAndAStopIsAnError) {
  auto s = healthy();
  ranger::PlausibilityFinding reference;
  reference.check = "steering_reference";
  reference.setting = "steering_reference";
  reference.try_value = "inner_front";
  reference.detail = "the wheels fit the inner front wheel";
  s.plausibility.warnings = {reference};
  DiagnosticStatusWrapper warned;
  diagnose_protocol(s, {"forced", "sim"}, warned);
  EXPECT_EQ(warned.level, DiagnosticStatus::WARN);
  EXPECT_NE(warned.message.find("steering_reference: try inner_front"), std::string::npos)
      << warned.message;
  EXPECT_EQ(value(warned, "Plausibility warning 1"), reference.text());

  ranger::PlausibilityFinding spin;
  spin.check = "yaw";
  spin.setting = "spin_sign";
  spin.try_value = "cw";
  spin.detail = "turns the other way";
  spin.stops = true;
  s.plausibility.stop = spin;
  DiagnosticStatusWrapper stopped;
  diagnose_protocol(s, {"forced", "sim"}, stopped);
  EXPECT_EQ(stopped.level, DiagnosticStatus::ERROR);
  EXPECT_NE(stopped.message.find("spin_sign: try cw"), std::string::npos) << stopped.message;
  EXPECT_NE(stopped.message.find("steering_reference: try inner_front"), std::string::npos)
      << stopped.message;
  EXPECT_EQ(value(stopped, "Plausibility stop"), spin.text());
}

TEST(ProtocolDiagnostics, ListeningIsNotAMissingChassis) {
  auto s = healthy();
  s.controller.link = ranger::LinkState::kNeverConnected;
  s.controller.refusal = ranger::MotionRefusal::kIdentifying;
  s.controller.quiet = true;
  s.controller.identifying = ranger::IdentificationPhase::kListening;
  s.now = ranger::Timestamp(1s);
  s.frames.record(protocol::kSystemStatusId, s.now, true, 0);
  DiagnosticStatusWrapper link, control;
  diagnose_link(s, link);
  diagnose_control(s, control);
  EXPECT_EQ(link.level, DiagnosticStatus::OK) << link.message;
  EXPECT_NE(link.message.find("listening"), std::string::npos) << link.message;
  EXPECT_EQ(control.level, DiagnosticStatus::OK) << control.message;
}

}  // namespace
}  // namespace ranger_base
