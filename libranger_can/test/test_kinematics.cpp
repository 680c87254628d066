// Kinematics: twist -> motion mode + 0x111 fields, per mode, with limits, NaN and wrap cases; the
// mode selector's hysteresis and dwell.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/mode_selector.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;
namespace interp = ranger::interpretation;

constexpr double kDeg = M_PI / 180.0;
constexpr double kTol = 1e-9;

KinematicsSolution solve(BodyTwist t, MotionMode mode, KinematicsLimits limits = {}) {
  Result<KinematicsSolution> r = solve_kinematics(t, mode, VehicleGeometry{}, limits);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : KinematicsSolution{};
}

std::array<std::uint8_t, 8> bytes_of(const MotionCommand& c) {
  Result<CanFrame> f = encode(c);
  EXPECT_TRUE(f.ok());
  return f.ok() ? f->data : std::array<std::uint8_t, 8>{};
}

void expect_twist_near(const BodyTwist& a, const BodyTwist& b, double tol = 1e-6) {
  EXPECT_NEAR(a.vx, b.vx, tol);
  EXPECT_NEAR(a.vy, b.vy, tol);
  EXPECT_NEAR(a.wz, b.wz, tol);
}

// ---- Ackermann ---------------------------------------------------------------------------------

TEST(KinematicsAckermann, StraightAheadIsTheManualSampleFrame) {
  const KinematicsSolution s = solve({0.15, 0, 0}, MotionMode::kAckermann);
  EXPECT_EQ(s.flags, kKinematicsExact);
  EXPECT_DOUBLE_EQ(s.command.linear_speed, 0.15);
  EXPECT_DOUBLE_EQ(s.command.steering_angle, 0.0);
  EXPECT_DOUBLE_EQ(s.command.spin_speed, 0.0);
  // Manual sample: forward 150 mm/s -> 00 96 00 00 00 00 00 00.
  EXPECT_EQ(bytes_of(s.command), (std::array<std::uint8_t, 8>{0x00, 0x96, 0, 0, 0, 0, 0, 0}));
}

struct AckermannCase {
  double vx, wz;
  double manual_steering_sign;  // 0x111 steering: positive = right
};

TEST(KinematicsAckermann, SignsForEveryQuadrantRoundTrip) {
  // Left turn forward (CCW) steers left = negative in the manual's convention; reversing with a
  // CCW rotation steers right.
  const AckermannCase cases[] = {
      {1.0, 0.5, -1.0}, {1.0, -0.5, +1.0}, {-1.0, 0.5, +1.0}, {-1.0, -0.5, -1.0}, {0.3, 0.1, -1.0}};
  const VehicleGeometry g;
  for (const AckermannCase& c : cases) {
    SCOPED_TRACE(testing::Message() << "vx=" << c.vx << " wz=" << c.wz);
    const KinematicsSolution s = solve({c.vx, 0, c.wz}, MotionMode::kAckermann);
    EXPECT_EQ(s.flags, kKinematicsExact);
    EXPECT_EQ(s.mode, MotionMode::kAckermann);
    EXPECT_DOUBLE_EQ(s.command.linear_speed, c.vx);
    EXPECT_GT(s.command.steering_angle * c.manual_steering_sign, 0.0);
    const double expected = interp::manual_from_rep103_command_steering(
        interp::ackermann_mean_front_angle(c.wz / c.vx, g.wheelbase, g.track));
    EXPECT_NEAR(s.command.steering_angle, expected, kTol);
    expect_twist_near(s.achieved, {c.vx, 0, c.wz});
    expect_twist_near(twist_from_command(s.command, MotionMode::kAckermann, g), {c.vx, 0, c.wz});
  }
}

TEST(KinematicsAckermann, TighterThanTheSteeringLimitKeepsTheCurvatureSign) {
  const VehicleGeometry g;
  const double k_max = max_ackermann_curvature(40 * kDeg, g);
  ASSERT_GT(k_max, 0.0);
  for (double sign : {+1.0, -1.0}) {
    const KinematicsSolution s = solve({0.5, 0, sign * 5.0}, MotionMode::kAckermann);
    EXPECT_TRUE(s.flags & kSteeringSaturated);
    EXPECT_FALSE(s.flags & kSpeedSaturated);
    // Full lock, in the requested direction (REP-103 left = manual negative).
    EXPECT_NEAR(s.command.steering_angle,
                interp::manual_from_rep103_command_steering(sign * 40 * kDeg), 1e-9);
    EXPECT_DOUBLE_EQ(s.command.linear_speed, 0.5);
    EXPECT_NEAR(s.achieved.wz, sign * k_max * 0.5, 1e-9);
    // Manual range: +-4000 x 0.01 deg.
    const auto b = bytes_of(s.command);
    const auto raw = static_cast<std::int16_t>((b[6] << 8) | b[7]);
    EXPECT_EQ(raw, sign > 0 ? -4000 : 4000);
  }
}

TEST(KinematicsAckermann, RotationWithoutSpeedTurnsTheWheelsButDoesNotMove) {
  const KinematicsSolution s = solve({0, 0, 0.7}, MotionMode::kAckermann);
  EXPECT_TRUE(s.flags & kRotationDropped);
  EXPECT_DOUBLE_EQ(s.command.linear_speed, 0.0);
  EXPECT_NEAR(s.command.steering_angle, interp::manual_from_rep103_command_steering(40 * kDeg),
              1e-12);
  expect_twist_near(s.achieved, {0, 0, 0});
}

TEST(KinematicsAckermann, LateralVelocityIsDroppedAndFlagged) {
  const KinematicsSolution s = solve({1.0, 0.3, 0}, MotionMode::kAckermann);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kLateralDropped));
  expect_twist_near(s.achieved, {1.0, 0, 0});
}

TEST(KinematicsAckermann, SpeedSaturatesAtTheConfiguredLimitNeverWraps) {
  KinematicsLimits limits;
  limits.max_linear_speed = 2.6;
  limits.max_speed_at_large_steering = 2.6;
  for (double vx : {3.0, 1e6, 1e300, -1e300}) {
    const KinematicsSolution s = solve({vx, 0, 0}, MotionMode::kAckermann, limits);
    EXPECT_TRUE(s.flags & kSpeedSaturated);
    EXPECT_DOUBLE_EQ(s.command.linear_speed, vx > 0 ? 2.6 : -2.6);
    const auto b = bytes_of(s.command);
    EXPECT_EQ(static_cast<std::int16_t>((b[0] << 8) | b[1]), vx > 0 ? 2600 : -2600);
  }
  // The default limit is the driver's conservative 1.5 m/s.
  EXPECT_DOUBLE_EQ(solve({2.0, 0, 0}, MotionMode::kAckermann).command.linear_speed, 1.5);
}

TEST(KinematicsAckermann, LargeSteeringSpeedLimitAppliesAbove20Degrees) {
  KinematicsLimits limits;
  limits.max_speed_at_large_steering = 0.5;
  const VehicleGeometry g;
  // A curvature needing ~30 deg mean steering, and one needing ~10 deg.
  const double k30 = interp::ackermann_curvature_from_mean_angle(30 * kDeg, g.wheelbase, g.track);
  const double k10 = interp::ackermann_curvature_from_mean_angle(10 * kDeg, g.wheelbase, g.track);
  const KinematicsSolution tight = solve({1.0, 0, k30 * 1.0}, MotionMode::kAckermann, limits);
  EXPECT_TRUE(tight.flags & kSpeedSaturated);
  EXPECT_DOUBLE_EQ(tight.command.linear_speed, 0.5);
  EXPECT_NEAR(tight.achieved.wz, k30 * 0.5, 1e-9);  // curvature kept while slowing down
  const KinematicsSolution gentle = solve({1.0, 0, k10}, MotionMode::kAckermann, limits);
  EXPECT_EQ(gentle.flags, kKinematicsExact);
  EXPECT_DOUBLE_EQ(gentle.command.linear_speed, 1.0);
}

// ---- Oblique -----------------------------------------------------------------------------------

struct ObliqueCase {
  double vx, vy;
  double speed;           // expected 0x111 linear speed
  double rep103_degrees;  // expected direction, REP-103
};

TEST(KinematicsOblique, DirectionFoldsIntoPlusMinus90WithSignedSpeed) {
  const double r2 = std::sqrt(2.0);
  const ObliqueCase cases[] = {
      {1, 0, 1, 0},
      {0, 1, 1, 90},
      {0, -1, 1, -90},
      {-1, 0, -1, 0},
      {1, 1, r2, 45},
      {1, -1, r2, -45},
      {-1, 1, -r2, -45},
      {-1, -1, -r2, 45},
      {0.5, 0.5 * std::tan(30 * kDeg), 0.5 / std::cos(30 * kDeg), 30},
  };
  for (const ObliqueCase& c : cases) {
    SCOPED_TRACE(testing::Message() << "vx=" << c.vx << " vy=" << c.vy);
    const KinematicsSolution s = solve({c.vx, c.vy, 0}, MotionMode::kOblique);
    EXPECT_EQ(s.flags, kKinematicsExact);
    EXPECT_NEAR(s.command.linear_speed, c.speed, 1e-12);
    EXPECT_NEAR(s.command.steering_angle,
                interp::manual_from_rep103_command_steering(c.rep103_degrees * kDeg), 1e-12);
    EXPECT_DOUBLE_EQ(s.command.spin_speed, 0.0);
    expect_twist_near(s.achieved, {c.vx, c.vy, 0}, 1e-12);
    expect_twist_near(twist_from_command(s.command, MotionMode::kOblique, VehicleGeometry{}),
                      {c.vx, c.vy, 0}, 1e-12);
  }
}

TEST(KinematicsOblique, ManualSteeringSampleFrameIsTenDegreesRight) {
  // Manual sample: steering 10 deg -> ... 03 E8, positive = right = REP-103 negative.
  const KinematicsSolution s =
      solve({std::cos(-10 * kDeg) * 0.1, std::sin(-10 * kDeg) * 0.1, 0}, MotionMode::kOblique);
  const auto b = bytes_of(s.command);
  EXPECT_EQ(b[6], 0x03);
  EXPECT_EQ(b[7], 0xE8);
}

TEST(KinematicsOblique, RotationDroppedAndSteeringLimitFlagged) {
  EXPECT_TRUE(solve({1, 0.5, 0.3}, MotionMode::kOblique).flags & kRotationDropped);
  KinematicsLimits limits;
  limits.max_oblique_steering = 60 * kDeg;
  const KinematicsSolution s = solve({0, 1, 0}, MotionMode::kOblique, limits);
  EXPECT_TRUE(s.flags & kSteeringSaturated);
  EXPECT_NEAR(s.command.steering_angle, interp::manual_from_rep103_command_steering(60 * kDeg),
              1e-12);
  const KinematicsSolution fast = solve({0, -9, 0}, MotionMode::kOblique);
  EXPECT_TRUE(fast.flags & kSpeedSaturated);
  EXPECT_DOUBLE_EQ(fast.command.linear_speed, 1.5);
}

TEST(KinematicsOblique, ZeroTwistIsZeroCommand) {
  const KinematicsSolution s = solve({0, 0, 0}, MotionMode::kOblique);
  EXPECT_EQ(bytes_of(s.command), (std::array<std::uint8_t, 8>{}));
}

// ---- Spin --------------------------------------------------------------------------------------

TEST(KinematicsSpin, YawRateToWheelSpeedAndLimit) {
  const VehicleGeometry g;
  const double r = std::hypot(g.wheelbase / 2, g.track / 2);
  const KinematicsSolution s = solve({0, 0, 1.0}, MotionMode::kSpin);
  EXPECT_EQ(s.flags, kKinematicsExact);
  EXPECT_NEAR(s.command.spin_speed, r, 1e-12);  // counter-clockwise positive
  EXPECT_DOUBLE_EQ(s.command.linear_speed, 0.0);
  EXPECT_DOUBLE_EQ(s.command.steering_angle, 0.0);
  expect_twist_near(twist_from_command(s.command, MotionMode::kSpin, g), {0, 0, 1.0}, 1e-12);

  for (double wz : {5.0, -5.0, 1e300}) {
    const KinematicsSolution sat = solve({0.2, 0, wz}, MotionMode::kSpin);
    EXPECT_TRUE(sat.flags & kSpinSaturated);
    EXPECT_TRUE(sat.flags & kTranslationDropped);
    EXPECT_DOUBLE_EQ(sat.command.spin_speed, wz > 0 ? 1.0 : -1.0);
    const auto b = bytes_of(sat.command);
    EXPECT_EQ(static_cast<std::int16_t>((b[4] << 8) | b[5]), wz > 0 ? 1000 : -1000);
  }
}

// ---- refusals and limits -----------------------------------------------------------------------

TEST(Kinematics, RefusesNaNAndInfinityNamingTheComponent) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const BodyTwist bad[] = {{nan, 0, 0}, {0, nan, 0}, {0, 0, nan}, {inf, 0, 0}, {0, 0, -inf}};
  const char* names[] = {"vx", "vy", "wz", "vx", "wz"};
  for (int i = 0; i < 5; ++i) {
    for (MotionMode m : {MotionMode::kAckermann, MotionMode::kOblique, MotionMode::kSpin}) {
      Result<KinematicsSolution> r = solve_kinematics(bad[i], m, VehicleGeometry{}, {});
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.error().code, Errc::kNotFinite);
      EXPECT_NE(r.error().message.find(names[i]), std::string::npos) << r.error().message;
    }
  }
}

TEST(Kinematics, InvalidLimitsAreRejected) {
  KinematicsLimits limits;
  limits.max_ackermann_steering = 50 * kDeg;  // beyond the protocol's 40 deg
  EXPECT_FALSE(limits.validate().ok());
  EXPECT_FALSE(solve_kinematics({1, 0, 0}, MotionMode::kAckermann, {}, limits).ok());
  limits = KinematicsLimits{};
  limits.max_linear_speed = 3.0;  // beyond 2.6 m/s
  EXPECT_FALSE(limits.validate().ok());
  limits.max_linear_speed = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(limits.validate().ok());
  EXPECT_TRUE(KinematicsLimits{}.validate().ok());
}

TEST(Kinematics, FlagsHaveNames) {
  EXPECT_EQ(kinematics_flags_to_string(0), "exact");
  EXPECT_EQ(kinematics_flags_to_string(kSpeedSaturated | kLateralDropped),
            "speed_saturated|lateral_dropped");
}

// ---- wheel states ------------------------------------------------------------------------------

TEST(WheelStates, AckermannFrontWheelsMeanIsTheSteeringAngle) {
  const VehicleGeometry g;
  const double k = 0.8;
  const WheelStates w = wheel_states_from_twist({1.0, 0, k}, g);
  const double mean_front = (w[kLeftFront].angle + w[kRightFront].angle) / 2;
  EXPECT_NEAR(mean_front, interp::ackermann_mean_front_angle(k, g.wheelbase, g.track), 1e-12);
  // Dual Ackermann: the rear wheels mirror the front ones.
  EXPECT_NEAR(w[kLeftRear].angle, -w[kLeftFront].angle, 1e-12);
  EXPECT_NEAR(w[kRightRear].angle, -w[kRightFront].angle, 1e-12);
  EXPECT_GT(w[kRightFront].speed, w[kLeftFront].speed);  // the outer wheel runs faster
}

TEST(WheelStates, SpinWheelsAreTangentAndHoldWhenStopped) {
  const VehicleGeometry g;
  const double r = g.wheel_radius_from_centre();
  const WheelStates w = wheel_states_from_twist({0, 0, 1.0}, g);
  for (const WheelState& s : w) {
    EXPECT_NEAR(std::fabs(s.speed), r, 1e-12);
    EXPECT_LE(std::fabs(s.angle), M_PI / 2 + 1e-12);
  }
  const std::array<double, 4> hold{0.1, 0.2, 0.3, 0.4};
  const WheelStates still = wheel_states_from_twist({}, g, hold);
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(still[i].angle, hold[i]);
    EXPECT_DOUBLE_EQ(still[i].speed, 0.0);
  }
}

// ---- mode selection ----------------------------------------------------------------------------

TEST(ModeSelector, ClassificationTable) {
  const ModeSelector sel;
  struct Case {
    BodyTwist t;
    MotionMode current, expected;
  } cases[] = {
      {{1, 0, 0}, MotionMode::kAckermann, MotionMode::kAckermann},
      {{1, 0, 0.5}, MotionMode::kAckermann, MotionMode::kAckermann},
      {{0.3, 0.3, 0}, MotionMode::kAckermann, MotionMode::kOblique},
      {{0, -0.3, 0}, MotionMode::kSpin, MotionMode::kOblique},
      {{0, 0, 0.5}, MotionMode::kAckermann, MotionMode::kSpin},
      {{0, 0, -0.5}, MotionMode::kOblique, MotionMode::kSpin},
      {{0, 0, 0}, MotionMode::kSpin, MotionMode::kSpin},  // standstill never switches
      {{0, 0, 0}, MotionMode::kOblique, MotionMode::kOblique},
      {{1, 0, 0}, MotionMode::kOblique, MotionMode::kOblique},  // oblique drives straight too
      {{1, 0, 0.5}, MotionMode::kOblique, MotionMode::kAckermann},
      {{1, 0, 0}, MotionMode::kSpin, MotionMode::kAckermann},
      // hysteresis bands
      {{1, 0.03, 0}, MotionMode::kAckermann, MotionMode::kAckermann},    // below lateral_enter
      {{1, 0.03, 0.5}, MotionMode::kOblique, MotionMode::kOblique},      // above lateral_exit
      {{0.03, 0, 0.5}, MotionMode::kAckermann, MotionMode::kAckermann},  // above linear_enter
      {{0.03, 0, 0.5}, MotionMode::kSpin, MotionMode::kSpin},            // below linear_exit
      {{0, 0, 0.03}, MotionMode::kSpin, MotionMode::kSpin},              // above rotation_exit
      // no dead band: a small twist drives in the mode a user expects
      {{0, 0, 0.03}, MotionMode::kAckermann, MotionMode::kSpin},        // small pure rotation
      {{0, 0.03, 0}, MotionMode::kAckermann, MotionMode::kOblique},     // small pure lateral
      {{0.02, 0.03, 0}, MotionMode::kAckermann, MotionMode::kOblique},  // lateral dominates
      {{0.01, 0, 0}, MotionMode::kSpin, MotionMode::kAckermann},        // small pure translation
      {{0, 0.05, 0}, MotionMode::kAckermann, MotionMode::kOblique},     // teleop's minimum
      {{0, 0, 0.05}, MotionMode::kAckermann, MotionMode::kSpin},
      // below the chassis's resolution: nothing to drive, no switch
      {{0.0004, 0, 0}, MotionMode::kSpin, MotionMode::kSpin},
      {{0, 0, 0.001}, MotionMode::kAckermann, MotionMode::kAckermann},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(sel.classify(c.t, c.current), c.expected)
        << "twist (" << c.t.vx << ", " << c.t.vy << ", " << c.t.wz << ") in "
        << protocol::to_string(c.current);
  }
}

TEST(ModeSelector, BelowMinimumIsNamedNotDropped) {
  const ModeSelector sel;
  EXPECT_FALSE(sel.below_minimum({0, 0, 0}));  // zero is a stop, not a too-small motion
  EXPECT_TRUE(sel.below_minimum({0.0004, 0, 0}));
  EXPECT_TRUE(sel.below_minimum({0, -0.0002, 0.001}));
  EXPECT_FALSE(sel.below_minimum({0.001, 0, 0}));
  EXPECT_FALSE(sel.below_minimum({0, 0, 0.002}));
}

TEST(ModeSelector, NoisyInputDoesNotFlapAndSteadyInputSwitchesAfterConfirmTime) {
  ModeSelector sel;  // confirm 100 ms, dwell 1 s
  Timestamp t{0};
  // Teleop noise: a lateral blip every other 20 ms sample never lasts the confirm time.
  for (int i = 0; i <= 50; ++i, t += 20ms) {  // ends on a clean sample
    const BodyTwist twist = (i % 2) ? BodyTwist{0.5, 0.1, 0} : BodyTwist{0.5, 0, 0};
    EXPECT_EQ(sel.select(twist, MotionMode::kAckermann, t), MotionMode::kAckermann) << i;
  }
  // A steady lateral request is granted once it has lasted 100 ms.
  const Timestamp start = t;
  MotionMode chosen = MotionMode::kAckermann;
  while (chosen == MotionMode::kAckermann && t < start + 1s) {
    chosen = sel.select({0.5, 0.3, 0}, MotionMode::kAckermann, t);
    if (chosen == MotionMode::kAckermann) t += 10ms;
  }
  EXPECT_EQ(chosen, MotionMode::kOblique);
  EXPECT_EQ(t - start, 100ms);
}

TEST(ModeSelector, DwellHoldsANewModeBeforeAnotherSwitch) {
  ModeSelector sel;
  Timestamp t{0};
  EXPECT_EQ(sel.select({0, 0.5, 0}, MotionMode::kAckermann, t), MotionMode::kAckermann);
  t += 100ms;
  EXPECT_EQ(sel.select({0, 0.5, 0}, MotionMode::kAckermann, t), MotionMode::kOblique);
  // The chassis reports oblique from now on; a spin request must wait for min_dwell (1 s).
  const Timestamp entered = t;
  MotionMode chosen = sel.select({0, 0, 1}, MotionMode::kOblique, t);
  while (chosen == MotionMode::kOblique && t < entered + 5s) {
    t += 10ms;
    chosen = sel.select({0, 0, 1}, MotionMode::kOblique, t);
  }
  EXPECT_EQ(chosen, MotionMode::kSpin);
  EXPECT_EQ(t - entered, 1000ms);
}

TEST(ModeSelector, ConfigValidation) {
  ModeSelectorConfig c;
  EXPECT_TRUE(c.validate().ok());
  c.lateral_exit = 0.1;  // exit above enter: no hysteresis
  EXPECT_FALSE(c.validate().ok());
  ModeSelectorConfig band;
  band.oblique_side_band = M_PI / 2;  // would reach straight ahead
  EXPECT_FALSE(band.validate().ok());
  band.oblique_side_band = std::nan("");
  EXPECT_FALSE(band.validate().ok());
}

// ---- Oblique side hysteresis near +-90 deg ---------------------------------------------------

double rep103_steering(const KinematicsSolution& s) {
  return interp::rep103_from_manual_command_steering(s.command.steering_angle);
}

KinematicsSolution solve_with(ModeSelector& selector, BodyTwist t) {
  Result<KinematicsSolution> r =
      selector.solve(t, MotionMode::kOblique, VehicleGeometry{}, KinematicsLimits{});
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : KinematicsSolution{};
}

TEST(KinematicsOblique, PureSolutionFlipsTheWheelsOnNoisyVx) {
  // The problem the hysteresis solves: stateless, the sign of a 1 mm/s vx swings the wheels.
  EXPECT_GT(rep103_steering(solve({1e-3, 0.5, 0}, MotionMode::kOblique)), 89 * kDeg);
  EXPECT_LT(rep103_steering(solve({-1e-3, 0.5, 0}, MotionMode::kOblique)), -89 * kDeg);
}

TEST(KinematicsOblique, SideHintKeepsTheWheelLineWithTheSpeedNegated) {
  const Result<KinematicsSolution> r =
      solve_kinematics({-1e-3, 0.5, 0}, MotionMode::kOblique, VehicleGeometry{}, KinematicsLimits{},
                       ObliqueSideHint{+1.0, 5 * kDeg});
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(rep103_steering(*r), 90 * kDeg, kTol);  // 90.1 deg, clamped to the limit
  EXPECT_NEAR(r->command.linear_speed, std::hypot(1e-3, 0.5), kTol);
  EXPECT_TRUE(r->flags & kSteeringSaturated);
  EXPECT_NEAR(r->achieved.vy, 0.5, 1e-5);  // still moving left
}

TEST(ModeSelector, ObliqueNoiseAroundNinetyDegreesDoesNotSwingTheWheels) {
  ModeSelector selector;
  const double first = rep103_steering(solve_with(selector, {1e-3, 0.5, 0}));
  ASSERT_GT(first, 89 * kDeg);
  for (int i = 0; i < 20; ++i) {
    const double vx = i % 2 == 0 ? -1e-3 : 1e-3;
    const KinematicsSolution s = solve_with(selector, {vx, 0.5, 0});
    SCOPED_TRACE(i);
    EXPECT_GT(rep103_steering(s), 89 * kDeg);  // never flips to about -90 deg
    EXPECT_GT(s.command.linear_speed, 0.0);
    EXPECT_NEAR(s.achieved.vy, 0.5, 1e-5);
  }
  // Reversing to the right inside the band: same wheel line, negative speed.
  const KinematicsSolution right = solve_with(selector, {1e-3, -0.5, 0});
  EXPECT_GT(rep103_steering(right), 89 * kDeg);
  EXPECT_LT(right.command.linear_speed, 0.0);
  EXPECT_NEAR(right.achieved.vy, -0.5, 1e-5);
}

TEST(ModeSelector, ObliqueDirectionChangeBeyondTheBandFlips) {
  ModeSelector selector;
  ASSERT_GT(rep103_steering(solve_with(selector, {1e-3, 0.5, 0})), 89 * kDeg);
  // 80 deg to the right of forward: outside the 5 deg band, the pure solution wins.
  const KinematicsSolution s =
      solve_with(selector, {0.5 * std::cos(-80 * kDeg), 0.5 * std::sin(-80 * kDeg), 0});
  EXPECT_NEAR(rep103_steering(s), -80 * kDeg, kTol);
  EXPECT_GT(s.command.linear_speed, 0.0);
  // ...and that is now the side the band keeps.
  EXPECT_LT(rep103_steering(solve_with(selector, {-1e-3, 0.5, 0})), -89 * kDeg);
}

TEST(ModeSelector, ObliqueSideIsForgottenOnResetAndInOtherModes) {
  ModeSelector selector;
  solve_with(selector, {1e-3, 0.5, 0});
  selector.reset();
  EXPECT_LT(rep103_steering(solve_with(selector, {-1e-3, 0.5, 0})), -89 * kDeg);
  ASSERT_TRUE(
      selector.solve({0.5, 0, 0}, MotionMode::kAckermann, VehicleGeometry{}, KinematicsLimits{}));
  EXPECT_GT(rep103_steering(solve_with(selector, {1e-3, 0.5, 0})), 89 * kDeg);
  // A zero band is the pure function.
  ModeSelectorConfig off;
  off.oblique_side_band = 0.0;
  ModeSelector pure(off);
  solve_with(pure, {1e-3, 0.5, 0});
  EXPECT_LT(rep103_steering(solve_with(pure, {-1e-3, 0.5, 0})), -89 * kDeg);
}

}  // namespace
}  // namespace ranger

// ---- protocol profiles: the chassis's readings of 0x111 ---------------------------

namespace ranger {
namespace {

TEST(KinematicsProfile, TheInnerWheelReferenceSteersTheInnerWheelToTheTurn) {
  const VehicleGeometry g;
  ProtocolProfile inner = manual_profile();
  inner.steering_reference = SteeringReference::kInnerFront;
  const BodyTwist turn{0.5, 0.0, 0.25};  // radius 2 m, to the left
  auto mean = solve_kinematics(turn, MotionMode::kAckermann, g, KinematicsLimits{});
  auto in = solve_kinematics(turn, MotionMode::kAckermann, g, KinematicsLimits{}, {}, inner);
  ASSERT_TRUE(mean.ok() && in.ok());
  const double k = 0.5;
  const double inner_angle = std::atan2(g.wheelbase / 2 * k, 1 - g.track / 2 * k);
  EXPECT_NEAR(interpretation::rep103_from_manual_command_steering(in->command.steering_angle),
              inner_angle, 1e-9);
  EXPECT_GT(std::fabs(in->command.steering_angle), std::fabs(mean->command.steering_angle));
  // Each reading inverts itself: the command realises the twist asked for.
  const BodyTwist back = twist_from_command(in->command, MotionMode::kAckermann, g, inner);
  EXPECT_NEAR(back.wz, 0.25, 1e-9);
  EXPECT_NEAR(back.vx, 0.5, 1e-9);
  // The wheels 0x271 should show are the same whatever the reading (one vehicle, one turn).
  const auto a = wheel_angles_for_command(mean->command, MotionMode::kAckermann, g);
  const auto b = wheel_angles_for_command(in->command, MotionMode::kAckermann, g, inner);
  for (int i = 0; i < kWheelCount; ++i)
    EXPECT_NEAR(a[i], b[i], 1e-9) << "wheel " << i;
  // And the steering limit applies to the angle that reading names.
  inner.steering_reference = SteeringReference::kInnerFront;
  EXPECT_LT(max_ackermann_curvature(0.5, g, inner), max_ackermann_curvature(0.5, g));
}

TEST(KinematicsProfile, SpinGoesOutInTheChassisFieldAndSign) {
  const VehicleGeometry g;
  const BodyTwist spin{0.0, 0.0, 0.5};
  const double wheel = 0.5 * std::hypot(g.wheelbase / 2, g.track / 2);
  auto manual = solve_kinematics(spin, MotionMode::kSpin, g, KinematicsLimits{});
  ASSERT_TRUE(manual.ok());
  EXPECT_NEAR(manual->command.spin_speed, wheel, 1e-12);
  EXPECT_EQ(manual->command.yaw_rate, 0.0);

  ProtocolProfile yaw = manual_profile();
  yaw.spin_field = SpinField::kYawRate;
  auto v2 = solve_kinematics(spin, MotionMode::kSpin, g, KinematicsLimits{}, {}, yaw);
  ASSERT_TRUE(v2.ok());
  EXPECT_EQ(v2->command.spin_speed, 0.0) << "a yaw-rate chassis must not see a wheel speed";
  EXPECT_NEAR(v2->command.yaw_rate, 0.5, 1e-12);
  EXPECT_NEAR(twist_from_command(v2->command, MotionMode::kSpin, g, yaw).wz, 0.5, 1e-12);

  ProtocolProfile cw = manual_profile();
  cw.spin_sign = -1;
  auto reversed = solve_kinematics(spin, MotionMode::kSpin, g, KinematicsLimits{}, {}, cw);
  ASSERT_TRUE(reversed.ok());
  EXPECT_NEAR(reversed->command.spin_speed, -wheel, 1e-12);
  EXPECT_NEAR(reversed->achieved.wz, 0.5, 1e-12) << "the body still turns the way asked";
  EXPECT_NEAR(twist_from_command(reversed->command, MotionMode::kSpin, g, cw).wz, 0.5, 1e-12);
}

}  // namespace
}  // namespace ranger
