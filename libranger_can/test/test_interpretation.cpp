// The manual's open points and field interpretations as decided in interpretation.hpp: sign
// conversions, both Ackermann steering references with their inverses, both readings of the
// 0x221 speed, the critical set, ultrasonic "no reading", the BMS current and spin signs, the
// pack facts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/vehicle_spec.hpp"

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

// ---- Point 6, the inner-front-wheel reading
// ------------------------------------------------------

double inner_curvature_by_bisection(double inner, double l, double w) {
  double lo = 0.0, hi = 1.0;
  while (ackermann_inner_front_angle(hi, l, w) < std::fabs(inner))
    hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ackermann_inner_front_angle(mid, l, w) < std::fabs(inner) ? lo : hi) = mid;
  }
  return std::copysign(0.5 * (lo + hi), inner);
}

TEST(Interpretation, InnerFrontAngleMatchesTheGeometry) {
  // R = 2 m to the left: the inner (left) front wheel at tan = 0.445 / 1.72.
  EXPECT_NEAR(ackermann_inner_front_angle(0.5, kL, kW), std::atan(0.445 / 1.72), 1e-15);
  EXPECT_NEAR(ackermann_inner_front_angle(-0.5, kL, kW), -std::atan(0.445 / 1.72), 1e-15);
  EXPECT_EQ(ackermann_inner_front_angle(0.0, kL, kW), 0.0);
  // R = W/2: the inner wheel stands across the body; |k| = inf: pi - atan(L/W), about 122 deg.
  EXPECT_NEAR(ackermann_inner_front_angle(2.0 / kW, kL, kW), M_PI / 2, 1e-15);
  EXPECT_NEAR(ackermann_inner_front_angle(-std::numeric_limits<double>::infinity(), kL, kW),
              -(M_PI - std::atan(kL / kW)), 1e-15);
  // It is larger than the mean for every turn (the outer wheel turns less).
  for (double k = 0.01; k < 100; k *= 1.5)
    EXPECT_GT(ackermann_inner_front_angle(k, kL, kW), ackermann_mean_front_angle(k, kL, kW));
}

TEST(Interpretation, CurvatureFromInnerAngleInvertsTheForwardFunction) {
  const double limit_deg = (M_PI - std::atan(kL / kW)) * 180 / M_PI;
  for (double deg = -limit_deg + 0.01; deg < limit_deg - 0.01; deg += 0.01) {
    const double a = deg * M_PI / 180;
    const double k = ackermann_curvature_from_inner_angle(a, kL, kW);
    ASSERT_TRUE(std::isfinite(k)) << deg;
    EXPECT_NEAR(ackermann_inner_front_angle(k, kL, kW), a, 1e-12) << deg;
    EXPECT_NEAR(k, inner_curvature_by_bisection(a, kL, kW), 1e-9 * std::max(1.0, std::fabs(k)))
        << deg;
  }
  for (double k = 1e-9; k < 1e5; k *= 1.3) {
    EXPECT_NEAR(
        ackermann_curvature_from_inner_angle(ackermann_inner_front_angle(k, kL, kW), kL, kW), k,
        1e-9 * k)
        << k;
  }
  EXPECT_EQ(ackermann_curvature_from_inner_angle(0.0, kL, kW), 0.0);
  EXPECT_EQ(ackermann_curvature_from_inner_angle(std::atan2(kL / 2, -kW / 2), kL, kW),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(ackermann_curvature_from_inner_angle(-3.0, kL, kW),
            -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(ackermann_curvature_from_inner_angle(std::nan(""), kL, kW)));
  EXPECT_TRUE(std::isnan(ackermann_curvature_from_inner_angle(0.1, kL, 0.0)));
  const double tiny = 1e-12;
  EXPECT_NEAR(ackermann_curvature_from_inner_angle(tiny, kL, kW) * kL / 2, tiny, 1e-24);
}

TEST(Interpretation, FrontAngleFollowsTheSteeringReference) {
  for (double k : {-1.5, -0.2, 0.0, 0.3, 2.0}) {
    EXPECT_EQ(ackermann_front_angle(k, kL, kW, SteeringReference::kMeanFront),
              ackermann_mean_front_angle(k, kL, kW));
    EXPECT_EQ(ackermann_front_angle(k, kL, kW, SteeringReference::kInnerFront),
              ackermann_inner_front_angle(k, kL, kW));
    for (auto ref : {SteeringReference::kMeanFront, SteeringReference::kInnerFront}) {
      EXPECT_NEAR(
          ackermann_curvature_from_front_angle(ackermann_front_angle(k, kL, kW, ref), kL, kW, ref),
          k, 1e-12);
    }
  }
  // The two readings of the same 20 deg differ by about 10 % of the turn rate (PROTOCOL.md).
  const double a = 20 * M_PI / 180;
  const double k_mean =
      ackermann_curvature_from_front_angle(a, kL, kW, SteeringReference::kMeanFront);
  const double k_inner =
      ackermann_curvature_from_front_angle(a, kL, kW, SteeringReference::kInnerFront);
  EXPECT_GT(k_mean / k_inner, 1.05);
  EXPECT_LT(k_mean / k_inner, 1.2);
}

// ---- Point 8 by the profile's feedback_speed
// --------------------------------------------------------

TEST(Interpretation, FeedbackSpeedReadings) {
  const double k = 0.9;
  EXPECT_EQ(ackermann_body_speed_from_feedback_speed(0.6, k, kL, kW, FeedbackSpeed::kMeanWheel),
            ackermann_body_speed_from_feedback_speed(0.6, k, kL, kW));
  EXPECT_EQ(ackermann_feedback_speed_from_body_speed(0.6, k, kL, kW, FeedbackSpeed::kMeanWheel),
            ackermann_feedback_speed_from_body_speed(0.6, k, kL, kW));
  EXPECT_EQ(ackermann_body_speed_from_feedback_speed(0.6, k, kL, kW, FeedbackSpeed::kBodyCentre),
            0.6);
  EXPECT_EQ(ackermann_feedback_speed_from_body_speed(-0.6, k, kL, kW, FeedbackSpeed::kBodyCentre),
            -0.6);
  EXPECT_LT(ackermann_body_speed_from_feedback_speed(0.6, k, kL, kW, FeedbackSpeed::kMeanWheel),
            0.6);
}

// ---- Field interpretations ----------------------------------------------------------------------

TEST(Interpretation, ImpossibleSteeringLimit) {
  EXPECT_DOUBLE_EQ(kMaxPlausibleSteeringRad * 180 / M_PI, 100.0);
  EXPECT_GT(kMaxPlausibleSteeringRad, M_PI / 2) << "oblique mode's 90 deg is possible";
}

TEST(Interpretation, UltrasonicZeroIsNoReading) {
  EXPECT_EQ(kUltrasonicNoReading, 0);
  EXPECT_FALSE(ultrasonic_distance_m(0).has_value());
  EXPECT_FALSE(ultrasonic_distance_m(-1).has_value());
  EXPECT_FALSE(ultrasonic_distance_m(-32768).has_value());
  EXPECT_DOUBLE_EQ(*ultrasonic_distance_m(1), 0.001);
  EXPECT_DOUBLE_EQ(*ultrasonic_distance_m(1200), 1.2);
}

TEST(Interpretation, BmsCurrentSignFromTheProfile) {
  ProtocolProfile p;  // manual: charge positive
  EXPECT_EQ(bms_discharge_current(-3.2, p), 3.2);
  EXPECT_EQ(bms_wire_current(bms_discharge_current(-3.2, p), p), -3.2);
  p.bms_current_sign = +1;
  EXPECT_EQ(bms_discharge_current(-3.2, p), -3.2);
}

TEST(Interpretation, SpinSignFromTheProfile) {
  ProtocolProfile p;
  EXPECT_EQ(spin_ccw_from_wire(0.4, p), 0.4);
  p.spin_sign = -1;
  EXPECT_EQ(spin_ccw_from_wire(0.4, p), -0.4);
  EXPECT_EQ(spin_wire_from_ccw(spin_ccw_from_wire(0.4, p), p), 0.4);
}

TEST(Interpretation, CriticalMaskPerLayout) {
  for (const auto layout : {ErrorWordLayout::kManual32, ErrorWordLayout::kAgxV2_16}) {
    const std::uint32_t mask = critical_error_mask(layout);
    EXPECT_NE(mask, 0u);
    for (const protocol::Fault f : critical_faults()) {
      for (int motor = 0; motor <= 8; ++motor)
        EXPECT_EQ(protocol::fault_bit(f, layout, motor) & ~mask, 0u);
    }
    // Host-link loss is never critical: commanding again cures it.
    EXPECT_EQ(protocol::fault_bit(protocol::Fault::kHostCommunicationLost, layout) & mask, 0u);
    EXPECT_EQ(protocol::fault_bit(protocol::Fault::kRemoteSignalLost, layout) & mask, 0u);
  }
  EXPECT_EQ(critical_error_mask(ErrorWordLayout::kAgxV2_16) >> 16, 0u);
}

TEST(VehicleSpec, ThePackOfTheManual) {
  EXPECT_EQ(vehicle_spec::kBatteryChemistry, "LiFePO4");
  EXPECT_EQ(vehicle_spec::kBatteryNominalVoltage, 48.0);
  EXPECT_EQ(vehicle_spec::kBatteryNormalMinVoltage, 46.0);
  EXPECT_EQ(vehicle_spec::kBatteryNormalMaxVoltage, 50.0);
  EXPECT_EQ(vehicle_spec::kBatteryCapacityAh, 24.0);
}

}  // namespace
}  // namespace ranger::interpretation
