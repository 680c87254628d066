// Odometry: closed loops from synthetic per-wheel feedback built from rigid-body motion, sent as
// real (quantised) CAN frames (support/synthetic_feedback); flipped-wheel equivalence; per-wheel
// vs 0x221 agreement; time handling; covariance.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "support/synthetic_feedback.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;
namespace interp = ranger::interpretation;

constexpr double kDeg = M_PI / 180.0;
// Stamp 0 means "no timestamp" (candump lines without one), so runs start later.
constexpr Timestamp kStart = std::chrono::seconds(1);

using test::motion_feedback_from_wheels;

// Feeds one 20 ms feedback cycle as encoded frames, the order the chassis sends them.
struct Chassis {
  VehicleGeometry geometry;
  MotionMode mode = MotionMode::kAckermann;
  bool send_angles = true;
  int flip_wheel = -1;  // report this wheel turned by 180 deg with negated speed

  void feed(Odometry& odom, const BodyTwist& twist, Timestamp t) const {
    test::FeedbackOptions options;
    options.steering_angles = send_angles;
    options.flip_wheel = flip_wheel;
    for (const CanFrame& f : test::feedback_frames(twist, mode, geometry, t, options)) {
      odom.on_frame(f);
    }
  }

  // Drives `twist` for `duration` in 20 ms cycles from t0; the last cycle is shortened so that
  // exactly `duration` is integrated. Returns the end time.
  Timestamp drive(Odometry& odom, const BodyTwist& twist, Timestamp t0,
                  std::chrono::nanoseconds duration) const {
    Timestamp t = t0;
    feed(odom, twist, t);
    while (t < t0 + duration) {
      t = std::min(t + 20ms, t0 + duration);
      feed(odom, twist, t);
    }
    return t;
  }
};

std::chrono::nanoseconds seconds_ns(double s) {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(s * 1e9)));
}

double angle_diff(double a, double b) {
  return std::remainder(a - b, 2 * M_PI);
}

// ---- closed loops ------------------------------------------------------------------------------

TEST(OdometryClosedLoop, TwoFullSpinsReturnYawWithinHalfADegree) {
  for (OdometrySource source : {OdometrySource::kWheels, OdometrySource::kMotion}) {
    SCOPED_TRACE(std::string(to_string(source)));
    OdometryConfig cfg;
    cfg.source = source;
    Odometry odom(cfg);
    Chassis chassis;
    chassis.mode = MotionMode::kSpin;
    // 0.5 m/s wheel speed: exact on the wire (500 mm/s).
    const double wz =
        interp::spin_yaw_rate_from_wheel_speed(0.5, cfg.geometry.wheelbase, cfg.geometry.track);
    chassis.drive(odom, {0, 0, wz}, kStart, seconds_ns(4 * M_PI / wz));
    const OdometryState& s = odom.state();
    EXPECT_LT(std::fabs(angle_diff(s.pose.yaw, 0.0)), 0.5 * kDeg) << s.pose.yaw;
    EXPECT_LT(std::hypot(s.pose.x, s.pose.y), 1e-3);
    EXPECT_NEAR(s.twist.wz, wz, 1e-3);
  }
}

TEST(OdometryClosedLoop, AckermannCircleClosesWithinHalfAPercentOfItsLength) {
  for (OdometrySource source : {OdometrySource::kWheels, OdometrySource::kMotion}) {
    SCOPED_TRACE(std::string(to_string(source)));
    OdometryConfig cfg;
    cfg.source = source;
    Odometry odom(cfg);
    Chassis chassis;
    const double radius = 2.0, speed = 0.8;
    const double length = 2 * M_PI * radius;
    chassis.drive(odom, {speed, 0, speed / radius}, kStart, seconds_ns(length / speed));
    const OdometryState& s = odom.state();
    EXPECT_LT(std::hypot(s.pose.x, s.pose.y), 0.005 * length)
        << "end (" << s.pose.x << ", " << s.pose.y << ")";
    EXPECT_NEAR(s.distance, length, 0.005 * length);
    EXPECT_LT(std::fabs(angle_diff(s.pose.yaw, 0.0)), 0.5 * kDeg);
    // Half-way round the circle (left turn) the body is at (0, 2R).
  }
}

TEST(OdometryClosedLoop, HalfCircleLeftEndsAtTwiceTheRadiusToTheLeft) {
  Odometry odom;
  Chassis chassis;
  const double radius = 1.5, speed = 0.5;
  chassis.drive(odom, {speed, 0, speed / radius}, kStart, seconds_ns(M_PI * radius / speed));
  EXPECT_NEAR(odom.state().pose.x, 0.0, 0.01);
  EXPECT_NEAR(odom.state().pose.y, 2 * radius, 0.01);
  EXPECT_NEAR(std::fabs(odom.state().pose.yaw), M_PI, 0.5 * kDeg);
}

TEST(OdometryClosedLoop, CrabAt30DegreesEndsWhereExpected) {
  for (OdometrySource source : {OdometrySource::kWheels, OdometrySource::kMotion}) {
    SCOPED_TRACE(std::string(to_string(source)));
    OdometryConfig cfg;
    cfg.source = source;
    Odometry odom(cfg);
    Chassis chassis;
    chassis.mode = MotionMode::kOblique;
    const double speed = 0.5, seconds = 4.0;
    chassis.drive(odom, {speed * std::cos(30 * kDeg), speed * std::sin(30 * kDeg), 0}, kStart,
                  seconds_ns(seconds));
    const OdometryState& s = odom.state();
    EXPECT_NEAR(s.pose.x, 2.0 * std::cos(30 * kDeg), 0.005);
    EXPECT_NEAR(s.pose.y, 2.0 * std::sin(30 * kDeg), 0.005);
    EXPECT_NEAR(s.pose.yaw, 0.0, 1e-6);
  }
}

TEST(OdometryClosedLoop, ReverseCrabAndReverseAckermann) {
  Odometry odom;
  Chassis chassis;
  chassis.mode = MotionMode::kOblique;
  Timestamp t = chassis.drive(odom, {-0.3, -0.4, 0}, kStart, 2s);  // 1 m backwards-right
  EXPECT_NEAR(odom.state().pose.x, -0.6, 0.005);
  EXPECT_NEAR(odom.state().pose.y, -0.8, 0.005);
  chassis.mode = MotionMode::kAckermann;
  odom.reset();
  chassis.drive(odom, {-0.5, 0, 0.25}, t + 1s, 4s);  // reversing, yaw grows CCW
  EXPECT_NEAR(odom.state().pose.yaw, 1.0, 0.01);
  EXPECT_LT(odom.state().pose.x, 0.0);
}

// ---- per-wheel fit properties -------------------------------------------------------------------

TEST(OdometryFit, RecoversRigidBodyTwistsExactly) {
  const VehicleGeometry g;
  const BodyTwist twists[] = {{1, 0, 0}, {0, 0, 1}, {0.5, 0.2, 0}, {0.7, 0, 0.4}, {0.3, -0.2, 0.5}};
  for (const BodyTwist& t : twists) {
    const BodyTwist fit = fit_body_twist(wheel_states_from_twist(t, g), g);
    EXPECT_NEAR(fit.vx, t.vx, 1e-12);
    EXPECT_NEAR(fit.vy, t.vy, 1e-12);
    EXPECT_NEAR(fit.wz, t.wz, 1e-12);
  }
}

TEST(OdometryFit, AWheelFlippedBy180DegreesWithNegatedSpeedGivesTheSameTwist) {
  const VehicleGeometry g;
  const BodyTwist t{0.6, 0, 0.5};
  const WheelStates w = wheel_states_from_twist(t, g);
  for (int i = 0; i < kWheelCount; ++i) {
    WheelStates flipped = w;
    flipped[i].angle += M_PI;
    flipped[i].speed = -flipped[i].speed;
    const BodyTwist a = fit_body_twist(w, g), b = fit_body_twist(flipped, g);
    EXPECT_NEAR(a.vx, b.vx, 1e-12);
    EXPECT_NEAR(a.vy, b.vy, 1e-12);
    EXPECT_NEAR(a.wz, b.wz, 1e-12);
  }
}

TEST(OdometryFit, FlippedWheelOnTheWireGivesTheSamePose) {
  Chassis plain, flipped;
  flipped.flip_wheel = kLeftRear;
  Odometry a, b;
  plain.drive(a, {0.5, 0, 0.3}, kStart, 3s);
  flipped.drive(b, {0.5, 0, 0.3}, kStart, 3s);
  EXPECT_NEAR(a.state().pose.x, b.state().pose.x, 1e-4);
  EXPECT_NEAR(a.state().pose.y, b.state().pose.y, 1e-4);
  EXPECT_NEAR(a.state().pose.yaw, b.state().pose.yaw, 1e-4);
}

TEST(OdometryFit, PerWheelAndMotionFeedbackAgreeOnCleanData) {
  const VehicleGeometry g;
  struct Case {
    BodyTwist t;
    MotionMode mode;
  } cases[] = {{{0.8, 0, 0.4}, MotionMode::kAckermann}, {{-0.5, 0, 0.6}, MotionMode::kAckermann},
               {{1.0, 0, 0}, MotionMode::kAckermann},   {{0.3, 0.4, 0}, MotionMode::kOblique},
               {{-0.3, 0.4, 0}, MotionMode::kOblique},  {{0, 0, 0.8}, MotionMode::kSpin},
               {{0, 0, -0.8}, MotionMode::kSpin}};
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << protocol::to_string(c.mode) << " (" << c.t.vx << ", "
                                    << c.t.vy << ", " << c.t.wz << ")");
    const WheelStates w = wheel_states_from_twist(c.t, g);
    const BodyTwist from_wheels = fit_body_twist(w, g);
    const BodyTwist from_motion =
        twist_from_motion_feedback(motion_feedback_from_wheels(w, c.mode, g), c.mode, g);
    EXPECT_NEAR(from_wheels.vx, from_motion.vx, 1e-6);
    EXPECT_NEAR(from_wheels.vy, from_motion.vy, 1e-6);
    EXPECT_NEAR(from_wheels.wz, from_motion.wz, 1e-6);
  }
  // And through whole runs with quantised frames.
  OdometryConfig wheels_cfg, motion_cfg;
  motion_cfg.source = OdometrySource::kMotion;
  Odometry by_wheels(wheels_cfg), by_motion(motion_cfg);
  Chassis chassis;
  chassis.drive(by_wheels, {0.9, 0, 0.5}, kStart, 5s);
  chassis.drive(by_motion, {0.9, 0, 0.5}, kStart, 5s);
  const double d = std::hypot(by_wheels.state().pose.x - by_motion.state().pose.x,
                              by_wheels.state().pose.y - by_motion.state().pose.y);
  EXPECT_LT(d, 0.005 * by_wheels.state().distance);
  EXPECT_EQ(by_wheels.state().active_source, OdometrySource::kWheels);
  EXPECT_EQ(by_motion.state().active_source, OdometrySource::kMotion);
}

// ---- fallback and time handling
// ------------------------------------------------------------------

TEST(OdometryFallback, MissingSteeringAnglesFallBackToMotionFeedbackAndBack) {
  Odometry odom;
  Chassis chassis;
  chassis.send_angles = false;  // 0x271 missing: the fit cannot run
  Timestamp t = chassis.drive(odom, {0.5, 0, 0}, kStart, 2s);
  EXPECT_NEAR(odom.state().pose.x, 1.0, 0.005);
  EXPECT_GT(odom.state().fallback_steps, 90u);
  EXPECT_EQ(odom.state().active_source, OdometrySource::kMotion);
  chassis.send_angles = true;
  const auto fallback_before = odom.state().fallback_steps;
  chassis.drive(odom, {0.5, 0, 0}, t + 20ms, 2s);
  EXPECT_NEAR(odom.state().pose.x, 2.01, 0.01);
  EXPECT_EQ(odom.state().active_source, OdometrySource::kWheels);
  EXPECT_LE(odom.state().fallback_steps - fallback_before, 1u);
}

TEST(OdometryTime, FirstFrameBackwardsJumpsAndLongGapsAreNotIntegrated) {
  Odometry odom;
  Chassis chassis;
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{5s});
  EXPECT_EQ(odom.state().steps, 0u);  // first frame only anchors
  EXPECT_DOUBLE_EQ(odom.state().pose.x, 0.0);
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{5s + 20ms});
  EXPECT_NEAR(odom.state().pose.x, 0.02, 1e-9);
  // A 10 s gap at 1 m/s must not add 10 m.
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{15s});
  EXPECT_NEAR(odom.state().pose.x, 0.02, 1e-9);
  // Backwards in time: re-anchored, not integrated.
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{3s});
  EXPECT_NEAR(odom.state().pose.x, 0.02, 1e-9);
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{3s + 20ms});
  EXPECT_NEAR(odom.state().pose.x, 0.04, 1e-9);
  EXPECT_GE(odom.state().skipped_steps, 3u);
  // Frames without a timestamp are never integrated.
  chassis.feed(odom, {1.0, 0, 0}, Timestamp{0});
  EXPECT_NEAR(odom.state().pose.x, 0.04, 1e-9);
}

// A gap in the feedback (longer than max_step) is not integrated, but not forgotten either: the
// pose variance grows by what the chassis could have moved in it at its limits, and the state
// says how long it was. An interval up to max_step is integrated and is no gap.
TEST(OdometryTime, AGapGrowsTheCovarianceByWhatTheChassisCouldHaveMovedAndIsSaid) {
  OdometryConfig cfg;
  cfg.limits.max_linear_speed = 1.2;
  Odometry odom(cfg);
  Chassis chassis;
  Timestamp t = chassis.drive(odom, {0.5, 0, 0}, Timestamp{5s}, 1s);
  t = chassis.drive(odom, {0.5, 0, 0}, t + 400ms, 100ms);  // 400 ms: integrated
  EXPECT_EQ(odom.state().gaps, 0u);
  EXPECT_EQ(odom.state().last_gap, 0ns);
  const OdometryState before = odom.state();
  chassis.feed(odom, {0.5, 0, 0}, t + 2s);
  const OdometryState& after = odom.state();
  EXPECT_EQ(after.gaps, 1u);
  EXPECT_EQ(after.last_gap, 2s);
  EXPECT_EQ(after.last_gap_end, t + 2s);
  EXPECT_DOUBLE_EQ(after.pose.x, before.pose.x) << "a gap is not integrated";
  const double reach = 1.2 * 2.0;
  EXPECT_NEAR(after.pose_variance[0] - before.pose_variance[0], reach * reach, 1e-9);
  EXPECT_NEAR(after.pose_variance[1] - before.pose_variance[1], reach * reach, 1e-9);
  const double turn = std::min(max_yaw_rate(cfg.limits, cfg.geometry) * 2.0, M_PI);
  EXPECT_NEAR(after.pose_variance[2] - before.pose_variance[2], turn * turn, 1e-9);
  // The fastest turn is a spin at the wheel-speed limit or full lock at full speed.
  const double spin = interp::spin_yaw_rate_from_wheel_speed(
      cfg.limits.max_spin_wheel_speed, cfg.geometry.wheelbase, cfg.geometry.track);
  EXPECT_GE(max_yaw_rate(cfg.limits, cfg.geometry), spin);
  // Integration goes on after it.
  chassis.drive(odom, {0.5, 0, 0}, t + 2s, 1s);
  EXPECT_NEAR(odom.state().pose.x - before.pose.x, 0.5, 0.01);
  EXPECT_EQ(odom.state().gaps, 1u);
}

// Where the chassis counts its wheels' distance in metres (the RANGER MINI 3.0's 0x311), what it
// counted across a gap advances the pose along the motion before the gap, straight or on an arc;
// a reading of no stated unit (the vendor's 0x311) adds nothing.
TEST(OdometryTime, TheChassissOwnOdometerBridgesAGapAlongTheMotionBeforeIt) {
  for (const double wz : {0.0, 0.2}) {
    Odometry odom;
    Chassis chassis;
    const BodyTwist twist{0.5, 0, wz};
    OdometerFeedback odometer;
    odometer.left_distance = odometer.right_distance = 1.0;
    const Timestamp t = chassis.drive(odom, twist, Timestamp{5s}, 1s);
    EXPECT_FALSE(odom.on_message(odometer, t));  // the first reading only anchors
    const Pose2D before = odom.state().pose;
    chassis.feed(odom, twist, t + 2s);  // 2 s of silence, in which the wheels rolled 0.3 m
    odometer.left_distance = odometer.right_distance = 1.3;
    EXPECT_TRUE(odom.on_message(odometer, t + 2s)) << "wz " << wz;
    EXPECT_NEAR(odom.state().last_gap_odometer_distance, 0.3, 1e-9);
    const Pose2D expected = integrate_pose(before, twist, 0.3 / 0.5);
    EXPECT_NEAR(odom.state().pose.x, expected.x, 2e-3) << "wz " << wz;
    EXPECT_NEAR(odom.state().pose.y, expected.y, 2e-3) << "wz " << wz;
    EXPECT_NEAR(odom.state().pose.yaw, expected.yaw, 2e-3) << "wz " << wz;
    EXPECT_EQ(odom.state().gaps, 1u);
    const auto variance = odom.state().pose_variance[0];  // the gap's stays: the path is unknown
    EXPECT_GT(variance, 1.0);
  }
  Odometry odom;
  Chassis chassis;
  OdometerFeedback no_unit;
  no_unit.left_wheel = no_unit.right_wheel = 1000;
  const Timestamp t = chassis.drive(odom, {0.5, 0, 0}, Timestamp{5s}, 1s);
  odom.on_message(no_unit, t);
  chassis.feed(odom, {0.5, 0, 0}, t + 2s);
  const double x = odom.state().pose.x;
  no_unit.left_wheel = no_unit.right_wheel = 1300;
  EXPECT_FALSE(odom.on_message(no_unit, t + 2s));
  EXPECT_DOUBLE_EQ(odom.state().pose.x, x);
  EXPECT_EQ(odom.state().last_gap_odometer_distance, 0.0);
}

// Odometer frames missing while the motion frames keep coming: the pose already holds the
// distance, nothing is added twice.
TEST(OdometryTime, AnOdometerGapWithoutAMotionGapAddsNothing) {
  Odometry odom;
  Chassis chassis;
  OdometerFeedback odometer;
  odometer.left_distance = odometer.right_distance = 1.0;
  Timestamp t = chassis.drive(odom, {0.5, 0, 0}, Timestamp{5s}, 1s);
  odom.on_message(odometer, t);
  t = chassis.drive(odom, {0.5, 0, 0}, t + 20ms, 2s);  // 2 s of motion frames, no 0x311
  const double x = odom.state().pose.x;
  odometer.left_distance = odometer.right_distance = 2.0;
  EXPECT_FALSE(odom.on_message(odometer, t));
  EXPECT_DOUBLE_EQ(odom.state().pose.x, x);
  EXPECT_EQ(odom.state().gaps, 0u);
  EXPECT_EQ(odom.state().last_gap_odometer_distance, 0.0);
}

TEST(OdometryRobustness, AbsurdSteeringOnTheWireNeverPoisonsThePose) {
  // 0x221 steering of 120 deg in Ackermann mode is outside the protocol but encodable.
  Odometry odom(OdometryConfig{{}, OdometrySource::kMotion});
  for (int i = 0; i < 10; ++i) {
    MotionFeedback fb;
    fb.speed = 0.5;
    fb.steering_angle = 120 * kDeg;
    odom.on_motion_feedback(fb, kStart + i * 20ms);
    fb.steering_angle = -200 * kDeg;
    odom.on_motion_feedback(fb, kStart + i * 20ms + 10ms);
  }
  EXPECT_TRUE(std::isfinite(odom.state().pose.x));
  EXPECT_TRUE(std::isfinite(odom.state().pose.y));
  EXPECT_TRUE(std::isfinite(odom.state().pose.yaw));
  EXPECT_TRUE(std::isfinite(odom.state().twist.wz));
}

TEST(OdometryIntegration, ExactArc) {
  const Pose2D p = integrate_pose({}, {1.0, 0, M_PI / 2}, 1.0);  // quarter circle, R = 2/pi
  EXPECT_NEAR(p.x, 2 / M_PI, 1e-12);
  EXPECT_NEAR(p.y, 2 / M_PI, 1e-12);
  EXPECT_NEAR(p.yaw, M_PI / 2, 1e-12);
  // Crab while rotated: body (0, 1) at yaw 90 deg moves along world -x.
  const Pose2D q = integrate_pose({1, 1, M_PI / 2}, {0, 1.0, 0}, 2.0);
  EXPECT_NEAR(q.x, -1.0, 1e-12);
  EXPECT_NEAR(q.y, 1.0, 1e-12);
  // Tiny rotation: continuous with the straight line.
  const Pose2D r = integrate_pose({}, {1.0, 0.5, 1e-9}, 1.0);
  EXPECT_NEAR(r.x, 1.0, 1e-9);
  EXPECT_NEAR(r.y, 0.5, 1e-9);
  // Yaw stays normalised.
  EXPECT_NEAR(integrate_pose({0, 0, 3.0}, {0, 0, 1.0}, 1.0).yaw, 4.0 - 2 * M_PI, 1e-12);
}

TEST(OdometryCovariance, GrowsWithDistanceAndResets) {
  OdometryConfig cfg;
  Odometry odom(cfg);
  EXPECT_DOUBLE_EQ(odom.state().pose_variance[0], cfg.initial_pose_variance_xy);
  EXPECT_DOUBLE_EQ(odom.state().twist_variance[2], cfg.twist_variance_angular);
  Chassis chassis;
  chassis.drive(odom, {1.0, 0, 0}, kStart, 2s);
  const double expected = cfg.initial_pose_variance_xy + cfg.pose_variance_per_meter * 2.0;
  EXPECT_NEAR(odom.state().pose_variance[0], expected, 1e-6);
  EXPECT_GT(odom.state().pose_variance[2], cfg.initial_pose_variance_yaw);
  odom.reset({1, 2, 3});
  EXPECT_DOUBLE_EQ(odom.state().pose.x, 1);
  EXPECT_DOUBLE_EQ(odom.state().pose.yaw, 3);
  EXPECT_DOUBLE_EQ(odom.state().pose_variance[0], cfg.initial_pose_variance_xy);
  EXPECT_EQ(odom.state().steps, 0u);
}

TEST(OdometryConfig, ValidationAndSourceNames) {
  OdometryConfig cfg;
  EXPECT_TRUE(cfg.validate().ok());
  cfg.pose_variance_per_meter = -1;
  EXPECT_FALSE(cfg.validate().ok());
  cfg = OdometryConfig{};
  cfg.geometry.track = 0;
  EXPECT_FALSE(cfg.validate().ok());
  EXPECT_EQ(*parse_odometry_source("motion"), OdometrySource::kMotion);
  EXPECT_EQ(*parse_odometry_source("wheels"), OdometrySource::kWheels);
  EXPECT_FALSE(parse_odometry_source("imu").ok());
}

}  // namespace
}  // namespace ranger

// ---- protocol profiles: the chassis's readings of 0x221 ---------------------------

namespace ranger {
namespace {

TEST(OdometryProfile, TheFallbackReadsTheFeedbackInTheProfilesReadings) {
  const VehicleGeometry g;
  const double k = 0.5;  // a 2 m turn to the left at 0.5 m/s (body centre)
  const double vx = 0.5;
  const double mean_speed =
      interpretation::ackermann_feedback_speed_from_body_speed(vx, k, g.wheelbase, g.track);
  MotionFeedback fb;
  // Mean-wheel speed and mean angle (the manual preset).
  fb.speed = mean_speed;
  fb.steering_angle = interpretation::manual_from_rep103_steering(
      interpretation::ackermann_mean_front_angle(k, g.wheelbase, g.track));
  BodyTwist t = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g);
  EXPECT_NEAR(t.vx, vx, 1e-9);
  EXPECT_NEAR(t.wz, k * vx, 1e-9);
  // Body-centre speed and the inner wheel's angle.
  ProtocolProfile p = manual_profile();
  p.steering_reference = SteeringReference::kInnerFront;
  p.feedback_speed = FeedbackSpeed::kBodyCentre;
  fb.speed = vx;
  fb.steering_angle = interpretation::manual_from_rep103_steering(
      interpretation::ackermann_inner_front_angle(k, g.wheelbase, g.track));
  t = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g, p);
  EXPECT_NEAR(t.vx, vx, 1e-9);
  EXPECT_NEAR(t.wz, k * vx, 1e-9);
  // The same frame read the manual's way would be wrong: the readings matter.
  t = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g);
  EXPECT_GT(std::fabs(t.wz - k * vx), 0.01);
}

TEST(OdometryProfile, SpinFeedbackFromTheYawRateFieldAndTheSign) {
  const VehicleGeometry g;
  MotionFeedback fb;
  fb.yaw_rate = 0.4;
  ProtocolProfile yaw = manual_profile();
  yaw.spin_field = SpinField::kYawRate;
  EXPECT_NEAR(twist_from_motion_feedback(fb, protocol::MotionMode::kSpin, g, yaw).wz, 0.4, 1e-12);
  yaw.spin_sign = -1;
  EXPECT_NEAR(twist_from_motion_feedback(fb, protocol::MotionMode::kSpin, g, yaw).wz, -0.4, 1e-12);
  MotionFeedback wheel;
  wheel.speed = 0.3;
  ProtocolProfile cw = manual_profile();
  cw.spin_sign = -1;
  EXPECT_NEAR(twist_from_motion_feedback(wheel, protocol::MotionMode::kSpin, g, cw).wz,
              -0.3 / std::hypot(g.wheelbase / 2, g.track / 2), 1e-12);
}

// A silence the chassis's own odometer bridges (0x311 counted what its wheels rolled): the distance
// goes along the path the driver's commands in the silence make, the steering turning toward what
// they asked at limits.steering_rate (Odometry::on_command), not along the last curve; without
// commands (a log without the host's frames), along the last curve.
double yaw_across_a_silence(bool with_commands) {
  OdometryConfig c;
  c.source = OdometrySource::kMotion;
  c.profile = *protocol_preset("mini_v3");  // 0x311 in mm
  c.limits.steering_rate = 3.26;            // rad/s, the field's
  Odometry odometry(c);
  const double speed = 0.5, angle = 0.15;  // m/s; rad, REP-103 (left)
  MotionFeedback arc;
  arc.speed = speed;
  arc.steering_angle = interp::manual_from_rep103_steering(angle);
  MotionCommand asked;
  asked.linear_speed = speed;
  asked.steering_angle = interp::manual_from_rep103_command_steering(angle);
  Timestamp t = kStart;
  double counted = 0.0;
  const auto odometer = [&](double m, Timestamp at) {
    OdometerFeedback o;
    o.left_distance = o.right_distance = m;
    odometry.on_odometer(o, at);
  };
  for (int i = 0; i < 50; ++i) {
    if (with_commands) odometry.on_command(asked, t);
    odometry.on_motion_feedback(arc, t);
    odometer(counted, t);
    counted += speed * 0.02;
    t += 20ms;
  }
  counted -= speed * 0.02;  // what the last 0x311 said
  const Timestamp silence = t - 20ms;
  const double yaw_before = odometry.state().pose.yaw;
  // The arc asked for 0.1 s more (the driver had not yet seen the link go), then a stop with the
  // wheels straight.
  if (with_commands) {
    for (auto s = 20ms; s <= 2000ms; s += 20ms)
      odometry.on_command(s <= 100ms ? asked : MotionCommand{}, silence + s);
  }
  odometer(counted + 0.11, silence + 2s);  // it coasted 0.11 m
  EXPECT_NEAR(odometry.state().last_gap_odometer_distance, 0.11, 1e-6);
  return odometry.state().pose.yaw - yaw_before;
}

TEST(OdometryGap, TheOdometersDistanceFollowsTheCommandsNotTheLastCurve) {
  const double last_curve = yaw_across_a_silence(false);
  const double commanded = yaw_across_a_silence(true);
  EXPECT_GT(last_curve, 0.0);
  // 0.06 m at the arc's curvature (0.12 s until the stop's first command), then the wheels
  // straighten in 46 ms while it brakes the rest: about two thirds of the last curve's turn.
  EXPECT_GT(commanded, 0.55 * last_curve);
  EXPECT_LT(commanded, 0.75 * last_curve);
}

}  // namespace
}  // namespace ranger
