// Fault injection against the virtual chassis through the controller, on the in-process loopback
// bus in lock-step with a ManualClock (loopback_fault_rig.hpp). Each case injects one fault while
// the vehicle moves and asserts the outcome: the state the controller reports, what crossed the
// wire (and when, on the bus's timestamps), whether the chassis stopped or resumed, and that no
// frame was lost without being counted. Every case also runs the WireAudit over the whole trace.
//
// tests/e2e covers the same chassis faults at the level of "the vehicle stopped / resumed"; this
// suite adds the bus faults (bus-off, link down, saturating noise), hostile commands, and the
// wire-level timing and accounting of each fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "loopback_fault_rig.hpp"
#include "ranger_can/transport/error_frame.hpp"

namespace ranger::faults {
namespace {

using protocol::ControlMode;
using protocol::MotionMode;

constexpr double kCruise = 0.8;  // m/s

bool has_fault(const ControllerState& s, const std::string& name) {
  return std::find(s.faults.begin(), s.faults.end(), name) != s.faults.end();
}
MotionCommand motion_of(const CanFrame& f) {
  auto m = decode(f);
  EXPECT_TRUE(m.ok());
  return m.ok() ? std::get<MotionCommand>(*m) : MotionCommand{};
}
double speed_of_0x221(const CanFrame& f) {
  auto m = decode(f);
  EXPECT_TRUE(m.ok());
  return m.ok() ? std::get<MotionFeedback>(*m).speed : std::numeric_limits<double>::quiet_NaN();
}
bool host_id(std::uint32_t id) {
  return id == protocol::kMotionCommandId || id == protocol::kMotionModeCommandId ||
         id == protocol::kControlModeCommandId || id == protocol::kErrorClearCommandId ||
         id == protocol::kUltrasonicSettingId;
}

class Faults : public ::testing::Test {
 protected:
  void TearDown() override {
    for (const std::string& v : rig_.audit().violations())
      ADD_FAILURE() << "wire audit: " << v;
  }
  std::uint64_t host_frames_on_wire(Timestamp from) const {
    return static_cast<std::uint64_t>(std::count_if(
        rig_.trace().begin(), rig_.trace().end(),
        [&](const CanFrame& f) { return !f.is_error && f.stamp >= from && host_id(f.id); }));
  }

  LoopbackFaultRig rig_;
};

// ---- bus faults ---------------------------------------------------------------------------------

TEST_F(Faults, BusOffStopsTheChassisAndRestartResumesWithEveryFrameAccountedFor) {
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  const BusStatistics before = rig_.driver_bus().status().stats;
  const ControllerCounters sent_before = rig_.state().counters;

  // The adapter reports bus-off and nothing is acknowledged any more: frames queue, then drop.
  const Timestamp t_off = rig_.now();
  rig_.network().inject_error_frame(can_error::make(can_error::kBusOff));
  rig_.network().stall_transmission(true);
  rig_.run_for(1500ms);

  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kBusOff);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kLinkLost);
  EXPECT_TRUE(has_fault(rig_.state(), "link_lost"));
  EXPECT_EQ(rig_.snapshot().speed, 0.0) << "the chassis's own 500 ms watchdog stops it";
  EXPECT_TRUE(rig_.snapshot().host_link_lost);
  // Nothing vanished silently: each send was queued (tx_frames) or refused and counted by both
  // the bus (tx_dropped) and the controller (send_failures).
  const BusStatistics during = rig_.driver_bus().status().stats;
  const ControllerCounters& c = rig_.state().counters;
  EXPECT_GT(c.send_failures - sent_before.send_failures, 0u) << "the queue must have filled";
  EXPECT_EQ(during.tx_dropped - before.tx_dropped, c.send_failures - sent_before.send_failures);
  EXPECT_EQ(during.tx_frames - before.tx_frames, c.frames_sent - sent_before.frames_sent);
  EXPECT_EQ(c.error_frames - sent_before.error_frames, 1u);

  // The controller restarts: the queued frames go out and the link comes back; motion resumes
  // only after the caller's re-arm (the link loss was an involuntary stop).
  rig_.network().inject_error_frame(can_error::make(can_error::kRestarted));
  rig_.network().stall_transmission(false);
  const Timestamp t_restart = rig_.now();
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().link == LinkState::kConnected; }, 2s));
  EXPECT_LE(rig_.now() - t_restart, 2s);
  ASSERT_TRUE(rig_.latched_then_rearmed_by_resume({kCruise, 0, 0}, kCruise));
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kActive);
  EXPECT_EQ(rig_.driver_bus().status().stats.restarts - before.restarts, 1u);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kNone);
  EXPECT_FALSE(rig_.snapshot().host_link_lost);
  // Every frame the driver's bus accepted since the fault reached the wire.
  EXPECT_EQ(host_frames_on_wire(t_off),
            rig_.driver_bus().status().stats.tx_frames - before.tx_frames);
}

TEST_F(Faults, InterfaceDownAndUpStopsTheChassisThenReopensAndResumes) {
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  const BusStatistics before = rig_.driver_bus().status().stats;
  const std::uint64_t failures_before = rig_.state().counters.send_failures;

  rig_.network().set_link_up(false);  // `ip link set can0 down`, or the adapter's cable pulled
  rig_.run_for(2s);
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kDown);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kLinkLost);
  EXPECT_EQ(rig_.state().link, LinkState::kStale);
  EXPECT_GT(rig_.state().counters.send_failures, failures_before);
  EXPECT_EQ(rig_.snapshot().speed, 0.0);
  EXPECT_TRUE(rig_.snapshot().host_link_lost);

  rig_.network().set_link_up(true);
  const Timestamp t_up = rig_.now();
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().link == LinkState::kConnected; }, 3s));
  // Reopening is rate-limited to one attempt per reopen_interval (1 s): back within that.
  EXPECT_LE(rig_.now() - t_up, 1s + 50ms);
  EXPECT_GE(rig_.driver_bus().status().stats.reopens - before.reopens, 1u);
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kActive);
  ASSERT_TRUE(rig_.latched_then_rearmed_by_resume({kCruise, 0, 0}, kCruise));
  EXPECT_FALSE(rig_.snapshot().host_link_lost);
}

TEST_F(Faults, GarbageAndForeignFramesAtFullBusRateChangeNothingAndAreCountedExactly) {
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  const ControllerCounters before = rig_.state().counters;
  const std::uint64_t chassis_sent_before = rig_.chassis().counters().frames_sent;
  const BusStatistics bus_before = rig_.driver_bus().status().stats;

  // 4 frames per ms (500 kbit/s is ~4000 eight-byte frames/s) for 2 s: two foreign IDs the
  // receive filter must drop and two RANGER IDs with a wrong DLC the codec must reject each
  // millisecond, and a bus error every 50 ms.
  constexpr std::uint64_t kBadRanger = 2 * 2000;
  constexpr std::uint64_t kErrors = 2000 / 50;
  std::uint64_t noise_refused = 0;
  std::uint64_t refusals_seen = 0;
  double min_speed = kCruise, max_speed = kCruise;
  rig_.each_step = [&](Timestamp t) {
    const CanFrame burst[4] = {
        CanFrame{0x123, 8, {1, 2, 3, 4, 5, 6, 7, 8}},
        CanFrame{protocol::kSystemStatusId, 3, {0x00, 0x01, 0x02}},
        CanFrame{0x7FF, 0, {}},
        // Shorter than its layout (a longer frame is valid: its extra bytes are ignored).
        CanFrame{protocol::kMotionModeFeedbackId, 1, {0x02}},
    };
    for (const CanFrame& f : burst) {
      if (!rig_.noise_bus().send(f)) ++noise_refused;
    }
    if (t.count() % 50'000'000 == 0) {
      rig_.network().inject_error_frame(can_error::make(can_error::kBusError));
    }
    if (rig_.state().refusal != MotionRefusal::kNone) ++refusals_seen;
    min_speed = std::min(min_speed, rig_.snapshot().speed);
    max_speed = std::max(max_speed, rig_.snapshot().speed);
  };
  rig_.run_for(2s);
  rig_.each_step = nullptr;
  rig_.step();  // the last noise frames are read

  EXPECT_EQ(noise_refused, 0u);
  EXPECT_EQ(refusals_seen, 0u) << "the controller never stopped commanding";
  EXPECT_EQ(min_speed, kCruise);
  EXPECT_EQ(max_speed, kCruise);
  const ControllerCounters& c = rig_.state().counters;
  const std::uint64_t chassis_sent = rig_.chassis().counters().frames_sent - chassis_sent_before;
  // Each wrong-DLC RANGER frame refused and counted once, each bus error counted once.
  EXPECT_EQ(c.decode_errors - before.decode_errors, kBadRanger);
  EXPECT_EQ(c.error_frames - before.error_frames, kErrors);
  // Every chassis frame and every wrong-DLC RANGER frame reached the controller; no foreign one.
  EXPECT_EQ(c.frames_received - before.frames_received, chassis_sent + kBadRanger);
  const BusStatistics bus = rig_.driver_bus().status().stats;
  EXPECT_EQ(bus.rx_dropped, bus_before.rx_dropped);
  EXPECT_EQ(bus.error_frames - bus_before.error_frames, kErrors);
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kActive);
  EXPECT_EQ(rig_.state().link, LinkState::kConnected);
}

// ---- the chassis misbehaves -------------------------------------------------------------------

TEST_F(Faults, ChassisSilentForOneSecondIsDetectedAfterLinkTimeoutAndResumesWithTheNewCommand) {
  ASSERT_TRUE(rig_.drive({0.6, 0, 0}, 0.6));
  const Timestamp t0 = rig_.now();
  rig_.chassis().silence_for(1s);
  ASSERT_TRUE(
      rig_.run_until([&] { return rig_.state().refusal == MotionRefusal::kLinkLost; }, 500ms));
  const auto statuses = rig_.wire(protocol::kSystemStatusId, t0 - 100ms, t0 + 1ms);
  ASSERT_FALSE(statuses.empty());
  const auto detected_after = rig_.now() - statuses.back().stamp;
  const auto link_timeout = rig_.controller().config().link_timeout;
  EXPECT_GT(detected_after, link_timeout);
  EXPECT_LE(detected_after, link_timeout + 2 * LoopbackFaultRig::kStep);

  rig_.command({0.3, 0, 0});  // the caller changes its mind during the outage
  const Timestamp t_detect = rig_.now();
  rig_.run_for(t0 + 1s - rig_.now());
  // The keep-alive went on with zero commands: the chassis (which still listens) braked and never
  // declared the host lost.
  const auto commands = rig_.wire(protocol::kMotionCommandId, t_detect + 6ms, rig_.now());
  EXPECT_GE(commands.size(), 40u);
  for (const CanFrame& f : commands)
    EXPECT_EQ(motion_of(f).linear_speed, 0.0);
  EXPECT_EQ(rig_.snapshot().speed, 0.0);
  EXPECT_FALSE(rig_.snapshot().host_link_lost);

  // Back: held at rest until the re-arm, then the new command, never the old one.
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().link == LinkState::kConnected; }, 3s));
  ASSERT_TRUE(rig_.latched_then_rearmed_by_resume({0.3, 0, 0}, 0.3));
  rig_.run_for(1s);
  EXPECT_LE(rig_.snapshot().speed, 0.3 + 1e-9);
  EXPECT_EQ(rig_.state().counters.link_losses, 1u);
}

// One chassis fault: how to cause it, what the controller must call it, how to end it.
struct RefusingFault {
  const char* name;
  std::function<void(LoopbackFaultRig&)> inject;
  std::function<void(LoopbackFaultRig&)> clear;
  std::vector<MotionRefusal> refusals;  // any of these is right
  const char* fault;                    // in state().faults, or nullptr
  std::chrono::nanoseconds detection;   // the feedback period that carries it, plus a step
  bool host_silent;                     // no host frames at all while it lasts (remote control)
  bool clear_needs_resume = false;      // ends in standby after remote control: resume() only
};

std::ostream& operator<<(std::ostream& os, const RefusingFault& f) {
  return os << f.name;
}

class RefusingFaults : public Faults, public ::testing::WithParamInterface<RefusingFault> {};

TEST_P(RefusingFaults, StopsMotionOnTheWireAtOnceAndResumesOnlyAfterTheRearm) {
  const RefusingFault& fault = GetParam();
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  fault.inject(rig_);
  ASSERT_TRUE(rig_.run_until(
      [&] {
        const auto r = rig_.state().refusal;
        return std::find(fault.refusals.begin(), fault.refusals.end(), r) != fault.refusals.end();
      },
      fault.detection))
      << "refusal " << to_string(rig_.state().refusal);
  const Timestamp t_detect = rig_.now();
  if (fault.fault) {
    EXPECT_TRUE(has_fault(rig_.state(), fault.fault)) << fault.fault;
  }

  // The first 0x111 after the controller learned of the fault stops the vehicle; none moves it.
  rig_.run_for(1500ms);
  const auto after = rig_.wire(protocol::kMotionCommandId, t_detect);
  if (fault.host_silent) {
    EXPECT_TRUE(after.empty()) << "the host stays silent while the remote control rules";
    EXPECT_TRUE(rig_.wire(protocol::kControlModeCommandId, t_detect).empty());
  } else {
    ASSERT_FALSE(after.empty());
    EXPECT_LE(after.front().stamp - t_detect,
              rig_.controller().config().min_command_interval + LoopbackFaultRig::kStep);
    for (const CanFrame& f : after) {
      EXPECT_EQ(motion_of(f).linear_speed, 0.0);
      EXPECT_EQ(motion_of(f).spin_speed, 0.0);
    }
  }
  EXPECT_EQ(rig_.snapshot().speed, 0.0);

  fault.clear(rig_);
  if (fault.clear_needs_resume) {
    // Remote switched off: standby, and remote control is final: no CAN-mode request of the
    // driver's own until resume().
    rig_.run_for(2s);
    EXPECT_TRUE(rig_.wire(protocol::kControlModeCommandId, t_detect).empty());
    EXPECT_EQ(rig_.snapshot().speed, 0.0);
    ASSERT_TRUE(rig_.resume().ok());
    ASSERT_TRUE(rig_.run_until([&] { return rig_.snapshot().speed > kCruise - 0.05; }, 5s))
        << "refusal " << to_string(rig_.state().refusal);
  } else {
    ASSERT_TRUE(rig_.latched_then_rearmed_by_resume({kCruise, 0, 0}, kCruise));
  }
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kNone);
  if (fault.fault) {
    EXPECT_FALSE(has_fault(rig_.state(), fault.fault));
  }
}

const int kSafetyEdge = protocol::error_bit_index(5, 5);
const int kUnderVoltage = protocol::error_bit_index(7, 0);

INSTANTIATE_TEST_SUITE_P(
    ChassisFaults, RefusingFaults,
    ::testing::Values(
        RefusingFault{"remote_takeover",
                      [](LoopbackFaultRig& r) { r.chassis().remote_takeover(); },
                      [](LoopbackFaultRig& r) { r.chassis().remote_hand_back(); },
                      {MotionRefusal::kRemote},
                      nullptr,
                      40ms,
                      true},
        RefusingFault{"remote_takeover_then_switched_off",
                      [](LoopbackFaultRig& r) { r.chassis().remote_takeover(); },
                      [](LoopbackFaultRig& r) { r.chassis().remote_hand_back(true); },
                      {MotionRefusal::kRemote},
                      nullptr,
                      40ms,
                      true,
                      true},
        RefusingFault{"emergency_stop",
                      [](LoopbackFaultRig& r) { r.chassis().set_emergency_stop(true); },
                      [](LoopbackFaultRig& r) { r.chassis().set_emergency_stop(false); },
                      {MotionRefusal::kEstop},
                      "emergency_stop",
                      40ms,
                      false},
        RefusingFault{"safety_edge_collision",
                      [](LoopbackFaultRig& r) { r.chassis().set_error_bit(kSafetyEdge, true); },
                      [](LoopbackFaultRig& r) { r.chassis().set_error_bit(kSafetyEdge, false); },
                      {MotionRefusal::kCriticalError},
                      nullptr,
                      40ms,
                      false},
        RefusingFault{"low_battery_cut_off",
                      [](LoopbackFaultRig& r) { r.chassis().set_battery_soc(8.0); },
                      [](LoopbackFaultRig& r) {
                        r.chassis().set_battery_soc(60.0);
                        // The chassis latches its under-voltage bit until told to retry.
                        EXPECT_TRUE(r.controller().clear_errors(0x09, r.now()).ok());
                      },
                      {MotionRefusal::kLowBattery, MotionRefusal::kCriticalError},
                      nullptr,
                      40ms,
                      false}),
    [](const ::testing::TestParamInfo<RefusingFault>& p) { return std::string(p.param.name); });

TEST_F(Faults, LowBatteryIsReportedFromBothTheBmsAndTheStatusBits) {
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  rig_.chassis().set_battery_soc(8.0);
  // The BMS frame comes every 500 ms; the status bit every 20 ms.
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().low_battery(); }, 600ms));
  EXPECT_TRUE(has_fault(rig_.state(), "low_battery"));
  EXPECT_TRUE(rig_.state().error_bits & (1u << kUnderVoltage));
  ASSERT_TRUE(rig_.state().battery_soc.has_value());
  EXPECT_LT(*rig_.state().battery_soc, 10.0);
}

TEST_F(Faults, ErrorBitsSetAndClearedByTheChassisAreReportedAndOnlyCriticalOnesStopMotion) {
  ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
  // A steering-servo warning is reported but does not stop the vehicle.
  const int warning = protocol::error_bit_index(4, 0);
  ASSERT_FALSE(protocol::is_critical_error(1u << warning));
  const std::string warning_name = protocol::error_bit_names(1u << warning).front();
  rig_.chassis().set_error_bit(warning, true);
  ASSERT_TRUE(rig_.run_until([&] { return has_fault(rig_.state(), warning_name); }, 40ms));
  const std::uint64_t moving_before = rig_.audit().moving_commands();
  rig_.run_for(1s);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kNone);
  EXPECT_EQ(rig_.snapshot().speed, kCruise);
  EXPECT_GE(rig_.audit().moving_commands() - moving_before, 45u) << "0x111 kept moving it";
  rig_.chassis().set_error_bit(warning, false);
  ASSERT_TRUE(rig_.run_until([&] { return !has_fault(rig_.state(), warning_name); }, 40ms));
  EXPECT_EQ(rig_.state().error_bits, 0u);

  // Two critical bits at once, cleared one after the other: motion resumes only after both.
  const int over_current = protocol::error_bit_index(6, 7);
  rig_.chassis().set_error_bits((1u << kSafetyEdge) | (1u << over_current));
  ASSERT_TRUE(
      rig_.run_until([&] { return rig_.state().refusal == MotionRefusal::kCriticalError; }, 40ms));
  for (const std::string& name :
       protocol::error_bit_names((1u << kSafetyEdge) | (1u << over_current))) {
    EXPECT_TRUE(has_fault(rig_.state(), name)) << name;
  }
  rig_.run_for(1s);
  EXPECT_EQ(rig_.snapshot().speed, 0.0);
  rig_.chassis().set_error_bit(kSafetyEdge, false);
  rig_.run_for(500ms);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kCriticalError);
  EXPECT_EQ(rig_.snapshot().speed, 0.0);
  rig_.chassis().set_error_bit(over_current, false);
  ASSERT_TRUE(rig_.latched_then_rearmed_by_resume({kCruise, 0, 0}, kCruise));
  EXPECT_TRUE(rig_.state().faults.empty());
}

TEST_F(Faults, ModeSwitchThatNeverCompletesIsRetriedAtABoundedRateAndNeverDrives) {
  ASSERT_TRUE(rig_.connect());
  rig_.chassis().set_mode_switch_stuck(true);
  const Timestamp t0 = rig_.now();
  const std::uint64_t moving_before = rig_.audit().moving_commands();
  rig_.command({0, 0, 0.5}, MotionMode::kSpin);
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().mode_switch.failed; }, 10s));
  EXPECT_TRUE(has_fault(rig_.state(), "motion_mode_switch_failed"));
  rig_.run_for(5s);

  const ControllerConfig& config = rig_.controller().config();
  const auto requests = rig_.wire(protocol::kMotionModeCommandId, t0);
  ASSERT_GE(requests.size(), static_cast<std::size_t>(config.mode_switch_max_attempts));
  for (std::size_t i = 1; i < requests.size(); ++i) {
    const auto gap = requests[i].stamp - requests[i - 1].stamp;
    EXPECT_GE(gap, config.mode_switch_timeout);
    EXPECT_LE(gap, config.mode_switch_timeout + LoopbackFaultRig::kStep);
  }
  EXPECT_EQ(rig_.audit().moving_commands(), moving_before) << "no motion while switching";
  EXPECT_EQ(rig_.snapshot().speed, 0.0);
  EXPECT_TRUE(rig_.snapshot().switching);
  EXPECT_EQ(rig_.state().refusal, MotionRefusal::kModeSwitchFailed);
}

// ---- hostile commands -------------------------------------------------------------------------

TEST_F(Faults, NonFiniteCommandsAreRefusedAndStopTheVehicleOnTheNextFrame) {
  const double kNaN = std::numeric_limits<double>::quiet_NaN();
  const double kInf = std::numeric_limits<double>::infinity();
  for (const BodyTwist bad : {BodyTwist{kNaN, 0, 0}, BodyTwist{0.5, 0, kInf},
                              BodyTwist{0.5, -kInf, 0}, BodyTwist{kNaN, kNaN, kNaN}}) {
    ASSERT_TRUE(rig_.drive({kCruise, 0, 0}, kCruise));
    rig_.stop_commanding();
    const Status st = rig_.controller().set_command(bad, rig_.now());
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, Errc::kNotFinite);
    const Timestamp t_bad = rig_.now();
    rig_.run_for(10ms);
    const auto next = rig_.wire(protocol::kMotionCommandId, t_bad);
    ASSERT_FALSE(next.empty());
    EXPECT_LE(next.front().stamp - t_bad,
              rig_.controller().config().min_command_interval + LoopbackFaultRig::kStep);
    EXPECT_EQ(motion_of(next.front()).linear_speed, 0.0);
    ASSERT_TRUE(rig_.run_until([&] { return rig_.snapshot().speed == 0.0; }, 2s));
    const ControllerState& s = rig_.state();
    EXPECT_TRUE(std::isfinite(s.limited.vx) && std::isfinite(s.limited.vy) &&
                std::isfinite(s.limited.wz));
    // Named while it lasts; the caller's next valid twist ends it.
    EXPECT_EQ(s.refusal, MotionRefusal::kInvalidCommand);
    rig_.command(BodyTwist{});
  }
}

TEST_F(Faults, HugeCommandsSaturateAtTheConfiguredLimitsNeverWrap) {
  ASSERT_TRUE(rig_.connect());
  const KinematicsLimits& limits = rig_.controller().config().limits;
  const int max_mm = static_cast<int>(std::lround(limits.max_linear_speed * 1000));
  for (const double vx : {1e9, -1e9, 1e300, -1e300, std::numeric_limits<double>::max()}) {
    rig_.command({vx, 0, 0});
    rig_.run_for(3s);
    const auto frames = rig_.wire(protocol::kMotionCommandId, rig_.now() - 100ms);
    ASSERT_FALSE(frames.empty());
    const double wire = motion_of(frames.back()).linear_speed;
    EXPECT_EQ(static_cast<int>(std::lround(wire * 1000)), vx > 0 ? max_mm : -max_mm) << vx;
    EXPECT_NEAR(rig_.snapshot().speed, vx > 0 ? limits.max_linear_speed : -limits.max_linear_speed,
                1e-9);
  }
  // A turn far too tight for Ackermann: full lock with the turn's sign, never a wrapped angle.
  rig_.command({0.5, 0, 1e9}, MotionMode::kAckermann);
  rig_.run_for(2s);
  const auto frames = rig_.wire(protocol::kMotionCommandId, rig_.now() - 100ms);
  ASSERT_FALSE(frames.empty());
  const MotionCommand c = motion_of(frames.back());
  EXPECT_NEAR(std::abs(c.steering_angle), limits.max_ackermann_steering, 1e-3);
  EXPECT_LT(c.steering_angle, 0.0) << "left turn = negative on the wire (manual's sign)";
  EXPECT_GT(c.linear_speed, 0.0);
}

TEST_F(Faults, CommandFloodAt10kHzIsRateLimitedOnTheWireAndTheLastCommandWins) {
  ASSERT_TRUE(rig_.drive({0.2, 0, 0}, 0.2));
  rig_.stop_commanding();
  // 10 commands per 1 ms step for one second: vx ramps 0.2 -> 1.0 m/s in 10000 distinct values.
  int n = 0;
  double last = 0.0;
  std::uint64_t refused = 0;
  rig_.each_step = [&](Timestamp t) {  // every 100 us between the previous tick and this one
    for (int i = 0; i < 10; ++i, ++n) {
      last = 0.2 + 0.8 * (n + 1) / 10000.0;
      const Timestamp at = t - LoopbackFaultRig::kStep + (i + 1) * 100us;
      if (!rig_.controller().set_command(BodyTwist{last, 0, 0}, at)) ++refused;
    }
  };
  const Timestamp t0 = rig_.now();
  const BusStatistics chassis_before = rig_.chassis_bus().status().stats;
  rig_.run_for(1s);
  rig_.each_step = nullptr;
  rig_.command({last, 0, 0});
  rig_.run_for(20ms);

  EXPECT_EQ(n, 10000);
  EXPECT_EQ(refused, 0u);
  const ControllerConfig& config = rig_.controller().config();
  const auto frames = rig_.wire(protocol::kMotionCommandId, t0, t0 + 1s);
  // At most one 0x111 per min_command_interval, at least the keep-alive rate.
  EXPECT_LE(frames.size(), static_cast<std::size_t>(1s / config.min_command_interval) + 1);
  EXPECT_GE(frames.size(), static_cast<std::size_t>(1s / config.keep_alive_period) - 1);
  EXPECT_EQ(rig_.chassis_bus().status().stats.rx_dropped, chassis_before.rx_dropped);
  // The flood's last value is what the chassis was told, and it gets there.
  const auto latest = rig_.wire(protocol::kMotionCommandId, t0);
  ASSERT_FALSE(latest.empty());
  EXPECT_NEAR(motion_of(latest.back()).linear_speed, 1.0, 0.0005);
  ASSERT_TRUE(rig_.run_until([&] { return std::abs(rig_.snapshot().speed - 1.0) < 1e-9; }, 3s));
}

// ---- the driver dies --------------------------------------------------------------------------

TEST_F(Faults, KilledDriverChassisStopsWithinFiveHundredMillisecondsOfTheLastCommand) {
  ASSERT_TRUE(rig_.drive({1.0, 0, 0}, 1.0));
  rig_.kill_driver();  // SIGKILL: no shutdown, no stop frame
  rig_.run_for(2s);

  const auto commands = rig_.wire(protocol::kMotionCommandId, Timestamp{0});
  ASSERT_FALSE(commands.empty());
  const Timestamp t_last = commands.back().stamp;
  const auto watchdog = std::chrono::milliseconds(protocol::kChassisCommandTimeoutMs);
  const auto period =
      std::chrono::milliseconds(protocol::frame_period_ms(protocol::kSystemStatusId));

  // Until the watchdog expires the chassis keeps the last command (manual 3.2)...
  const auto feedback = rig_.wire(protocol::kMotionFeedbackId, t_last);
  ASSERT_FALSE(feedback.empty());
  Timestamp first_slower{0}, first_stopped{0};
  for (const CanFrame& f : feedback) {
    const double v = speed_of_0x221(f);
    if (f.stamp < t_last + watchdog) {
      EXPECT_EQ(v, 1.0) << "slower before the watchdog, at +" << (f.stamp - t_last).count()
                        << " ns";
    }
    if (first_slower.count() == 0 && v < 1.0) first_slower = f.stamp;
    if (first_stopped.count() == 0 && v == 0.0) first_stopped = f.stamp;
  }
  // ...then it brakes: the first slower 0x221 within one feedback period of the 500 ms, and at
  // rest after the braking time (1 m/s at the model's 2 m/s^2).
  ASSERT_NE(first_slower.count(), 0);
  ASSERT_NE(first_stopped.count(), 0);
  EXPECT_GE(first_slower - t_last, watchdog);
  EXPECT_LE(first_slower - t_last, watchdog + period + LoopbackFaultRig::kStep);
  EXPECT_LE(first_stopped - t_last, watchdog + 500ms + period + LoopbackFaultRig::kStep);
  // The chassis reports why: host communication lost (0x211 byte 6 bit 1).
  const auto statuses = rig_.wire(protocol::kSystemStatusId, t_last + watchdog + period);
  ASSERT_FALSE(statuses.empty());
  const auto status = decode(statuses.front());
  ASSERT_TRUE(status.ok());
  EXPECT_TRUE(std::get<SystemStatus>(*status).error_bits & (1u << protocol::error_bit_index(6, 1)));
}

}  // namespace
}  // namespace ranger::faults
