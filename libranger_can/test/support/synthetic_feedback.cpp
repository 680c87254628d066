#include "support/synthetic_feedback.hpp"

#include <cmath>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger::test {

using protocol::MotionMode;

MotionFeedback motion_feedback_from_wheels(const WheelStates& w, MotionMode mode,
                                           const VehicleGeometry& g) {
  MotionFeedback fb;
  double steering = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    const WheelState& s = w[static_cast<std::size_t>(i)];
    switch (mode) {
      case MotionMode::kAckermann:
        if (i == kLeftFront || i == kRightFront) steering += s.angle / 2;
        fb.speed += s.speed / kWheelCount;
        break;
      case MotionMode::kOblique:
        steering += s.angle / kWheelCount;
        fb.speed += s.speed / kWheelCount;
        break;
      case MotionMode::kSpin: {
        const WheelPosition p = g.wheel_position(i);
        steering += std::fabs(s.angle) / kWheelCount;
        fb.speed += (s.speed * std::cos(s.angle) * -p.y + s.speed * std::sin(s.angle) * p.x) /
                    g.wheel_radius_from_centre() / kWheelCount;
        break;
      }
    }
  }
  fb.steering_angle = interpretation::manual_from_rep103_steering(steering);
  return fb;
}

std::vector<CanFrame> feedback_frames(const BodyTwist& twist, MotionMode mode,
                                      const VehicleGeometry& geometry, Timestamp stamp,
                                      const FeedbackOptions& options) {
  WheelStates w = wheel_states_from_twist(twist, geometry);
  std::vector<CanFrame> frames;
  auto push = [&](const Message& m) {
    Result<CanFrame> f = encode(m);
    if (!f) return;  // cannot happen for finite values; the caller's assertions will notice
    f->stamp = stamp;
    frames.push_back(*f);
  };
  if (options.motion_mode) {
    MotionModeFeedback mm;
    mm.mode = mode;
    mm.mode_raw = static_cast<std::uint8_t>(mode);
    push(mm);
  }
  if (options.motion) push(motion_feedback_from_wheels(w, mode, geometry));
  if (options.flip_wheel >= 0 && options.flip_wheel < kWheelCount) {
    WheelState& s = w[static_cast<std::size_t>(options.flip_wheel)];
    s.angle += s.angle > 0 ? -M_PI : M_PI;
    s.speed = -s.speed;
  }
  SteeringAnglesFeedback angles;
  WheelSpeedsFeedback speeds;
  for (std::size_t i = 0; i < w.size(); ++i) {
    angles.angles[i] = interpretation::manual_from_rep103_wheel_angle(w[i].angle);
    speeds.speeds[i] = w[i].speed;
  }
  if (options.steering_angles) push(angles);
  if (options.wheel_speeds) push(speeds);
  return frames;
}

}  // namespace ranger::test
