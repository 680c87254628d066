#include "ranger_can/control/joint_tracker.hpp"

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

// Whether a step between two frame stamps is integrated, and its length in seconds.
bool usable_step(Timestamp previous, Timestamp now, double* dt) {
  if (previous.count() == 0 || now <= previous || now - previous > WheelJointTracker::kMaxStep) {
    return false;
  }
  *dt = seconds(now - previous);
  return true;
}

}  // namespace

void WheelJointTracker::on_message(const Message& message, Timestamp stamp) {
  if (const auto* angles = std::get_if<SteeringAnglesFeedback>(&message)) {
    double dt = 0.0;
    const bool step = joints_.has_steering && usable_step(steering_stamp_, stamp, &dt);
    for (int i = 0; i < kWheelCount; ++i) {
      const auto w = static_cast<std::size_t>(i);
      // + 0.0 turns the -0.0 of a sign flip into 0.0 for tidy joint_states.
      const double angle = interpretation::rep103_from_manual_wheel_angle(angles->angles[w]) + 0.0;
      joints_.steering_velocity[w] = step ? (angle - joints_.steering_position[w]) / dt : 0.0;
      joints_.steering_position[w] = angle;
    }
    joints_.has_steering = true;
    steering_stamp_ = stamp;
  } else if (const auto* speeds = std::get_if<WheelSpeedsFeedback>(&message)) {
    double dt = 0.0;
    const bool step = joints_.has_wheels && usable_step(wheels_stamp_, stamp, &dt);
    for (int i = 0; i < kWheelCount; ++i) {
      const auto w = static_cast<std::size_t>(i);
      const double velocity = speeds->speeds[w] / wheel_radius_;
      // Trapezoid between the previous and the new speed, like the odometry's mean twist.
      if (step) joints_.wheel_position[w] += 0.5 * (joints_.wheel_velocity[w] + velocity) * dt;
      joints_.wheel_velocity[w] = velocity;
    }
    joints_.has_wheels = true;
    wheels_stamp_ = stamp;
  }
}

}  // namespace ranger
