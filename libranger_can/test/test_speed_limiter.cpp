// SpeedLimiter: ros_controllers semantics (velocity clamp, acceleration per step), NaN handling.
#include <gtest/gtest.h>

#include <limits>

#include "ranger_can/control/speed_limiter.hpp"

namespace ranger {
namespace {

SpeedLimits both() {
  SpeedLimits l;
  l.has_velocity_limits = true;
  l.has_acceleration_limits = true;
  l.min_velocity = -0.5;
  l.max_velocity = 1.0;
  l.min_acceleration = -2.0;
  l.max_acceleration = 1.0;
  return l;
}

TEST(SpeedLimiter, DisabledPassesThrough) {
  const SpeedLimiter none;
  EXPECT_DOUBLE_EQ(none.limit(7.0, 0.0, 0.02), 7.0);
  EXPECT_DOUBLE_EQ(none.limit(-7.0, 3.0, 0.0), -7.0);
}

TEST(SpeedLimiter, VelocityAndAccelerationTable) {
  const SpeedLimiter lim(both());
  struct Case {
    double target, previous, dt, expected;
  } cases[] = {
      {2.0, 1.0, 1.0, 1.0},     // velocity clamp
      {-3.0, -0.5, 1.0, -0.5},  // negative velocity clamp
      {1.0, 0.0, 0.02, 0.02},   // max_acceleration * dt
      {0.0, 1.0, 0.02, 0.96},   // min_acceleration * dt
      {0.01, 0.0, 0.02, 0.01},  // within limits: unchanged
      {1.0, 0.5, 0.0, 0.5},     // no time passed: hold
  };
  for (const Case& c : cases) {
    EXPECT_NEAR(lim.limit(c.target, c.previous, c.dt), c.expected, 1e-12)
        << c.target << " from " << c.previous << " in " << c.dt;
  }
}

TEST(SpeedLimiter, NonFiniteTargetHoldsThePreviousValue) {
  const SpeedLimiter lim(both());
  EXPECT_DOUBLE_EQ(lim.limit(std::numeric_limits<double>::quiet_NaN(), 0.3, 0.02), 0.3);
  EXPECT_DOUBLE_EQ(lim.limit(std::numeric_limits<double>::infinity(), 0.3, 0.02), 0.3);
}

TEST(SpeedLimiter, Validation) {
  EXPECT_TRUE(both().validate().ok());
  SpeedLimits l = both();
  l.min_velocity = 2.0;
  EXPECT_FALSE(l.validate().ok());
  l = both();
  l.min_acceleration = 0.5;  // could never slow down
  EXPECT_FALSE(l.validate().ok());
}

}  // namespace
}  // namespace ranger
