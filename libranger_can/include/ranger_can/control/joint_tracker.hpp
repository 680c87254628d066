// The eight joints of the robot model (4 steering, 4 wheels), for joint_states, from the chassis's
// per-wheel feedback: steering angles from 0x271 (converted to REP-103 by interpretation.hpp),
// wheel rotation integrated from 0x281 wheel speeds over the frames' own timestamps (the chassis
// reports no usable wheel angle: 0x251's encoder pulses have no documented scale).
#pragma once

#include <array>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"

namespace ranger {

struct WheelJoints {
  // geometry.hpp wheel order (right-front, right-rear, left-rear, left-front), as
  // kSteeringJointNames / kWheelJointNames.
  std::array<double, kWheelCount> steering_position{};  // rad, REP-103 (CCW positive)
  std::array<double, kWheelCount> steering_velocity{};  // rad/s, between two 0x271
  std::array<double, kWheelCount> wheel_position{};     // rad, forward rolling positive
  std::array<double, kWheelCount> wheel_velocity{};     // rad/s
  bool has_steering = false;
  bool has_wheels = false;
};

class WheelJointTracker {
 public:
  explicit WheelJointTracker(double wheel_radius) : wheel_radius_(wheel_radius) {}

  // Ignores every message but 0x271 and 0x281. Steps going backwards in time, or longer than
  // `max_step`, only re-anchor the time (as the odometry does).
  void on_message(const Message& message, Timestamp stamp);

  const WheelJoints& joints() const { return joints_; }

  static constexpr Timestamp kMaxStep = std::chrono::milliseconds(500);

 private:
  double wheel_radius_;
  WheelJoints joints_;
  Timestamp steering_stamp_{0};
  Timestamp wheels_stamp_{0};
};

}  // namespace ranger
