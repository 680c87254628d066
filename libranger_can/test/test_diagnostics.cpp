// The diagnostic groups (control/diagnostics.hpp), from hand-made snapshots: what /diagnostics
// shows (the ROS node maps them one to one) and `ranger_can monitor --diagnostics` prints.
#include <gtest/gtest.h>

#include "cli_commands.hpp"
#include "ranger_can/control/diagnostics.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/cli_run.hpp"

namespace ranger {
namespace {

using L = DiagnosticLevel;
using namespace std::chrono_literals;

DriverSnapshot healthy() {
  DriverSnapshot s;
  s.bus_name = "can0";
  s.bus_open = true;
  s.controller.link = LinkState::kConnected;
  s.controller.control_mode = protocol::ControlMode::kCan;
  s.controller.refusal = MotionRefusal::kNone;
  return s;
}

std::string value(const DiagnosticGroup& d, const std::string& key) {
  const std::string* v = d.value(key);
  return v != nullptr ? *v : "<missing>";
}

TEST(Diagnostics, MissingAdapterIsAnErrorNamingThePort) {
  DriverSnapshot s;
  s.bus_name = "can0";
  s.bus_error = "can0: no such interface";
  const DiagnosticGroup d = diagnose_link(s);
  EXPECT_EQ(d.level, L::kError);
  EXPECT_NE(d.message.find("can0: no such interface"), std::string::npos) << d.message;
}

TEST(Diagnostics, InterfaceDownIsAnError) {
  auto s = healthy();
  s.bus.state = BusState::kDown;
  s.bus.detail = "link down";
  const DiagnosticGroup d = diagnose_link(s);
  EXPECT_EQ(d.level, L::kError);
}

TEST(Diagnostics, HealthyLinkIsOk) {
  auto s = healthy();
  const DiagnosticGroup d = diagnose_link(s);
  EXPECT_EQ(d.level, L::kOk) << d.message;
  s.controller.link = LinkState::kStale;
  const DiagnosticGroup stale = diagnose_link(s);
  EXPECT_EQ(stale.level, L::kError);
}

TEST(Diagnostics, RemoteControlIsAWarning) {
  auto s = healthy();
  s.controller.control_mode = protocol::ControlMode::kRemote;
  s.controller.refusal = MotionRefusal::kRemote;
  const DiagnosticGroup d = diagnose_control(s);
  EXPECT_EQ(d.level, L::kWarn);
  EXPECT_EQ(value(d, "Control mode"), "remote");
}

TEST(Diagnostics, ReArmRequiredIsAWarningNamingTheCause) {
  auto s = healthy();
  s.controller.refusal = MotionRefusal::kRearmRequired;
  s.controller.latched_causes = 0u | StopCause::kEstop;
  const DiagnosticGroup d = diagnose_control(s);
  EXPECT_EQ(d.level, L::kWarn);
  EXPECT_NE(d.message.find("rearm_required after emergency_stop"), std::string::npos) << d.message;
  EXPECT_EQ(value(d, "Re-arm required"), "yes");
  EXPECT_EQ(value(d, "Latched stop causes"), "emergency_stop");
}

TEST(Diagnostics, ReclaimBlockedAfterRemoteSaysToCallResume) {
  auto s = healthy();
  s.controller.control_mode = protocol::ControlMode::kStandby;
  s.controller.refusal = MotionRefusal::kStandby;
  s.controller.reclaim_blocked = true;
  const DiagnosticGroup d = diagnose_control(s);
  EXPECT_EQ(d.level, L::kWarn);
  EXPECT_EQ(d.message, "remote control had the chassis: call resume to take CAN control");
}

TEST(Diagnostics, SteerFirstAndBelowMinimumAreShown) {
  auto s = healthy();
  s.controller.steer_first_factor = 0.5;
  const DiagnosticGroup steering = diagnose_control(s);
  EXPECT_EQ(steering.level, L::kOk);
  EXPECT_NE(steering.message.find("steering first"), std::string::npos) << steering.message;
  s.controller.steer_first_factor = 1.0;
  s.controller.refusal = MotionRefusal::kBelowMinimum;
  const DiagnosticGroup below = diagnose_control(s);
  EXPECT_EQ(below.level, L::kWarn);
  EXPECT_NE(below.message.find("below_minimum"), std::string::npos) << below.message;
}

TEST(Diagnostics, IdleAfterCmdVelTimeoutIsOk) {
  auto s = healthy();
  s.controller.refusal = MotionRefusal::kCmdTimeout;
  const DiagnosticGroup d = diagnose_control(s);
  EXPECT_EQ(d.level, L::kOk);
}

TEST(Diagnostics, FaultsAreListedByNameAndStoppingOnesAreErrors) {
  auto s = healthy();
  s.controller.faults = {"motor_driver_1_communication_fault"};
  const DiagnosticGroup warn = diagnose_errors(s);
  EXPECT_EQ(warn.level, L::kWarn);
  EXPECT_EQ(value(warn, "motor_driver_1_communication_fault"), "active");
  s.controller.active_causes = 0u | StopCause::kEstop;
  s.controller.faults.push_back("emergency_stop");
  const DiagnosticGroup error = diagnose_errors(s);
  EXPECT_EQ(error.level, L::kError);
  const DiagnosticGroup none = diagnose_errors(healthy());
  EXPECT_EQ(none.level, L::kOk);
}

TEST(Diagnostics, BatteryShowsTheManualsPack) {
  const DiagnosticGroup out = diagnose_battery(healthy());
  EXPECT_EQ(value(out, "Technology"), "LiFePO4");
  EXPECT_EQ(std::stod(value(out, "Nominal voltage (V)")), 48.0);
  EXPECT_EQ(value(out, "Normal voltage range (V)"), "46-50");
}

TEST(Diagnostics, LowBatteryIsAnError) {
  auto s = healthy();
  BmsData d;
  d.soc = 8.0;
  s.feedback.bms[0] = Stamped<BmsData>{d, 1s, 1s};
  s.controller.active_causes = 0u | StopCause::kLowBattery;
  const DiagnosticGroup out = diagnose_battery(s);
  EXPECT_EQ(out.level, L::kError);
}

TEST(Diagnostics, FrameRatesPerIdFromTheSnapshotAndRejectsWarn) {
  FrameRateMonitor monitor;
  auto s = healthy();
  // 50 Hz of 0x211 over the stats' window, as the driver records them.
  for (int i = 0; i < 100; ++i) {
    s.frames.record(protocol::kSystemStatusId, Timestamp(10s) + i * 20ms, true, 0);
  }
  s.now = Timestamp(10s) + 2s;
  const DiagnosticGroup ok = monitor.diagnose(s);
  EXPECT_EQ(ok.level, L::kOk) << ok.message;
  EXPECT_NEAR(std::stod(value(ok, "0x211 system_status (Hz)")), 50.0, 5.0);
  // A padded frame is counted and shown; a rejected one turns the status to WARN once.
  s.frames.record(protocol::kMotionFeedbackId, s.now, true, 2);
  s.frames.record(protocol::kMotionFeedbackId, s.now, false, 0);
  const DiagnosticGroup rejected = monitor.diagnose(s);
  EXPECT_EQ(rejected.level, L::kWarn) << rejected.message;
  EXPECT_EQ(value(rejected, "0x221 longer than its layout"), "1");
  EXPECT_EQ(value(rejected, "0x221 rejected"), "1");
  const DiagnosticGroup later = monitor.diagnose(s);
  EXPECT_EQ(later.level, L::kOk) << later.message;  // nothing new rejected
}

// ---- Protocol: the settings, the identification, the plausibility monitors -----------------

std::shared_ptr<IdentificationStatus> identification(IdentificationPhase phase) {
  IdentificationStatus id;
  id.phase = phase;
  id.revision = "manual";
  id.message = "steering probe";
  return std::make_shared<IdentificationStatus>(std::move(id));
}

TEST(ProtocolDiagnostics, ForcedSettingsAreOkAndListed) {
  auto s = healthy();
  s.profile.spin_sign = -1;
  const DiagnosticGroup d = diagnose_protocol(s, {"can0", "forced: protocol manual, model ranger"});
  EXPECT_EQ(d.level, L::kOk) << d.message;
  EXPECT_NE(d.message.find("manual with spin_sign=cw"), std::string::npos) << d.message;
  EXPECT_EQ(value(d, "Settings from"), "forced: protocol manual, model ranger");
  EXPECT_EQ(value(d, "spin_sign"), "cw");
  EXPECT_EQ(value(d, "steering_unit_111"), "centideg");
  EXPECT_EQ(value(d, "Identification"), "<missing>");
}

TEST(ProtocolDiagnostics, IdentifyingIsOkAndDecidedShowsTheEvidence) {
  auto s = healthy();
  s.protocol = ProtocolChoice::kAuto;
  const auto status = identification(IdentificationPhase::kSteerProbe);
  s.identification = status;
  const DiagnosticGroup probing =
      diagnose_protocol(s, {"can0", "auto: identified from the chassis, model ranger"});
  EXPECT_EQ(probing.level, L::kOk) << probing.message;
  EXPECT_NE(probing.message.find("identifying the chassis (steer_probe)"), std::string::npos)
      << probing.message;

  auto& id = *status;
  id.phase = IdentificationPhase::kDecided;
  id.evidence = {"no frame only the vendor's revision sends: preset manual",
                 "spin position at standstill: the unit is centideg"};
  id.decided = {{"steering_unit_271", "centideg", "spin position 57.8 deg"}};
  id.undecided = {"spin_field", "spin_sign"};
  id.confidence = 0.97;
  const DiagnosticGroup decided = diagnose_protocol(s, {"can0", "auto"});
  EXPECT_EQ(decided.level, L::kOk) << decided.message;
  EXPECT_EQ(decided.message, "identified: manual");
  EXPECT_EQ(value(decided, "Identification"), "decided");
  EXPECT_EQ(value(decided, "Evidence 2"), "spin position at standstill: the unit is centideg");
  EXPECT_EQ(value(decided, "Decided steering_unit_271"), "centideg (spin position 57.8 deg)");
  EXPECT_EQ(value(decided, "Undecided (the preset's value, checked while driving)"),
            "spin_field, spin_sign");
}

TEST(ProtocolDiagnostics, AFailedIdentificationIsAnErrorNamingWhatToSetAndTheCommissioning) {
  auto s = healthy();
  s.protocol = ProtocolChoice::kAuto;
  const auto failed = identification(IdentificationPhase::kFailed);
  failed->message = unidentified_message("no 0x271 answer", 10s);
  s.identification = failed;
  const DiagnosticGroup d = diagnose_protocol(s, {"can1", "auto"});
  EXPECT_EQ(d.level, L::kError);
  for (const char* expected : {"identify_timeout", "protocol: manual", "steering_unit_111",
                               "commissioning_file", "ranger_can commission IFACE --wheels-lifted",
                               "ranger_can commission can1 --wheels-lifted"}) {
    EXPECT_NE(d.message.find(expected), std::string::npos) << expected << " in " << d.message;
  }
  // Control mode says why motion is refused, pointing at Protocol.
  s.controller.refusal = MotionRefusal::kIdentifying;
  s.controller.identifying = IdentificationPhase::kFailed;
  const DiagnosticGroup control = diagnose_control(s);
  EXPECT_EQ(control.level, L::kError) << control.message;
}

TEST(ProtocolDiagnostics, WarningsAreWarnWithTheValueToTryAndAStopIsAnError) {
  auto s = healthy();
  PlausibilityFinding reference;
  reference.check = "steering_reference";
  reference.setting = "steering_reference";
  reference.try_value = "inner_front";
  reference.detail = "the wheels fit the inner front wheel";
  s.plausibility.warnings = {reference};
  const DiagnosticGroup warned = diagnose_protocol(s, {"sim", "forced"});
  EXPECT_EQ(warned.level, L::kWarn);
  EXPECT_NE(warned.message.find("steering_reference: try inner_front"), std::string::npos)
      << warned.message;
  EXPECT_EQ(value(warned, "Plausibility warning 1"), reference.text());

  PlausibilityFinding spin;
  spin.check = "yaw";
  spin.setting = "spin_sign";
  spin.try_value = "cw";
  spin.detail = "turns the other way";
  spin.stops = true;
  s.plausibility.stop = spin;
  const DiagnosticGroup stopped = diagnose_protocol(s, {"sim", "forced"});
  EXPECT_EQ(stopped.level, L::kError);
  EXPECT_NE(stopped.message.find("spin_sign: try cw"), std::string::npos) << stopped.message;
  EXPECT_NE(stopped.message.find("steering_reference: try inner_front"), std::string::npos)
      << stopped.message;
  EXPECT_EQ(value(stopped, "Plausibility stop"), spin.text());
}

TEST(ProtocolDiagnostics, ListeningIsNotAMissingChassis) {
  auto s = healthy();
  s.controller.link = LinkState::kNeverConnected;
  s.controller.refusal = MotionRefusal::kIdentifying;
  s.controller.quiet = true;
  s.controller.identifying = IdentificationPhase::kListening;
  s.now = Timestamp(1s);
  s.frames.record(protocol::kSystemStatusId, s.now, true, 0);
  const DiagnosticGroup link = diagnose_link(s);
  const DiagnosticGroup control = diagnose_control(s);
  EXPECT_EQ(link.level, L::kOk) << link.message;
  EXPECT_NE(link.message.find("listening"), std::string::npos) << link.message;
  EXPECT_EQ(control.level, L::kOk) << control.message;
}

// ---- the group as data -------------------------------------------------------------------------

// merge_summary is diagnostic_updater's mergeSummary: the higher level wins; problems are joined.
TEST(DiagnosticGroup, MergesSummariesAsDiagnosticUpdaterDoes) {
  DiagnosticGroup g;
  g.summary(L::kOk, "CAN bus active");
  g.merge_summary(L::kOk, "chassis connected");
  EXPECT_EQ(g.level, L::kOk);
  EXPECT_EQ(g.message, "CAN bus active");
  g.merge_summary(L::kError, "chassis silent");
  EXPECT_EQ(g.level, L::kError);
  EXPECT_EQ(g.message, "chassis silent");
  g.merge_summary(L::kWarn, "check the setting");
  EXPECT_EQ(g.level, L::kError);
  EXPECT_EQ(g.message, "chassis silent; check the setting");
}

TEST(DiagnosticGroup, NumbersAreWrittenAsAStreamWritesThem) {
  DiagnosticGroup g;
  g.add("double", 0.97);
  g.add("whole", 48.0);
  g.add("large", 1e6);
  g.add("count", std::uint64_t{12});
  EXPECT_EQ(value(g, "double"), "0.97");
  EXPECT_EQ(value(g, "whole"), "48");
  EXPECT_EQ(value(g, "large"), "1e+06");
  EXPECT_EQ(value(g, "count"), "12");
  g.name = "Battery";
  g.summary(L::kWarn, "battery low");
  EXPECT_EQ(to_text(g),
            "Battery: WARN: battery low\n  double: 0.97\n  whole: 48\n  large: 1e+06\n"
            "  count: 12\n");
}

TEST(ChassisDiagnostics, AReportHasEveryGroupInOrderAndTheHardwareIdNamesTheRobot) {
  ChassisDiagnostics diagnostics({"sim", "forced: protocol manual, model ranger", "/robot1"});
  const auto groups = diagnostics.report(healthy());
  ASSERT_EQ(groups.size(), kDiagnosticGroups.size());
  for (std::size_t i = 0; i < groups.size(); ++i)
    EXPECT_EQ(groups[i].name, kDiagnosticGroups[i]);
  EXPECT_EQ(value(groups[2], "Settings from"), "forced: protocol manual, model ranger");
  EXPECT_EQ(hardware_id("/robot1", "sim"), "ranger:/robot1:sim");
  EXPECT_EQ(hardware_id("", "can0"), "ranger:/:can0");
}

// `ranger_can monitor IFACE --diagnostics` prints the same groups, listening only (the virtual
// chassis in lock-step: simulated time, nothing sent, identified passively).
TEST(MonitorDiagnostics, PrintsEveryGroupFromAListeningDriver) {
  const auto r = test::run_cli(cli::run_monitor, {"sim:agx_v2", "--diagnostics"});
  ASSERT_EQ(r.rc, 0) << r.err;
  std::size_t previous = 0;  // every group, in order, each a heading line
  for (const std::string_view name : kDiagnosticGroups) {
    const std::size_t at = r.out.find(std::string(name) + ": ", previous);
    ASSERT_NE(at, std::string::npos) << name << " in\n" << r.out;
    EXPECT_TRUE(at == 0 || r.out[at - 1] == '\n') << name;
    previous = at;
  }
  EXPECT_NE(r.out.find("Protocol: OK: identified: agx_v2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  Frames sent: 0\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Chassis link: connected"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace ranger
