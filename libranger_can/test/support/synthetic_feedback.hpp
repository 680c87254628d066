// Synthetic chassis feedback from rigid-body motion, for odometry and CLI tests: what a RANGER
// reports (0x291, 0x221, 0x271, 0x281, in that order) while its body moves with a given twist.
// Built from kinematics' wheel_states_from_twist and the manual's definition of 0x221 per mode.
#pragma once

#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::test {

// 0x221 as the manual defines it per mode: Ackermann — mean front angle and mean wheel speed;
// oblique — mean angle and mean speed; spin — mean |angle| and the tangential speed (CCW +).
MotionFeedback motion_feedback_from_wheels(const WheelStates& wheels, protocol::MotionMode mode,
                                           const VehicleGeometry& geometry);

struct FeedbackOptions {
  bool motion_mode = true;      // 0x291
  bool motion = true;           // 0x221
  bool steering_angles = true;  // 0x271
  bool wheel_speeds = true;     // 0x281
  int flip_wheel = -1;          // report this wheel turned by 180 deg with negated speed
};

// One 20 ms cycle of encoded feedback frames stamped `stamp`.
std::vector<CanFrame> feedback_frames(const BodyTwist& twist, protocol::MotionMode mode,
                                      const VehicleGeometry& geometry, Timestamp stamp,
                                      const FeedbackOptions& options = {});

}  // namespace ranger::test
