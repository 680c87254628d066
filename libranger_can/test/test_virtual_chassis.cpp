// The virtual chassis against the protocol: driven by injected time over the test-support FakeBus,
// so every period, timeout and duration is checked exactly and no test sleeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

#include "ranger_can/sim/chassis_model.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/wire/vehicle_spec.hpp"
#include "support/fake_bus.hpp"

namespace ranger::sim {
namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;

constexpr double kDeg = M_PI / 180.0;

CanFrame encoded(const Message& m) {
  auto f = encode(m);
  EXPECT_TRUE(f.ok()) << (f ? "" : f.error().message);
  return f ? *f : CanFrame{};
}

// A chassis, its bus and a clock in milliseconds, with helpers to talk to it like a host.
struct Harness {
  explicit Harness(VirtualChassisConfig config = {}) : chassis(bus, config, Timestamp{0}) {
    chassis.step(Timestamp{0});
  }

  Timestamp t{0};
  test::FakeBus bus;
  VirtualChassis chassis;

  void send(const Message& m) { chassis.on_frame(encoded(m), t); }
  void advance(std::chrono::nanoseconds d, std::chrono::nanoseconds granularity = 1ms) {
    const Timestamp end = t + d;
    while (t < end) {
      t = std::min(end, t + granularity);
      chassis.step(t);
    }
  }
  // Sends `cmd` every 20 ms (like a host's keep-alive) for `d`.
  void drive(const MotionCommand& cmd, std::chrono::nanoseconds d) {
    const Timestamp end = t + d;
    while (t < end) {
      send(cmd);
      advance(std::min<std::chrono::nanoseconds>(20ms, end - t));
    }
  }
  void handshake() {
    send(ControlModeCommand{ControlMode::kCan});
    advance(20ms);
  }
  void switch_mode(MotionMode m) {
    send(MotionModeCommand{m});
    advance(1500ms);
    ASSERT_EQ(chassis.snapshot().motion_mode, m);
    ASSERT_FALSE(chassis.snapshot().switching);
  }

  template <typename T>
  std::optional<T> last(std::uint32_t id) const {
    for (auto it = bus.sent.rbegin(); it != bus.sent.rend(); ++it) {
      if (it->id != id) continue;
      auto m = decode(*it);
      if (!m) return std::nullopt;
      if (auto* v = std::get_if<T>(&*m)) return *v;
    }
    return std::nullopt;
  }
  SystemStatus status() const { return *last<SystemStatus>(protocol::kSystemStatusId); }
  MotionModeFeedback mode_feedback() const {
    return *last<MotionModeFeedback>(protocol::kMotionModeFeedbackId);
  }
  std::size_t count(std::uint32_t id) const { return bus.count(id); }
};

MotionCommand ackermann(double v, double rep103_steering = 0.0) {
  MotionCommand c;
  c.linear_speed = v;
  c.steering_angle = interpretation::manual_from_rep103_command_steering(rep103_steering);
  return c;
}
MotionCommand spin(double wheel_speed) {
  MotionCommand c;
  c.spin_speed = wheel_speed;
  return c;
}

// ---- boot and control mode --------------------------------------------------------------------

TEST(VirtualChassis, BootsInStandbyAckermannAndReportsIt) {
  Harness h;
  EXPECT_EQ(h.status().control_mode, ControlMode::kStandby);
  EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kNormal);
  EXPECT_EQ(h.status().error_bits, 0u);
  // The manual's LiFePO4 pack at the default 90 % SOC: inside its normal range, 46-50 V.
  EXPECT_GE(h.status().battery_voltage, vehicle_spec::kBatteryNormalMinVoltage);
  EXPECT_LE(h.status().battery_voltage, vehicle_spec::kBatteryNormalMaxVoltage);
  EXPECT_EQ(h.mode_feedback().mode, MotionMode::kAckermann);
  EXPECT_FALSE(h.mode_feedback().switching);
}

TEST(VirtualChassis, BootsInRemoteModeWhenConfigured) {
  VirtualChassisConfig c;
  c.boot_in_remote_mode = true;
  Harness h(c);
  EXPECT_EQ(h.status().control_mode, ControlMode::kRemote);
  h.send(ControlModeCommand{ControlMode::kCan});  // the remote has priority
  h.advance(40ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kRemote);
}

TEST(VirtualChassis, IgnoresMotionAndOtherCommandsInStandby) {
  Harness h;
  h.drive(ackermann(0.5), 1s);
  h.send(MotionModeCommand{MotionMode::kSpin});
  h.send(UltrasonicSettingCommand{true});
  h.advance(1s);
  const auto s = h.chassis.snapshot();
  EXPECT_EQ(s.pose.x, 0.0);
  EXPECT_EQ(s.motion_mode, MotionMode::kAckermann);
  EXPECT_FALSE(s.switching);
  EXPECT_EQ(h.count(protocol::kUltrasonicSettingFeedbackId), 0u);
  EXPECT_GT(h.chassis.counters().frames_ignored, 40u);
  EXPECT_EQ(h.status().error_bits, 0u);  // no watchdog outside CAN mode
}

TEST(VirtualChassis, HandshakeSwitchesToCanModeAndBackToStandby) {
  Harness h;
  h.handshake();
  EXPECT_EQ(h.status().control_mode, ControlMode::kCan);
  h.drive(ackermann(0.5), 1s);
  EXPECT_GT(h.chassis.snapshot().speed, 0.4);
  h.send(ControlModeCommand{ControlMode::kStandby});
  h.advance(40ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kStandby);
  h.drive(ackermann(0.5), 1s);  // ignored now: the chassis brakes to rest
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
}

TEST(VirtualChassis, RemoteTakeoverBlocksCanAndHandBackRestoresIt) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.0), 1500ms);
  h.chassis.remote_takeover();
  h.advance(20ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kRemote);
  h.drive(ackermann(1.0), 1s);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0) << "the remote's neutral sticks stop the chassis";
  h.send(ControlModeCommand{ControlMode::kStandby});  // blocked as well
  h.advance(20ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kRemote);

  h.chassis.remote_hand_back();
  h.advance(20ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kCan);
  h.drive(ackermann(0.5), 1s);
  EXPECT_GT(h.chassis.snapshot().speed, 0.4);

  h.chassis.remote_takeover();
  h.chassis.remote_hand_back(/*to_standby=*/true);
  h.advance(20ms);
  EXPECT_EQ(h.status().control_mode, ControlMode::kStandby);
}

// ---- the 500 ms command watchdog --------------------------------------------------------------

TEST(VirtualChassis, StopsByItself500msAfterTheLastMotionCommand) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.0), 2s);
  ASSERT_NEAR(h.chassis.snapshot().speed, 1.0, 1e-9);
  const std::uint32_t lost = 1u << protocol::error_bit_index(6, 1);

  h.advance(479ms);  // last 0x111 was at t - 20 ms: 500 ms after it is t + 480 ms
  EXPECT_NEAR(h.chassis.snapshot().speed, 1.0, 1e-9);
  EXPECT_FALSE(h.chassis.snapshot().host_link_lost);
  EXPECT_EQ(h.status().error_bits & lost, 0u);
  h.advance(1ms);
  EXPECT_TRUE(h.chassis.snapshot().host_link_lost);
  h.advance(1ms);
  EXPECT_LT(h.chassis.snapshot().speed, 1.0);
  h.advance(20ms);
  EXPECT_EQ(h.status().error_bits & lost, lost);
  EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kAbnormal);
  h.advance(1s);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);

  // Commands resume: the bit clears and the chassis obeys again.
  h.drive(ackermann(0.3), 1s);
  EXPECT_EQ(h.status().error_bits & lost, 0u);
  EXPECT_NEAR(h.chassis.snapshot().speed, 0.3, 1e-9);
}

TEST(VirtualChassis, HostLinkLostClearsWith0x441AllNonCritical) {
  Harness h;
  h.handshake();
  h.drive(ackermann(0.2), 100ms);
  h.advance(600ms);
  ASSERT_TRUE(h.chassis.snapshot().host_link_lost);
  h.send(ErrorClearCommand{0x00});
  h.advance(2s);  // watchdog disarmed until the next 0x111: the bit stays clear
  EXPECT_EQ(h.status().error_bits, 0u);
  EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kNormal);
}

TEST(VirtualChassis, WatchdogArmsOnlyWithTheFirstMotionCommand) {
  Harness h;
  h.handshake();
  h.advance(3s);
  EXPECT_EQ(h.status().error_bits, 0u);
}

// ---- motion modes -----------------------------------------------------------------------------

TEST(VirtualChassis, ModeSwitchTakesTheConfiguredTimeWithSwitchingReported) {
  VirtualChassisConfig c;
  c.mode_switch_duration = 700ms;
  Harness h(c);
  h.handshake();
  h.send(MotionModeCommand{MotionMode::kSpin});
  h.advance(20ms);
  EXPECT_TRUE(h.mode_feedback().switching);
  EXPECT_EQ(h.mode_feedback().mode, MotionMode::kAckermann) << "reports the mode being left";
  h.drive(spin(0.5), 660ms);  // speed commands are ignored while switching
  EXPECT_TRUE(h.chassis.snapshot().switching);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
  EXPECT_TRUE(h.mode_feedback().switching);
  h.advance(40ms);  // 720 ms after the request
  EXPECT_FALSE(h.mode_feedback().switching);
  EXPECT_EQ(h.mode_feedback().mode, MotionMode::kSpin);
  h.drive(spin(0.5), 1s);
  EXPECT_NEAR(h.chassis.snapshot().speed, 0.5, 1e-9);
  EXPECT_GT(h.chassis.snapshot().twist.wz, 0.0);
}

TEST(VirtualChassis, ModeSwitchBrakesToRestFirst) {
  Harness h;
  h.handshake();
  h.drive(ackermann(2.0), 3s);
  ASSERT_NEAR(h.chassis.snapshot().speed, 2.0, 1e-9);
  h.send(MotionModeCommand{MotionMode::kOblique});
  h.advance(1000ms);  // 2 m/s at 2 m/s^2: 1 s of braking, then 0.5 s of turning wheels
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
  EXPECT_TRUE(h.chassis.snapshot().switching);
  h.advance(480ms);
  EXPECT_TRUE(h.chassis.snapshot().switching);
  h.advance(40ms);
  EXPECT_FALSE(h.chassis.snapshot().switching);
  EXPECT_EQ(h.chassis.snapshot().motion_mode, MotionMode::kOblique);
}

TEST(VirtualChassis, SameModeRequestChangesNothing) {
  Harness h;
  h.handshake();
  h.send(MotionModeCommand{MotionMode::kAckermann});
  h.advance(20ms);
  EXPECT_FALSE(h.mode_feedback().switching);
}

TEST(VirtualChassis, SteeringSlewsAndSpeedRampsAtFiniteRates) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.0, 30 * kDeg), 100ms);
  const auto s = h.chassis.snapshot();
  // 90 deg/s and 1 m/s^2 by default: after ~0.1 s, ~9 deg and ~0.1 m/s.
  EXPECT_NEAR(s.steering, 9 * kDeg, 0.5 * kDeg);
  EXPECT_NEAR(s.speed, 0.1, 0.005);
  h.drive(ackermann(1.0, 30 * kDeg), 1s);
  EXPECT_NEAR(h.chassis.snapshot().steering, 30 * kDeg, 1e-9);
  EXPECT_NEAR(h.chassis.snapshot().speed, 1.0, 1e-9);
}

TEST(VirtualChassis, CommandsAreClampedToTheModesRange) {
  Harness h;
  h.handshake();
  h.drive(ackermann(5.0, 60 * kDeg), 4s);
  EXPECT_NEAR(h.chassis.snapshot().steering, 40 * kDeg, 1e-9);
  EXPECT_NEAR(h.chassis.snapshot().speed, interpretation::kMaxLinearSpeedMps, 1e-9);
}

// ---- feedback periods -------------------------------------------------------------------------

TEST(VirtualChassis, SendsEveryFeedbackFrameAtTheManualsPeriod) {
  for (auto granularity : {1ms, 7ms, 50ms}) {
    Harness h;
    h.advance(2s, granularity);
    std::map<std::uint32_t, std::vector<Timestamp>> stamps;
    for (const auto& f : h.bus.sent)
      stamps[f.id].push_back(f.stamp);
    auto period_of = [](std::uint32_t id) -> std::chrono::nanoseconds {
      if (id == 0x342 || id == 0x343) return 50ms;
      if (id >= 0x261 && id <= 0x268) return 100ms;
      if (id >= 0x361 && id <= 0x36A) return 500ms;
      return 20ms;
    };
    std::vector<std::uint32_t> expected = {0x211, 0x221, 0x271, 0x281, 0x291, 0x342, 0x343,
                                           0x361, 0x362, 0x363, 0x364, 0x365, 0x366};
    for (int n = 1; n <= 8; ++n) {
      expected.push_back(0x250 + n);
      expected.push_back(0x260 + n);
    }
    for (auto id : expected) {
      SCOPED_TRACE(testing::Message() << "id 0x" << std::hex << id << std::dec << " granularity "
                                      << granularity.count());
      ASSERT_TRUE(stamps.count(id));
      const auto& ts = stamps[id];
      EXPECT_EQ(ts.size(), 2s / period_of(id) + 1);  // at 0 and every period up to 2 s
      for (std::size_t i = 1; i < ts.size(); ++i)
        EXPECT_EQ(ts[i] - ts[i - 1], period_of(id));
    }
    // Two batteries fitted by default: no frames for slots 3 and 4.
    EXPECT_EQ(stamps.count(0x367) + stamps.count(0x369), 0u);
    for (const auto& f : h.bus.sent) {
      EXPECT_TRUE(decode(f).ok()) << "undecodable frame 0x" << std::hex << f.id;
    }
  }
}

TEST(VirtualChassis, AfterAStallDoesNotBurstStaleFeedback) {
  Harness h;
  h.advance(10ms);
  const auto before = h.bus.sent.size();
  h.advance(10s, 10s);
  EXPECT_LT(h.bus.sent.size() - before, 200u);
}

// ---- per-wheel kinematics and the manual's signs ----------------------------------------------

struct WheelReport {
  std::array<double, 4> angle;  // REP-103
  std::array<double, 4> speed;
};
WheelReport wheels_on_bus(const Harness& h) {
  const auto a = *h.last<SteeringAnglesFeedback>(protocol::kSteeringAnglesId);
  const auto s = *h.last<WheelSpeedsFeedback>(protocol::kWheelSpeedsId);
  WheelReport r{};
  for (int i = 0; i < 4; ++i) {
    r.angle[i] = interpretation::rep103_from_manual_wheel_angle(a.angles[i]);
    r.speed[i] = s.speeds[i];
  }
  return r;
}

// Every reported wheel moves as the rigid body does at its position (within wire resolution).
void expect_rigid_body(const Harness& h) {
  const auto s = h.chassis.snapshot();
  const WheelReport w = wheels_on_bus(h);
  const VehicleGeometry g;
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(testing::Message() << "wheel " << kWheelNames[i]);
    const auto p = g.wheel_position(i);
    EXPECT_GE(w.angle[i], -M_PI / 2 - 1e-9);
    EXPECT_LE(w.angle[i], M_PI / 2 + 1e-9);
    EXPECT_NEAR(w.speed[i] * std::cos(w.angle[i]), s.twist.vx - s.twist.wz * p.y, 2e-3);
    EXPECT_NEAR(w.speed[i] * std::sin(w.angle[i]), s.twist.vy + s.twist.wz * p.x, 2e-3);
  }
  // The same wheels as the controller library's kinematics derives from the twist.
  const WheelStates lib = wheel_states_from_twist(s.twist, g);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(lib[i].angle, w.angle[i], 0.02 * kDeg);
    EXPECT_NEAR(lib[i].speed, w.speed[i], 2e-3);
  }
}

TEST(VirtualChassis, AckermannLeftTurnWheelsAndFeedbackUseTheManualsSigns) {
  Harness h;
  h.handshake();
  h.drive(ackermann(0.8, 20 * kDeg), 2s);
  expect_rigid_body(h);
  const auto s = h.chassis.snapshot();
  EXPECT_GT(s.twist.wz, 0.0);
  EXPECT_EQ(s.twist.vy, 0.0);
  EXPECT_NEAR(s.twist.vx, 0.8, 1e-9);
  // Turning left: front wheels turn left (negative on the wire), rear wheels right (positive).
  const auto a = *h.last<SteeringAnglesFeedback>(protocol::kSteeringAnglesId);
  EXPECT_LT(a.angles[kRightFront], 0.0);
  EXPECT_LT(a.angles[kLeftFront], 0.0);
  EXPECT_GT(a.angles[kRightRear], 0.0);
  EXPECT_GT(a.angles[kLeftRear], 0.0);
  // The left (inner) wheels are slower than the right (outer) ones.
  const auto v = *h.last<WheelSpeedsFeedback>(protocol::kWheelSpeedsId);
  EXPECT_LT(v.speeds[kLeftFront], v.speeds[kRightFront]);
  // 0x221: (alpha+beta)/2 = the commanded mean angle, negative = left; speed = mean wheel speed.
  const auto fb = *h.last<MotionFeedback>(protocol::kMotionFeedbackId);
  EXPECT_NEAR(fb.steering_angle, -20 * kDeg, 0.011 * kDeg);
  EXPECT_NEAR(fb.speed, (v.speeds[0] + v.speeds[1] + v.speeds[2] + v.speeds[3]) / 4, 2e-3);
  EXPECT_GT(fb.speed, 0.8);  // the wheels are further from the centre of rotation than the body
  // The wheels realise the curvature the interpretation assigns to the mean angle.
  EXPECT_NEAR(s.twist.wz / s.twist.vx,
              interpretation::ackermann_curvature_from_mean_angle(20 * kDeg, 0.89, 0.56), 1e-9);
}

TEST(VirtualChassis, AckermannReverseRightTurn) {
  Harness h;
  h.handshake();
  h.drive(ackermann(-0.5, -15 * kDeg), 2s);
  expect_rigid_body(h);
  const auto s = h.chassis.snapshot();
  EXPECT_LT(s.twist.vx, 0.0);
  EXPECT_GT(s.twist.wz, 0.0) << "reversing with the wheels turned right turns the body CCW";
  const auto fb = *h.last<MotionFeedback>(protocol::kMotionFeedbackId);
  EXPECT_NEAR(fb.steering_angle, 15 * kDeg, 0.011 * kDeg);
  EXPECT_LT(fb.speed, 0.0);
}

TEST(VirtualChassis, ObliqueMovesSidewaysWithoutTurning) {
  Harness h;
  h.handshake();
  h.switch_mode(MotionMode::kOblique);
  h.drive(ackermann(0.5, 30 * kDeg), 2s);
  expect_rigid_body(h);
  const auto s = h.chassis.snapshot();
  EXPECT_NEAR(s.twist.vx, 0.5 * std::cos(30 * kDeg), 1e-9);
  EXPECT_NEAR(s.twist.vy, 0.5 * std::sin(30 * kDeg), 1e-9);
  EXPECT_EQ(s.twist.wz, 0.0);
  const auto a = *h.last<SteeringAnglesFeedback>(protocol::kSteeringAnglesId);
  for (double angle : a.angles)
    EXPECT_NEAR(angle, -30 * kDeg, 0.011 * kDeg);
  const auto fb = *h.last<MotionFeedback>(protocol::kMotionFeedbackId);
  EXPECT_NEAR(fb.steering_angle, -30 * kDeg, 0.011 * kDeg);
  EXPECT_NEAR(fb.speed, 0.5, 1e-3);
  EXPECT_NEAR(s.pose.yaw, 0.0, 1e-12);
  EXPECT_GT(s.pose.y, 0.0);

  h.drive(ackermann(0.4, 90 * kDeg), 2s);  // pure sideways, to the left
  expect_rigid_body(h);
  EXPECT_NEAR(h.chassis.snapshot().twist.vy, 0.4, 1e-9);
  EXPECT_NEAR(h.chassis.snapshot().twist.vx, 0.0, 1e-9);
}

TEST(VirtualChassis, SpinWheelsStandTangentAndFeedbackIsTheMeanAbsoluteAngle) {
  Harness h;
  h.handshake();
  h.switch_mode(MotionMode::kSpin);
  h.drive(spin(0.6), 2s);
  expect_rigid_body(h);
  const auto s = h.chassis.snapshot();
  const double r = std::hypot(0.445, 0.28);
  EXPECT_NEAR(s.twist.wz, 0.6 / r, 1e-9);
  EXPECT_NEAR(std::hypot(s.twist.vx, s.twist.vy), 0.0, 1e-12);
  const double tangent = std::atan2(0.445, 0.28);  // ~57.8 deg
  const auto a = *h.last<SteeringAnglesFeedback>(protocol::kSteeringAnglesId);
  EXPECT_NEAR(a.angles[kRightFront], -tangent, 0.011 * kDeg);
  EXPECT_NEAR(a.angles[kRightRear], tangent, 0.011 * kDeg);
  EXPECT_NEAR(a.angles[kLeftRear], -tangent, 0.011 * kDeg);
  EXPECT_NEAR(a.angles[kLeftFront], tangent, 0.011 * kDeg);
  // Counter-clockwise: the right wheels roll forward, the left ones backward.
  const auto v = *h.last<WheelSpeedsFeedback>(protocol::kWheelSpeedsId);
  EXPECT_NEAR(v.speeds[kRightFront], 0.6, 1e-3);
  EXPECT_NEAR(v.speeds[kRightRear], 0.6, 1e-3);
  EXPECT_NEAR(v.speeds[kLeftRear], -0.6, 1e-3);
  EXPECT_NEAR(v.speeds[kLeftFront], -0.6, 1e-3);
  const auto fb = *h.last<MotionFeedback>(protocol::kMotionFeedbackId);
  EXPECT_NEAR(fb.steering_angle, tangent, 0.011 * kDeg);
  EXPECT_NEAR(fb.speed, 0.6, 1e-3);

  h.drive(spin(-0.4), 2s);
  EXPECT_LT(h.chassis.snapshot().twist.wz, 0.0);
  EXPECT_NEAR((*h.last<MotionFeedback>(protocol::kMotionFeedbackId)).speed, -0.4, 1e-3);
}

TEST(VirtualChassis, WheelsHoldTheirAnglesAtRest) {
  Harness h;
  h.handshake();
  h.drive(ackermann(0.0, 25 * kDeg), 1s);
  const auto fb = *h.last<MotionFeedback>(protocol::kMotionFeedbackId);
  EXPECT_NEAR(fb.steering_angle, -25 * kDeg, 0.011 * kDeg);
  EXPECT_EQ(h.chassis.snapshot().pose.x, 0.0);
}

TEST(VirtualChassis, GroundTruthFollowsTheArcExactly) {
  Harness h;
  h.handshake();
  h.drive(ackermann(0.5, 0.0), 2s);  // accelerate straight (0.5 s ramp)
  const Pose2D start = h.chassis.snapshot().pose;
  h.drive(ackermann(0.5, 0.0), 2s);
  const Pose2D end = h.chassis.snapshot().pose;
  EXPECT_NEAR(end.x - start.x, 1.0, 1e-9);
  EXPECT_NEAR(end.y, 0.0, 1e-12);
  // Ramp: 0.125 m during the 0.5 s acceleration at 1 m/s^2, then 1.5 s at 0.5 m/s.
  EXPECT_NEAR(start.x, 0.125 + 1.5 * 0.5, 1e-6);
}

TEST(VirtualChassis, MotorFramesArePlausible) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.0), 3s);
  const double rpm = 1.0 / (2 * M_PI * 0.16) * 60;
  for (int n = 1; n <= 4; ++n) {
    const auto m = *h.last<MotorHighSpeedFeedback>(protocol::kMotorHighSpeedBaseId + n);
    EXPECT_NEAR(m.rpm, rpm, 1.0);
    EXPECT_GT(m.current, 0.0);
    EXPECT_GT(m.position, 0);
  }
  const auto low = *h.last<MotorLowSpeedFeedback>(protocol::kMotorLowSpeedBaseId + 1);
  EXPECT_GE(low.driver_voltage, vehicle_spec::kBatteryNormalMinVoltage - 1.0);  // under load
  EXPECT_LE(low.driver_voltage, vehicle_spec::kBatteryNormalMaxVoltage);
  EXPECT_EQ(low.driver_status, 0u);
  EXPECT_GE(low.motor_temperature, 25.0);
}

// ---- battery ----------------------------------------------------------------------------------

TEST(VirtualChassis, BatteryIsTheManualsLiFePO4Pack) {
  // Open-circuit voltage: inside the manual's 46-50 V over the usable 10-90 % SOC, a flat
  // plateau (3.2-3.3 V per cell), steep ends, rising with the charge; 48 V nominal.
  double previous = 0.0;
  for (double soc = 0.0; soc <= 100.0; soc += 0.5) {
    const double v = sim::lifepo4_pack_open_circuit_voltage(soc);
    EXPECT_GT(v, previous) << soc;
    previous = v;
    if (soc >= 10.0 && soc <= 90.0) {
      EXPECT_GE(v, vehicle_spec::kBatteryNormalMinVoltage) << soc;
      EXPECT_LE(v, vehicle_spec::kBatteryNormalMaxVoltage) << soc;
    }
  }
  auto ocv = sim::lifepo4_pack_open_circuit_voltage;
  EXPECT_LT(ocv(80) - ocv(20), 2.0) << "the plateau";
  EXPECT_GT(ocv(10) - ocv(0), 3.0) << "the steep empty end";
  EXPECT_GT(ocv(100) - ocv(95), 1.0) << "the steep full end";
  EXPECT_NEAR(ocv(20), vehicle_spec::kBatteryNominalVoltage, 0.5);
  EXPECT_EQ(ocv(-5), ocv(0));
  EXPECT_EQ(ocv(150), ocv(100));
  EXPECT_EQ(ocv(std::nan("")), ocv(0));
  // What the chassis reports follows the curve: 0x211 and the BMS at 30 % SOC, at rest.
  Harness h;
  h.chassis.set_battery_soc(30.0);
  h.advance(600ms);
  EXPECT_NEAR(h.status().battery_voltage, ocv(30), 0.15);
  EXPECT_NEAR(h.last<BmsData>(protocol::kBmsBaseId)->voltage, ocv(30), 0.15);
}

TEST(VirtualChassis, BatteryDrainsFasterUnderLoad) {
  Harness idle, driving;
  idle.handshake();
  driving.handshake();
  idle.advance(60s, 20ms);
  driving.drive(ackermann(1.5, 10 * kDeg), 60s);
  const auto soc_idle = idle.chassis.snapshot().battery.soc;
  const auto soc_driving = driving.chassis.snapshot().battery.soc;
  EXPECT_LT(soc_idle, 90.0);
  EXPECT_LT(soc_driving, soc_idle);
  EXPECT_GT(soc_driving, 89.0);  // slowly
  const auto bms = *driving.last<BmsData>(protocol::kBmsBaseId);
  EXPECT_LT(bms.current, 0.0);  // discharging
  EXPECT_NEAR(bms.soc, soc_driving, 1.0);
}

TEST(VirtualChassis, LowBatteryCutsPowerAndRefusesMotionUntilClearedAndCharged) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.0), 2s);
  const std::uint32_t uv = 1u << protocol::error_bit_index(7, 0);
  h.chassis.set_battery_soc(8.0);
  h.drive(ackermann(1.0), 1s);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
  EXPECT_EQ(h.status().error_bits & uv, uv);
  const auto alarm = *h.last<BmsAlarm>(protocol::kBmsBaseId + 1);
  EXPECT_TRUE(alarm.alarm1 & (1u << 2));
  const auto low = *h.last<MotorLowSpeedFeedback>(protocol::kMotorLowSpeedBaseId + 1);
  EXPECT_TRUE(low.driver_status & (1u << 6)) << "drivers disabled";

  h.send(ErrorClearCommand{0x09});  // still empty: the fault comes back at once
  h.drive(ackermann(1.0), 500ms);
  EXPECT_EQ(h.status().error_bits & uv, uv);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);

  h.chassis.set_battery_soc(60.0);  // charged, but the fault is latched
  h.drive(ackermann(1.0), 500ms);
  EXPECT_EQ(h.status().error_bits & uv, uv);
  h.send(ErrorClearCommand{0x09});
  h.drive(ackermann(1.0), 2s);
  EXPECT_EQ(h.status().error_bits, 0u);
  EXPECT_NEAR(h.chassis.snapshot().speed, 1.0, 1e-9);
}

// ---- faults -----------------------------------------------------------------------------------

TEST(VirtualChassis, EmergencyStopStopsAndRefusesMotionUntilReleased) {
  Harness h;
  h.handshake();
  h.drive(ackermann(1.5), 2s);
  h.chassis.set_emergency_stop(true);
  h.drive(ackermann(1.5), 300ms);  // 1.5 m/s at 6 m/s^2: stopped within 0.25 s
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
  EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kEmergencyStop);
  h.chassis.set_emergency_stop(false);
  h.drive(ackermann(0.5), 1s);
  EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kNormal);
  EXPECT_NEAR(h.chassis.snapshot().speed, 0.5, 1e-9);
}

TEST(VirtualChassis, EveryErrorBitCanBeInjectedAndIsReported) {
  for (int index = 0; index < 32; ++index) {
    SCOPED_TRACE(index);
    Harness h;
    h.handshake();
    h.chassis.set_error_bit(index, true);
    h.advance(20ms);
    EXPECT_EQ(h.status().error_bits, 1u << index);
    EXPECT_EQ(h.status().vehicle_status, protocol::VehicleStatus::kAbnormal);
    const bool critical = protocol::is_critical_error(1u << index);
    h.drive(ackermann(0.5), 1s);
    if (critical) {
      EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
    }
    h.chassis.set_error_bit(index, false);
    h.drive(ackermann(0.5), 20ms);
    EXPECT_EQ(h.status().error_bits, 0u);
  }
}

TEST(VirtualChassis, Clears441EachCodeItsOwnFault) {
  struct Case {
    std::uint8_t code;
    int byte, bit;
  };
  const Case cases[] = {
      {0x01, 7, 3}, {0x02, 7, 4}, {0x03, 7, 5}, {0x04, 7, 6}, {0x05, 6, 2}, {0x06, 6, 3},
      {0x07, 6, 4}, {0x08, 6, 5}, {0x09, 7, 0}, {0x0A, 7, 2}, {0x0B, 5, 0}, {0x0C, 5, 1},
      {0x0D, 5, 2}, {0x0E, 5, 3}, {0x0F, 6, 7}, {0x10, 6, 6},
  };
  const std::uint32_t warning = 1u << protocol::error_bit_index(4, 0);  // a non-critical bit
  for (const auto& c : cases) {
    SCOPED_TRACE(testing::Message() << "code " << int(c.code));
    Harness h;
    h.handshake();
    const std::uint32_t target = 1u << protocol::error_bit_index(c.byte, c.bit);
    h.chassis.set_error_bits(target | warning);
    h.advance(20ms);
    ASSERT_EQ(h.status().error_bits, target | warning);
    h.send(ErrorClearCommand{c.code});
    h.advance(20ms);
    EXPECT_EQ(h.status().error_bits, warning);
  }
}

TEST(VirtualChassis, Clear441AllNonCriticalKeepsCriticalFaults) {
  Harness h;
  h.handshake();
  const std::uint32_t warning = 1u << protocol::error_bit_index(4, 2);
  const std::uint32_t over_current = 1u << protocol::error_bit_index(6, 7);
  h.chassis.set_error_bits(warning | over_current);
  h.send(ErrorClearCommand{0x00});
  h.advance(20ms);
  EXPECT_EQ(h.status().error_bits, over_current);
}

TEST(VirtualChassis, ErrorClearingIsIgnoredOutsideCanMode) {
  Harness h;
  h.chassis.set_error_bit(protocol::error_bit_index(6, 7), true);
  h.send(ErrorClearCommand{0x0F});
  h.advance(20ms);
  EXPECT_NE(h.status().error_bits, 0u);
}

TEST(VirtualChassis, RemoteSignalLossGoesToStandbyAndClearsWith0x0A) {
  Harness h;
  h.handshake();
  h.chassis.remote_takeover();
  h.chassis.remote_signal_lost();
  h.advance(20ms);
  const std::uint32_t lost = 1u << protocol::error_bit_index(7, 2);
  EXPECT_EQ(h.status().control_mode, ControlMode::kStandby);
  EXPECT_EQ(h.status().error_bits, lost);
  h.handshake();
  h.send(ErrorClearCommand{0x0A});
  h.advance(20ms);
  EXPECT_EQ(h.status().error_bits, 0u);
}

TEST(VirtualChassis, SilentChassisSendsNothingThenResumes) {
  Harness h;
  h.advance(100ms);
  h.chassis.silence_for(1s);
  const auto before = h.bus.sent.size();
  h.advance(999ms);
  EXPECT_EQ(h.bus.sent.size(), before);
  h.advance(21ms);
  EXPECT_GT(h.bus.sent.size(), before);
  h.chassis.set_silent(true);
  const auto later = h.bus.sent.size();
  h.advance(2s);
  EXPECT_EQ(h.bus.sent.size(), later);
  h.chassis.set_silent(false);
  h.advance(20ms);
  EXPECT_GT(h.bus.sent.size(), later);
}

TEST(VirtualChassis, SilentChassisStillObeys) {
  Harness h;
  h.handshake();
  h.chassis.set_silent(true);
  h.drive(ackermann(0.5), 1s);
  EXPECT_GT(h.chassis.snapshot().pose.x, 0.1);
}

TEST(VirtualChassis, GarbageFramesAreAllUndecodable) {
  Harness h;
  h.advance(5ms);
  const auto before = h.bus.sent.size();
  h.chassis.inject_garbage(200);
  h.chassis.step(h.t);
  ASSERT_EQ(h.bus.sent.size() - before, 200u);
  int unknown = 0, bad_dlc = 0;
  for (std::size_t i = before; i < h.bus.sent.size(); ++i) {
    const auto r = decode(h.bus.sent[i]);
    ASSERT_FALSE(r.ok());
    if (r.error().code == Errc::kUnknownId) ++unknown;
    if (r.error().code == Errc::kBadDlc) ++bad_dlc;
  }
  EXPECT_GT(unknown, 50);
  EXPECT_GT(bad_dlc, 50);
}

TEST(VirtualChassis, StuckModeSwitchNeverCompletesUntilReleased) {
  Harness h;
  h.handshake();
  h.chassis.set_mode_switch_stuck(true);
  h.send(MotionModeCommand{MotionMode::kOblique});
  h.advance(10s, 10ms);
  EXPECT_TRUE(h.mode_feedback().switching);
  EXPECT_EQ(h.mode_feedback().mode, MotionMode::kAckermann);
  h.chassis.set_mode_switch_stuck(false);
  h.advance(20ms);
  EXPECT_FALSE(h.mode_feedback().switching);
  EXPECT_EQ(h.mode_feedback().mode, MotionMode::kOblique);
}

TEST(VirtualChassis, RejectsFramesThatAreNotCommands) {
  Harness h;
  h.handshake();
  CanFrame bad;
  bad.id = 0x111;
  bad.dlc = 3;  // wrong DLC
  h.chassis.on_frame(bad, h.t);
  h.send(MotionFeedback{1.0, 0.0});  // another node's feedback
  CanFrame error_frame;
  error_frame.is_error = true;
  h.chassis.on_frame(error_frame, h.t);
  EXPECT_EQ(h.chassis.counters().frames_rejected, 3u);
  h.advance(100ms);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
}

// ---- ultrasonic -------------------------------------------------------------------------------

TEST(VirtualChassis, Answers0x451With0x45AAndReportsChanges) {
  Harness h;
  h.handshake();
  h.send(UltrasonicSettingCommand{true});
  ASSERT_EQ(h.count(protocol::kUltrasonicSettingFeedbackId), 1u);
  EXPECT_TRUE(h.last<UltrasonicSettingFeedback>(protocol::kUltrasonicSettingFeedbackId)->enabled);
  h.send(UltrasonicSettingCommand{true});  // answered even without a change
  EXPECT_EQ(h.count(protocol::kUltrasonicSettingFeedbackId), 2u);
  h.advance(1s);
  EXPECT_EQ(h.count(protocol::kUltrasonicSettingFeedbackId), 2u) << "not periodic";
  h.chassis.set_ultrasonic_enabled(false);  // the remote's switch
  EXPECT_EQ(h.count(protocol::kUltrasonicSettingFeedbackId), 3u);
  EXPECT_FALSE(h.last<UltrasonicSettingFeedback>(protocol::kUltrasonicSettingFeedbackId)->enabled);
}

TEST(VirtualChassis, UltrasonicDistancesAndAvoidance) {
  Harness h;
  h.handshake();
  h.chassis.set_ultrasonic(6, 1234);
  h.chassis.set_ultrasonic(2, -1);
  h.advance(60ms);
  const auto a = *h.last<UltrasonicFeedback>(protocol::kUltrasonic1to4Id);
  const auto b = *h.last<UltrasonicFeedback>(protocol::kUltrasonic5to8Id);
  EXPECT_EQ(a.raw[1], -1);
  EXPECT_EQ(b.raw[1], 1234);
  EXPECT_EQ(a.raw[0], 3000);

  h.send(UltrasonicSettingCommand{true});
  h.drive(ackermann(0.5), 1s);
  EXPECT_GT(h.chassis.snapshot().speed, 0.4);
  h.chassis.set_ultrasonic(1, 200);  // an obstacle closer than 300 mm
  h.drive(ackermann(0.5), 1s);
  EXPECT_EQ(h.chassis.snapshot().speed, 0.0);
  const std::uint32_t triggered = 1u << protocol::error_bit_index(7, 1);
  EXPECT_EQ(h.status().error_bits, triggered);
  h.chassis.set_ultrasonic(1, 2000);
  h.drive(ackermann(0.5), 1s);
  EXPECT_EQ(h.status().error_bits, 0u);
  EXPECT_GT(h.chassis.snapshot().speed, 0.4);
}

// ---- events -----------------------------------------------------------------------------------

TEST(VirtualChassis, ReportsStateChangesAsEvents) {
  Harness h;
  h.handshake();
  h.chassis.set_emergency_stop(true);
  const auto events = h.chassis.take_events();
  auto has = [&](const std::string& needle) {
    return std::any_of(events.begin(), events.end(),
                       [&](const SimEvent& e) { return e.text.find(needle) != std::string::npos; });
  };
  EXPECT_TRUE(has("power on"));
  EXPECT_TRUE(has("control mode standby -> can"));
  EXPECT_TRUE(has("emergency stop pressed"));
  EXPECT_TRUE(h.chassis.take_events().empty());
}

}  // namespace
}  // namespace ranger::sim
