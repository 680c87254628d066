// End-to-end: the driver (ChassisController + Odometry, as the ROS node uses them) against the
// virtual chassis (VirtualChassis), talking the real protocol over a real Bus.
//
// One typed suite, two rigs:
//  * LoopbackRig (test_e2e_loopback.cpp, label `unit`): in-process LoopbackNetwork, a ManualClock,
//    chassis and driver stepped in lock-step every millisecond. Deterministic: exact timing
//    assertions are allowed there (rig.deterministic()).
//  * VcanRig (test_e2e_vcan.cpp, label `vcan`): two SocketCAN sockets on vcan0, the chassis on its
//    own thread (VirtualChassisRunner) and the driver loop on the test's thread, both on the real
//    clock. Only outcomes are asserted, with generous time limits (timing_slack()).
//
// The odometry cases print one line per mode, "[odometry] bus=... mode=... distance=... m
// position_error=... % yaw_error=... deg/turn", the figures for docs/PERFORMANCE.md.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::e2e {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;

// The driver's odometry as the node configures it, except max_step: under qemu TCG on a loaded
// host the whole VM (and with it the chassis's sending thread) stalls now and then for up to half
// a second; the default max_step (500 ms) would then re-anchor instead of integrating the gap.
// The chassis moves steadily through such a gap, so integrating it is right here.
inline OdometryConfig odometry_config() {
  OdometryConfig c;
  c.max_step = std::chrono::seconds(2);
  return c;
}

// The driver side and the chassis, whatever connects them.
class Rig {
 public:
  virtual ~Rig() = default;

  // Runs the driver loop (and, in lock-step rigs, the chassis) until `done()` holds or `timeout`
  // of the rig's time passed (multiplied by timing_slack()); returns done().
  virtual bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) = 0;
  void run_for(std::chrono::nanoseconds d) {
    const Timestamp end = now() + d;
    run_until([&] { return now() >= end; }, d + 1s);
  }
  // Calls `f` with the chassis, safely with respect to the chassis's own thread if any.
  virtual void with_chassis(const std::function<void(sim::VirtualChassis&)>& f) = 0;
  virtual Timestamp now() const = 0;
  virtual bool deterministic() const = 0;
  virtual double timing_slack() const = 0;
  virtual std::string name() const = 0;

  sim::ChassisSnapshot chassis() {
    sim::ChassisSnapshot s;
    with_chassis([&](sim::VirtualChassis& c) { s = c.snapshot(); });
    return s;
  }
  ChassisController& controller() { return *controller_; }
  const ControllerState& state() const { return controller_->state(); }
  const Odometry& odometry() const { return odometry_; }

  // The caller wants `twist` (re-issued every 100 ms, like a teleop at 10 Hz) from now on.
  void command(const BodyTwist& twist, std::optional<MotionMode> mode = std::nullopt) {
    request_ = MotionRequest{twist, mode};
    next_request_ = Timestamp{0};
  }
  // The caller stops calling set_command (the controller's own cmd_timeout then applies).
  void stop_commanding() { request_.reset(); }
  // The driver process dies (true): no frames are read, nothing is ticked, nothing is sent.
  void kill_driver(bool dead) { driver_dead_ = dead; }

 protected:
  void attach_driver(Bus& bus, ControllerConfig config = {}) {
    driver_bus_ = &bus;
    controller_ = std::make_unique<ChassisController>(bus, config);
  }
  // Derived rigs call this first in their destructor: the controller sends its stop on
  // destruction, so it must go while their bus still exists.
  void release_driver() { controller_.reset(); }
  // One driver iteration at `now`: read frames (waiting up to `wait` for the first), feed the
  // controller and the odometry, refresh the caller's command, tick.
  void driver_step(Timestamp now, std::chrono::nanoseconds wait) {
    if (driver_dead_) return;
    for (auto frame = driver_bus_->receive(wait); frame; frame = driver_bus_->receive(0ns)) {
      if (frame->id == protocol::kWheelSpeedsId) {
        if (last_wheel_stamp_.count() != 0) {
          max_wheel_gap_ = std::max(max_wheel_gap_, frame->stamp - last_wheel_stamp_);
        }
        last_wheel_stamp_ = frame->stamp;
      }
      controller_->on_frame(*frame, now);
      odometry_.on_frame(*frame);
    }
    if (request_ && now >= next_request_) {
      EXPECT_TRUE(controller_->set_command(*request_, now).ok());
      next_request_ = now + 100ms;
    }
    controller_->tick(now);
  }
  bool driver_dead() const { return driver_dead_; }

 public:
  // Longest interval between two consecutive 0x281 frames as the driver received them.
  std::chrono::nanoseconds max_wheel_gap() const { return max_wheel_gap_; }

 private:
  Timestamp last_wheel_stamp_{0};
  std::chrono::nanoseconds max_wheel_gap_{0};

 private:
  Bus* driver_bus_ = nullptr;
  std::unique_ptr<ChassisController> controller_;
  Odometry odometry_{odometry_config()};
  std::optional<MotionRequest> request_;
  Timestamp next_request_{0};
  bool driver_dead_ = false;
};

template <typename RigT>
class E2e : public ::testing::Test {
 protected:
  RigT rig_;

  std::chrono::nanoseconds slack(std::chrono::nanoseconds d) const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(d * rig_.timing_slack());
  }
  bool eventually(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    return rig_.run_until(done, timeout);
  }
  void connect() {
    ASSERT_TRUE(eventually(
        [&] {
          return rig_.state().control_mode == ControlMode::kCan && rig_.state().motion_mode &&
                 rig_.state().refusal == MotionRefusal::kNone;
        },
        3s))
        << "controller refusal: " << to_string(rig_.state().refusal);
    EXPECT_EQ(rig_.chassis().control_mode, ControlMode::kCan);
  }
  bool chassis_at_rest() {
    return rig_.chassis().speed == 0.0 && rig_.state().link == LinkState::kConnected;
  }
  // Commands zero and waits until the chassis has stopped and the last feedback is integrated.
  void stop_and_settle() {
    rig_.command(BodyTwist{});
    ASSERT_TRUE(eventually([&] { return rig_.chassis().speed == 0.0; }, 5s));
    rig_.run_for(300ms);
  }
  // After an involuntary stop whose cause has cleared: the driver holds the chassis at rest
  // (kRearmRequired) although the caller still asks for `twist`, and a zero twist followed by
  // `twist` does not restart it either (a zero twist is no re-arm); resume() re-arms, and then
  // `twist` drives again (speed above `min_speed`).
  void expect_latched_then_rearm_by_resume(const BodyTwist& twist, double min_speed) {
    rig_.command(twist);
    ASSERT_TRUE(
        eventually([&] { return rig_.state().refusal == MotionRefusal::kRearmRequired; }, 3s))
        << "refusal " << to_string(rig_.state().refusal);
    const auto hold = [&](std::chrono::nanoseconds d) {
      const Timestamp until = rig_.now() + d;
      while (rig_.now() < until) {
        rig_.run_for(100ms);
        ASSERT_EQ(rig_.chassis().speed, 0.0) << "restarted without a re-arm";
        ASSERT_EQ(rig_.state().refusal, MotionRefusal::kRearmRequired);
      }
    };
    hold(1s);
    rig_.command(BodyTwist{});  // a zero twist: no re-arm
    hold(300ms);
    rig_.command(twist);
    hold(500ms);
    ASSERT_TRUE(rig_.controller().resume(rig_.now()).ok());
    ASSERT_TRUE(
        eventually([&] { return rig_.state().refusal != MotionRefusal::kRearmRequired; }, 2s));
    ASSERT_TRUE(eventually([&] { return std::fabs(rig_.chassis().speed) > min_speed; }, 5s));
  }

  // Drives `twist` for `duration` once the chassis is in `mode` and up to speed.
  void drive(const BodyTwist& twist, MotionMode mode, std::chrono::nanoseconds duration) {
    rig_.command(twist);
    ASSERT_TRUE(eventually(
        [&] {
          const auto s = rig_.chassis();
          return s.motion_mode == mode && !s.switching && s.speed != 0.0;
        },
        8s))
        << "chassis in " << protocol::to_string(rig_.chassis().motion_mode)
        << ", controller refusal " << to_string(rig_.state().refusal);
    rig_.run_for(duration);
  }

  // Compares the driver's odometry with the chassis's ground truth, prints the figures and checks
  // the budget: <= 1 % of the distance travelled, <= 1 deg of heading per full turn.
  // `enforce` = false only prints: for scenarios that are mostly braking and accelerating over a
  // short distance, on a real clock, where a VM's stamp jitter (tens of ms) dominates a figure
  // that the per-mode cases measure properly.
  void expect_odometry_within_budget(const std::string& mode, bool enforce = true) {
    const auto truth = rig_.chassis();
    const Pose2D est = rig_.odometry().state().pose;
    const double position_error = std::hypot(est.x - truth.pose.x, est.y - truth.pose.y);
    const double yaw_error =
        std::abs(std::remainder(est.yaw - truth.pose.yaw, 2 * M_PI)) * 180.0 / M_PI;
    const double turns = truth.yaw_travelled / (2 * M_PI);
    const double distance = truth.distance_travelled;
    const double pct = distance > 0 ? 100.0 * position_error / distance : 0.0;
    const OdometryState& odo = rig_.odometry().state();
    std::printf(
        "[odometry] bus=%s mode=%s distance=%.3f m turns=%.3f position_error=%.4f m (%.3f %% of "
        "distance) yaw_error=%.4f deg (%.4f deg/turn) steps=%llu skipped=%llu fallback=%llu "
        "max_0x281_gap=%.1f ms\n",
        rig_.name().c_str(), mode.c_str(), distance, turns, position_error, pct, yaw_error,
        turns > 0 ? yaw_error / turns : 0.0, static_cast<unsigned long long>(odo.steps),
        static_cast<unsigned long long>(odo.skipped_steps),
        static_cast<unsigned long long>(odo.fallback_steps),
        std::chrono::duration<double, std::milli>(rig_.max_wheel_gap()).count());
    std::fflush(stdout);
    ::testing::Test::RecordProperty("odometry_position_error_pct", std::to_string(pct));
    ::testing::Test::RecordProperty("odometry_yaw_error_deg", std::to_string(yaw_error));
    EXPECT_GT(distance + truth.yaw_travelled, 0.5) << "the scenario must actually move";
    if (!enforce) return;
    EXPECT_LE(position_error, 0.01 * std::max(distance, 0.0) + 1e-3);
    EXPECT_LE(yaw_error, 1.0 * std::max(1.0, turns));
  }
};

TYPED_TEST_SUITE_P(E2e);

TYPED_TEST_P(E2e, HandshakeBringsTheChassisIntoCanMode) {
  auto& rig = this->rig_;
  EXPECT_EQ(rig.chassis().control_mode, ControlMode::kStandby) << "boots in standby";
  this->connect();
  EXPECT_EQ(rig.state().motion_mode, MotionMode::kAckermann);
  EXPECT_GE(rig.state().counters.control_mode_requests, 1u);
  EXPECT_TRUE(rig.state().faults.empty());
}

TYPED_TEST_P(E2e, AckermannOdometryMatchesGroundTruth) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.8, 0.0, 0.3}, MotionMode::kAckermann, 15s);    // a left circle, r = 2.7 m
  this->drive({-0.5, 0.0, 0.25}, MotionMode::kAckermann, 10s);  // reversing: body turns right
  this->stop_and_settle();
  EXPECT_EQ(rig.chassis().motion_mode, MotionMode::kAckermann);
  this->expect_odometry_within_budget("ackermann");
}

TYPED_TEST_P(E2e, ObliqueOdometryMatchesGroundTruth) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.3, 0.4, 0.0}, MotionMode::kOblique, 12s);
  this->drive({0.5, -0.2, 0.0}, MotionMode::kOblique, 8s);
  this->drive({-0.2, 0.4, 0.0}, MotionMode::kOblique, 6s);
  this->stop_and_settle();
  EXPECT_EQ(rig.chassis().motion_mode, MotionMode::kOblique);
  EXPECT_NEAR(rig.chassis().pose.yaw, 0.0, 1e-9) << "crab motion never rotates";
  this->expect_odometry_within_budget("oblique");
}

TYPED_TEST_P(E2e, SpinOdometryMatchesGroundTruth) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.0, 0.0, 0.9}, MotionMode::kSpin, 14s);  // two full turns counter-clockwise
  this->drive({0.0, 0.0, -0.6}, MotionMode::kSpin, 5s);
  this->stop_and_settle();
  EXPECT_EQ(rig.chassis().motion_mode, MotionMode::kSpin);
  EXPECT_GT(rig.chassis().yaw_travelled, 4 * M_PI);
  this->expect_odometry_within_budget("spin");
}

TYPED_TEST_P(E2e, SwitchesBetweenEveryPairOfModes) {
  auto& rig = this->rig_;
  this->connect();
  const MotionMode sequence[] = {MotionMode::kOblique,   MotionMode::kSpin,
                                 MotionMode::kAckermann, MotionMode::kSpin,
                                 MotionMode::kOblique,   MotionMode::kAckermann};
  for (MotionMode m : sequence) {
    SCOPED_TRACE(protocol::to_string(m));
    const BodyTwist twist = m == MotionMode::kSpin      ? BodyTwist{0.0, 0.0, 0.5}
                            : m == MotionMode::kOblique ? BodyTwist{0.2, 0.2, 0.0}
                                                        : BodyTwist{0.4, 0.0, 0.1};
    rig.command(twist, m);
    ASSERT_TRUE(this->eventually(
        [&] {
          const auto s = rig.chassis();
          return s.motion_mode == m && !s.switching && s.speed != 0.0;
        },
        10s));
    EXPECT_EQ(rig.state().motion_mode, m);
    EXPECT_FALSE(rig.state().mode_switch.failed);
    rig.run_for(500ms);
  }
  this->stop_and_settle();
  EXPECT_EQ(rig.state().counters.mode_switch_timeouts, 0u);
  this->expect_odometry_within_budget("mixed", rig.deterministic());
}

TYPED_TEST_P(E2e, ChassisStopsByItselfWhenTheDriverDies) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({1.0, 0.0, 0.0}, MotionMode::kAckermann, 2s);
  ASSERT_NEAR(rig.chassis().speed, 1.0, 1e-9);
  rig.kill_driver(true);
  if (rig.deterministic()) {
    rig.run_for(450ms);  // the last 0x111 left at most ~20 ms before the driver died
    EXPECT_NEAR(rig.chassis().speed, 1.0, 1e-9) << "keeps the last command for 500 ms";
    EXPECT_FALSE(rig.chassis().host_link_lost);
    rig.run_for(100ms);
    EXPECT_TRUE(rig.chassis().host_link_lost);
  }
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 3s));
  EXPECT_TRUE(rig.chassis().host_link_lost);
  EXPECT_TRUE(rig.chassis().error_bits & (1u << protocol::error_bit_index(6, 1)));

  rig.kill_driver(false);  // the driver comes back: the link is restored and it drives again
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed > 0.5; }, 5s));
  EXPECT_FALSE(rig.chassis().host_link_lost);
}

TYPED_TEST_P(E2e, CallerSilenceMakesTheControllerStopTheChassis) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.8, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.stop_commanding();  // the caller (e.g. teleop) goes quiet; the controller keeps the link
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 5s));
  EXPECT_TRUE(rig.state().cmd_timed_out);
  EXPECT_FALSE(rig.chassis().host_link_lost) << "keep-alive continues with zero commands";
}

TYPED_TEST_P(E2e, RemoteTakeoverAndHandBack) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.6, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.remote_takeover(); });
  ASSERT_TRUE(this->eventually([&] { return rig.state().refusal == MotionRefusal::kRemote; }, 2s));
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 3s));
  std::uint64_t ignored_before = 0;
  rig.with_chassis([&](sim::VirtualChassis& c) { ignored_before = c.counters().frames_ignored; });
  rig.run_for(1s);
  std::uint64_t ignored_after = 0;
  rig.with_chassis([&](sim::VirtualChassis& c) { ignored_after = c.counters().frames_ignored; });
  EXPECT_EQ(ignored_after, ignored_before) << "the driver sends nothing while the remote rules";
  EXPECT_EQ(rig.state().control_mode, ControlMode::kRemote);

  // SWB back up: the chassis is in CAN mode again, but the stale twist does not restart it.
  rig.with_chassis([](sim::VirtualChassis& c) { c.remote_hand_back(); });
  this->expect_latched_then_rearm_by_resume({0.6, 0.0, 0.0}, 0.5);

  // The remote takes over again and is switched off: standby. Remote control is final: the
  // driver does not ask for CAN mode by itself; resume() does (and re-arms).
  rig.with_chassis([](sim::VirtualChassis& c) { c.remote_takeover(); });
  ASSERT_TRUE(this->eventually([&] { return rig.state().refusal == MotionRefusal::kRemote; }, 2s));
  rig.with_chassis([](sim::VirtualChassis& c) { c.remote_hand_back(/*to_standby=*/true); });
  ASSERT_TRUE(
      this->eventually([&] { return rig.chassis().control_mode == ControlMode::kStandby; }, 1s));
  rig.run_for(2s);
  EXPECT_EQ(rig.chassis().control_mode, ControlMode::kStandby) << "reclaimed without resume";
  EXPECT_EQ(rig.chassis().speed, 0.0);
  EXPECT_TRUE(rig.state().reclaim_blocked);
  ASSERT_TRUE(rig.controller().resume(rig.now()).ok());
  ASSERT_TRUE(this->eventually(
      [&] { return rig.chassis().control_mode == ControlMode::kCan && rig.chassis().speed > 0.5; },
      5s));
}

TYPED_TEST_P(E2e, EmergencyStopAndRelease) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({1.0, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_emergency_stop(true); });
  ASSERT_TRUE(this->eventually([&] { return rig.state().refusal == MotionRefusal::kEstop; }, 2s));
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 2s));
  EXPECT_TRUE(rig.state().estop());
  // The e-stop is released: resetting it must not restart the chassis (ISO 13850).
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_emergency_stop(false); });
  this->expect_latched_then_rearm_by_resume({1.0, 0.0, 0.0}, 0.5);
  EXPECT_FALSE(rig.state().estop());
}

TYPED_TEST_P(E2e, CriticalErrorIsReportedAndClearedThroughTheController) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.5, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) {
    c.set_error_bit(protocol::error_bit_index(6, 7), true);  // over-current protection
  });
  ASSERT_TRUE(
      this->eventually([&] { return rig.state().refusal == MotionRefusal::kCriticalError; }, 2s));
  const auto& faults = rig.state().faults;
  EXPECT_NE(std::find(faults.begin(), faults.end(), "over_current"), faults.end());
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 2s));

  ASSERT_TRUE(rig.controller().clear_errors(0x00, rig.now()).ok());  // not critical enough: stays
  rig.run_for(200ms);
  EXPECT_NE(rig.chassis().error_bits, 0u);
  ASSERT_TRUE(rig.controller().clear_errors(0x0F, rig.now()).ok());
  this->expect_latched_then_rearm_by_resume({0.5, 0.0, 0.0}, 0.4);
  EXPECT_EQ(rig.chassis().error_bits, 0u);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
}

TYPED_TEST_P(E2e, LowBatteryRefusesMotionUntilChargedAndCleared) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.5, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_battery_soc(8.0); });
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 2s));
  ASSERT_TRUE(this->eventually(
      [&] {
        return rig.state().refusal == MotionRefusal::kLowBattery ||
               rig.state().refusal == MotionRefusal::kCriticalError;
      },
      3s));
  EXPECT_TRUE(rig.state().low_battery() || rig.state().critical_error());
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_battery_soc(80.0); });
  ASSERT_TRUE(rig.controller().clear_errors(0x09, rig.now()).ok());
  this->expect_latched_then_rearm_by_resume({0.5, 0.0, 0.0}, 0.4);
  EXPECT_EQ(rig.chassis().error_bits, 0u);
}

TYPED_TEST_P(E2e, SilentChassisIsDetectedAndRecovered) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.5, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.silence_for(2s); });
  ASSERT_TRUE(
      this->eventually([&] { return rig.state().refusal == MotionRefusal::kLinkLost; }, 2s));
  EXPECT_EQ(rig.state().link, LinkState::kStale);
  ASSERT_TRUE(this->eventually([&] { return rig.state().link == LinkState::kConnected; }, 6s));
  this->expect_latched_then_rearm_by_resume({0.5, 0.0, 0.0}, 0.4);
  EXPECT_GE(rig.state().counters.link_losses, 1u);
}

TYPED_TEST_P(E2e, GarbageFramesDoNotDisturbTheDriver) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({0.5, 0.0, 0.2}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.inject_garbage(300); });
  rig.run_for(2s);
  EXPECT_GT(rig.state().counters.decode_errors, 0u);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_GT(rig.chassis().speed, 0.4);
  this->stop_and_settle();
  this->expect_odometry_within_budget("ackermann+garbage", rig.deterministic());
}

TYPED_TEST_P(E2e, ModeSwitchThatNeverCompletesIsReported) {
  auto& rig = this->rig_;
  this->connect();
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_mode_switch_stuck(true); });
  rig.command({0.0, 0.0, 0.5}, MotionMode::kSpin);
  ASSERT_TRUE(this->eventually([&] { return rig.state().mode_switch.failed; }, 15s));
  const auto& faults = rig.state().faults;
  EXPECT_NE(std::find(faults.begin(), faults.end(), "motion_mode_switch_failed"), faults.end());
  EXPECT_EQ(rig.chassis().speed, 0.0);
  EXPECT_TRUE(rig.chassis().switching);
  // Released: the next retry completes the switch, and motion waits for the re-arm.
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_mode_switch_stuck(false); });
  ASSERT_TRUE(
      this->eventually([&] { return rig.state().refusal == MotionRefusal::kRearmRequired; }, 10s))
      << "refusal " << to_string(rig.state().refusal);
  EXPECT_EQ(rig.chassis().speed, 0.0);
  ASSERT_TRUE(rig.controller().resume(rig.now()).ok());
  rig.command({0.0, 0.0, 0.5}, MotionMode::kSpin);
  ASSERT_TRUE(this->eventually(
      [&] { return rig.chassis().motion_mode == MotionMode::kSpin && rig.chassis().speed > 0.2; },
      10s));
}

TYPED_TEST_P(E2e, UltrasonicSettingIsConfirmedAndAvoidanceStops) {
  auto& rig = this->rig_;
  this->connect();
  ASSERT_TRUE(rig.controller().set_ultrasonic(true, rig.now()).ok());
  ASSERT_TRUE(this->eventually(
      [&] { return rig.state().ultrasonic_enabled == std::optional<bool>(true); }, 2s));
  EXPECT_TRUE(rig.chassis().ultrasonic_enabled);
  this->drive({0.5, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_ultrasonic(1, 150); });
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 2s));
  EXPECT_TRUE(rig.state().error_bits & (1u << protocol::error_bit_index(7, 1)));
  rig.with_chassis([](sim::VirtualChassis& c) { c.set_ultrasonic(1, 2000); });
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed > 0.4; }, 5s));
}

TYPED_TEST_P(E2e, ShutdownStopsTheChassis) {
  auto& rig = this->rig_;
  this->connect();
  this->drive({1.0, 0.0, 0.0}, MotionMode::kAckermann, 1s);
  rig.controller().shutdown(rig.now());
  rig.stop_commanding();
  ASSERT_TRUE(this->eventually([&] { return rig.chassis().speed == 0.0; }, 3s));
  EXPECT_TRUE(rig.state().shut_down);
}

REGISTER_TYPED_TEST_SUITE_P(E2e, HandshakeBringsTheChassisIntoCanMode,
                            AckermannOdometryMatchesGroundTruth, ObliqueOdometryMatchesGroundTruth,
                            SpinOdometryMatchesGroundTruth, SwitchesBetweenEveryPairOfModes,
                            ChassisStopsByItselfWhenTheDriverDies,
                            CallerSilenceMakesTheControllerStopTheChassis,
                            RemoteTakeoverAndHandBack, EmergencyStopAndRelease,
                            CriticalErrorIsReportedAndClearedThroughTheController,
                            LowBatteryRefusesMotionUntilChargedAndCleared,
                            SilentChassisIsDetectedAndRecovered, GarbageFramesDoNotDisturbTheDriver,
                            ModeSwitchThatNeverCompletesIsReported,
                            UltrasonicSettingIsConfirmedAndAvoidanceStops, ShutdownStopsTheChassis);

}  // namespace ranger::e2e
