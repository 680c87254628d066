// The joint tracker: joint_states from 0x271 / 0x281.
#include <gtest/gtest.h>

#include "ranger_can/control/joint_tracker.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

WheelSpeedsFeedback speeds(double v) {
  WheelSpeedsFeedback f;
  f.speeds = {v, v, v, v};
  return f;
}

TEST(WheelJoints, WheelAngleIsDistanceOverRadius) {
  WheelJointTracker t(0.16);
  // 1 m/s for 1 s in 20 ms steps: 1 m of tread = 6.25 rad.
  for (int i = 0; i <= 50; ++i)
    t.on_message(speeds(1.0), Timestamp(1s + i * 20ms));
  EXPECT_NEAR(t.joints().wheel_position[0], 1.0 / 0.16, 1e-9);
  EXPECT_NEAR(t.joints().wheel_velocity[3], 1.0 / 0.16, 1e-9);
}

TEST(WheelJoints, GapsAndBackwardStepsAreNotIntegrated) {
  WheelJointTracker t(0.5);
  t.on_message(speeds(1.0), Timestamp(1s));
  t.on_message(speeds(1.0), Timestamp(5s));  // 4 s gap: the link was down
  t.on_message(speeds(1.0), Timestamp(4s));  // backwards
  EXPECT_DOUBLE_EQ(t.joints().wheel_position[0], 0.0);
  t.on_message(speeds(1.0), Timestamp(4s + 100ms));
  EXPECT_NEAR(t.joints().wheel_position[0], 0.2, 1e-9);
}

TEST(WheelJoints, SteeringIsConvertedToRep103ThroughTheInterpretation) {
  WheelJointTracker t(0.16);
  SteeringAnglesFeedback f;
  f.angles = {0.1, -0.2, 0.3, -0.4};  // manual signs
  t.on_message(f, Timestamp(1s));
  ASSERT_TRUE(t.joints().has_steering);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(t.joints().steering_position[i],
                     interpretation::rep103_from_manual_wheel_angle(f.angles[i]));
  }
  EXPECT_DOUBLE_EQ(t.joints().steering_velocity[0], 0.0);  // one sample: no velocity yet
  SteeringAnglesFeedback g = f;
  g.angles[0] = 0.3;
  t.on_message(g, Timestamp(1s + 100ms));
  EXPECT_NEAR(t.joints().steering_velocity[0],
              interpretation::rep103_from_manual_wheel_angle(0.2) / 0.1, 1e-9);
}

TEST(WheelJoints, OtherMessagesAreIgnored) {
  WheelJointTracker t(0.16);
  t.on_message(MotionFeedback{1.0, 0.0}, Timestamp(1s));
  EXPECT_FALSE(t.joints().has_wheels);
  EXPECT_FALSE(t.joints().has_steering);
}

}  // namespace
}  // namespace ranger
