// The manual's open points as decided in interpretation.hpp: sign conversions and the Ackermann
// mean-angle reading with its inverse.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger::interpretation {
namespace {

constexpr double kL = 0.890, kW = 0.560;  // manual 1.1

// Independent reference: bisection on the forward function, which must be monotonic.
double curvature_by_bisection(double mean, double l, double w) {
  double lo = 0.0, hi = 1.0;
  while (ackermann_mean_front_angle(hi, l, w) < std::fabs(mean))
    hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ackermann_mean_front_angle(mid, l, w) < std::fabs(mean) ? lo : hi) = mid;
  }
  return std::copysign(0.5 * (lo + hi), mean);
}

TEST(Interpretation, SteeringSignsAreInvolutions) {
  EXPECT_EQ(rep103_from_manual_steering(0.3), -0.3);  // manual: positive = right
  EXPECT_EQ(manual_from_rep103_steering(rep103_from_manual_steering(0.25)), 0.25);
  EXPECT_EQ(rep103_from_manual_wheel_angle(-0.1), 0.1);
  EXPECT_EQ(manual_from_rep103_wheel_angle(rep103_from_manual_wheel_angle(0.7)), 0.7);
  // Open point 2: a 0x111 angle is read like 0x221's (a left turn in REP-103 is negative on the
  // wire, so the manual's 10 deg sample frame 03 E8 steers right).
  EXPECT_EQ(manual_from_rep103_command_steering(0.2), -0.2);
  EXPECT_EQ(rep103_from_manual_command_steering(manual_from_rep103_command_steering(0.2)), 0.2);
  EXPECT_EQ(kCommandSteeringSignVsRep103, kManualSteeringSignVsRep103);
}

TEST(Interpretation, SpinYawRateUsesTheWheelRadiusFromCentre) {
  const double r = std::hypot(kL / 2, kW / 2);
  EXPECT_DOUBLE_EQ(spin_yaw_rate_from_wheel_speed(1.0, kL, kW), 1.0 / r);
  EXPECT_DOUBLE_EQ(
      spin_wheel_speed_from_yaw_rate(spin_yaw_rate_from_wheel_speed(-0.4, kL, kW), kL, kW), -0.4);
}

TEST(Interpretation, MeanFrontAngleMatchesTheGeometry) {
  // R = 2 m to the left: tan(alpha) = 0.445 / 1.72, tan(beta) = 0.445 / 2.28.
  const double expected = (std::atan(0.445 / 1.72) + std::atan(0.445 / 2.28)) / 2;
  EXPECT_NEAR(ackermann_mean_front_angle(0.5, kL, kW), expected, 1e-15);
  EXPECT_NEAR(ackermann_mean_front_angle(-0.5, kL, kW), -expected, 1e-15);
  EXPECT_EQ(ackermann_mean_front_angle(0.0, kL, kW), 0.0);
  // Turning about the body centre: the front wheels stand at +-(90 deg -+ atan(L/W)) around 90.
  EXPECT_NEAR(ackermann_mean_front_angle(std::numeric_limits<double>::infinity(), kL, kW), M_PI / 2,
              1e-15);
}

TEST(Interpretation, MeanFrontAngleIsStrictlyMonotonic) {
  double previous = 0.0;
  for (double k = 1e-6; k < 1e6; k *= 1.05) {  // across R = W/2 where the inner wheel passes 90
    const double a = ackermann_mean_front_angle(k, kL, kW);
    EXPECT_GT(a, previous) << "k = " << k;
    EXPECT_LT(a, M_PI / 2);
    previous = a;
  }
}

TEST(Interpretation, CurvatureFromMeanAngleInvertsTheForwardFunction) {
  for (double deg = -89.99; deg <= 89.99; deg += 0.01) {
    const double m = deg * M_PI / 180;
    const double k = ackermann_curvature_from_mean_angle(m, kL, kW);
    ASSERT_TRUE(std::isfinite(k)) << deg;
    EXPECT_NEAR(ackermann_mean_front_angle(k, kL, kW), m, 1e-12) << deg;
    EXPECT_NEAR(k, curvature_by_bisection(m, kL, kW), 1e-9 * std::max(1.0, std::fabs(k))) << deg;
  }
  // Up to R = 10 um: beyond, the mean angle is pi/2 - O(1/k) and a double near pi/2 cannot carry
  // 1/k to nine digits any more (ill-conditioned, not inexact).
  for (double k = 1e-9; k < 1e5; k *= 1.3) {
    EXPECT_NEAR(ackermann_curvature_from_mean_angle(ackermann_mean_front_angle(k, kL, kW), kL, kW),
                k, 1e-9 * k)
        << k;
  }
}

TEST(Interpretation, CurvatureEdgeCases) {
  EXPECT_EQ(ackermann_curvature_from_mean_angle(0.0, kL, kW), 0.0);
  EXPECT_EQ(ackermann_curvature_from_mean_angle(M_PI / 2, kL, kW),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(ackermann_curvature_from_mean_angle(-2.0, kL, kW),
            -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(ackermann_curvature_from_mean_angle(std::nan(""), kL, kW)));
  EXPECT_TRUE(std::isnan(ackermann_curvature_from_mean_angle(0.1, 0.0, kW)));
  EXPECT_TRUE(std::isnan(ackermann_curvature_from_mean_angle(0.1, kL, -1.0)));
  EXPECT_TRUE(std::isnan(
      ackermann_curvature_from_mean_angle(0.1, std::numeric_limits<double>::infinity(), kW)));
  // Tiny angles keep full relative precision (no cancellation).
  const double tiny = 1e-12;
  EXPECT_NEAR(ackermann_curvature_from_mean_angle(tiny, kL, kW) * kL / 2, tiny, 1e-24);
}

// Points 7-9: which point's speed 0x111 and 0x221 carry.
TEST(Interpretation, CommandSpeedIsTheBodyCentreSpeed) {
  EXPECT_EQ(body_speed_from_command_speed(0.7, 1.2, kL, kW), 0.7);
  EXPECT_EQ(command_speed_from_body_speed(-0.4, -0.8, kL, kW), -0.4);
}

TEST(Interpretation, AckermannFeedbackSpeedIsTheMeanWheelSpeed) {
  // Independent reference: the four wheels' rigid-body speeds at (+-L/2, +-W/2).
  const double k = 0.9, vx = 0.6;
  double mean = 0.0;
  for (double x : {kL / 2, -kL / 2}) {
    for (double y : {kW / 2, -kW / 2})
      mean += std::hypot(vx - k * vx * y, k * vx * x) / 4;
  }
  EXPECT_NEAR(ackermann_feedback_speed_from_body_speed(vx, k, kL, kW), mean, 1e-15);
  EXPECT_NEAR(ackermann_body_speed_from_feedback_speed(mean, k, kL, kW), vx, 1e-15);
  EXPECT_NEAR(ackermann_body_speed_from_feedback_speed(-mean, -k, kL, kW), -vx, 1e-15);
  EXPECT_EQ(ackermann_mean_wheel_speed_factor(0.0, kL, kW), 1.0);  // straight: all alike
  // A corrupt 90-degree angle (infinite curvature) leaves the body centre at rest, never NaN.
  EXPECT_EQ(ackermann_body_speed_from_feedback_speed(0.5, std::numeric_limits<double>::infinity(),
                                                     kL, kW),
            0.0);
}

TEST(Interpretation, SpinFeedbackSpeedIsTheSignedTangentialSpeed) {
  const double r = std::hypot(kL / 2, kW / 2);
  EXPECT_DOUBLE_EQ(spin_yaw_rate_from_feedback_speed(0.5, kL, kW), 0.5 / r);  // CCW positive
  EXPECT_DOUBLE_EQ(spin_feedback_speed_from_yaw_rate(-1.0, kL, kW), -r);
}

}  // namespace
}  // namespace ranger::interpretation
