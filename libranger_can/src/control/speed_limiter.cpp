#include "ranger_can/control/speed_limiter.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace ranger {

Status SpeedLimits::validate() const {
  auto bad = [](const std::string& what) {
    return Status(Error{Errc::kOutOfRange, "speed limits: " + what});
  };
  if (has_velocity_limits) {
    if (!std::isfinite(min_velocity) || !std::isfinite(max_velocity)) {
      return bad("min_velocity/max_velocity must be finite");
    }
    if (min_velocity > max_velocity) {
      return bad("min_velocity " + std::to_string(min_velocity) + " > max_velocity " +
                 std::to_string(max_velocity));
    }
  }
  if (has_acceleration_limits) {
    if (!std::isfinite(min_acceleration) || !std::isfinite(max_acceleration)) {
      return bad("min_acceleration/max_acceleration must be finite");
    }
    if (min_acceleration > 0.0 || max_acceleration < 0.0) {
      return bad("need min_acceleration <= 0 <= max_acceleration (got " +
                 std::to_string(min_acceleration) + ", " + std::to_string(max_acceleration) + ")");
    }
  }
  return ok_status();
}

double SpeedLimiter::limit_velocity(double v) const {
  if (!limits_.has_velocity_limits) return v;
  return std::clamp(v, limits_.min_velocity, limits_.max_velocity);
}

double SpeedLimiter::limit_acceleration(double v, double previous, double dt) const {
  if (!limits_.has_acceleration_limits) return v;
  if (!std::isfinite(dt) || dt <= 0.0) return previous;
  const double dv =
      std::clamp(v - previous, limits_.min_acceleration * dt, limits_.max_acceleration * dt);
  return previous + dv;
}

double SpeedLimiter::limit(double target, double previous, double dt) const {
  if (!std::isfinite(target)) return limit_velocity(previous);
  return limit_velocity(limit_acceleration(target, previous, dt));
}

}  // namespace ranger
