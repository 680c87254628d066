// The eight joints of joint_states (4 steering, 4 wheels), from the chassis's per-wheel feedback:
// steering angles from 0x271 (converted to REP-103 by interpretation.hpp), wheel rotation
// integrated from 0x281 wheel speeds over the frames' own timestamps (the chassis reports no
// usable wheel angle: 0x251's encoder pulses have no documented scale).
#pragma once

#include <array>

#include <ranger_can/wire/codec.hpp>
#include <ranger_can/wire/frame.hpp>
#include <ranger_can/control/geometry.hpp>

namespace ranger_base {

struct WheelJoints {
  // geometry.hpp wheel order (right-front, right-rear, left-rear, left-front), as
  // kSteeringJointNames / kWheelJointNames.
  std::array<double, ranger::kWheelCount> steering_position{};  // rad, REP-103 (CCW positive)
  std::array<double, ranger::kWheelCount> steering_velocity{};  // rad/s, between two 0x271
  std::array<double, ranger::kWheelCount> wheel_position{};     // rad, forward rolling positive
  std::array<double, ranger::kWheelCount> wheel_velocity{};     // rad/s
  bool has_steering = false;
  bool has_wheels = false;
};

class WheelJointTracker {
 public:
  explicit WheelJointTracker(double wheel_radius) : wheel_radius_(wheel_radius) {}

  // Ignores every message but 0x271 and 0x281. Steps going backwards in time, or longer than
  // `max_step`, only re-anchor the time (as the odometry does).
  void on_message(const ranger::Message& message, ranger::Timestamp stamp);

  const WheelJoints& joints() const { return joints_; }

  static constexpr ranger::Timestamp kMaxStep = std::chrono::milliseconds(500);

 private:
  double wheel_radius_;
  WheelJoints joints_;
  ranger::Timestamp steering_stamp_{0};
  ranger::Timestamp wheels_stamp_{0};
};

}  // namespace ranger_base
