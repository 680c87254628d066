// The vehicle's geometry: the one place the library's defaults for wheel positions live.
// Kinematics, odometry and the simulator take a VehicleGeometry; the ROS node fills it from
// parameters (ranger_description/config/geometry.yaml is the shared source for node and URDF).
#pragma once

#include <array>
#include <string_view>

#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"

namespace ranger {

// Wheel order used throughout the library: the manual's motor order. Wheel i has its drive
// motor i+1 (0x251+i, 0x281 slot i) and its steering motor i+5 (0x255+i, 0x271 slot i).
enum WheelIndex : int { kRightFront = 0, kRightRear = 1, kLeftRear = 2, kLeftFront = 3 };

inline constexpr std::array<std::string_view, kWheelCount> kWheelNames = {
    "front_right", "rear_right", "rear_left", "front_left"};
// Joint names shared with ranger_description's URDF and ranger_base's joint_states.
inline constexpr std::array<std::string_view, kWheelCount> kSteeringJointNames = {
    "front_right_steering_joint", "rear_right_steering_joint", "rear_left_steering_joint",
    "front_left_steering_joint"};
inline constexpr std::array<std::string_view, kWheelCount> kWheelJointNames = {
    "front_right_wheel_joint", "rear_right_wheel_joint", "rear_left_wheel_joint",
    "front_left_wheel_joint"};

struct WheelPosition {
  double x;  // m, forward of the body centre (REP-103 base_link)
  double y;  // m, left of the body centre
};

struct VehicleGeometry {
  double wheelbase = 0.890;    // m, front axle to rear axle (manual 1.1)
  double track = 0.560;        // m, left wheel centre to right wheel centre (manual 1.1)
  double wheel_radius = 0.16;  // m, used for joint_states wheel angle only

  WheelPosition wheel_position(int wheel) const {
    const double hx = wheelbase / 2.0, hy = track / 2.0;
    switch (wheel) {
      case kRightFront:
        return {hx, -hy};
      case kRightRear:
        return {-hx, -hy};
      case kLeftRear:
        return {-hx, hy};
      default:
        return {hx, hy};
    }
  }
  // Distance from the body centre to each wheel (all equal on the symmetric RANGER).
  double wheel_radius_from_centre() const;

  // Checks that every dimension is finite and positive; the message names the field.
  Status validate() const;
};

}  // namespace ranger
