// Velocity and acceleration limiting of one command axis, after ros_controllers'
// diff_drive_controller::SpeedLimiter (same parameter names and semantics, without jerk), so the
// ROS node's parameters read as users of diff_drive_controller expect.
#pragma once

#include "ranger_can/result.hpp"

namespace ranger {

struct SpeedLimits {
  bool has_velocity_limits = false;
  bool has_acceleration_limits = false;
  double min_velocity = 0.0;      // e.g. -1.0 m/s (or rad/s); must be <= max_velocity
  double max_velocity = 0.0;      // e.g. +1.0
  double min_acceleration = 0.0;  // e.g. -2.0 m/s^2: the most negative change of velocity per s
  double max_acceleration = 0.0;  // e.g. +1.0 m/s^2: the most positive change of velocity per s

  // Enabled limits must be finite and ordered (min <= max; min_acceleration <= 0 <=
  // max_acceleration so that a limited axis can always stop).
  Status validate() const;
};

class SpeedLimiter {
 public:
  explicit SpeedLimiter(SpeedLimits limits = {}) : limits_(limits) {}

  // The value to command now, given the wanted value `target`, the value commanded in the
  // previous cycle `previous` and the time since then `dt` (s). Acceleration is limited first,
  // then velocity. A non-finite target, or dt <= 0 / non-finite with acceleration limits, holds
  // `previous` (clamped to the velocity limits).
  double limit(double target, double previous, double dt) const;

  double limit_velocity(double v) const;
  double limit_acceleration(double v, double previous, double dt) const;

  const SpeedLimits& limits() const { return limits_; }

 private:
  SpeedLimits limits_;
};

}  // namespace ranger
