#include "ranger_can/control/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "ranger_can/parse.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using protocol::MotionMode;
namespace interp = ranger::interpretation;

// Below this a twist component counts as absent (for flags and degenerate geometry only; the
// mode thresholds live in ModeSelectorConfig).
constexpr double kEps = 1e-9;

double sign(double v) {
  return v < 0.0 ? -1.0 : 1.0;
}

// Folds a direction into [-pi/2, pi/2]; returns whether the rolling speed must be negated.
bool fold_half_plane(double& angle) {
  if (angle > M_PI / 2) {
    angle -= M_PI;
    return true;
  }
  if (angle < -M_PI / 2) {
    angle += M_PI;
    return true;
  }
  return false;
}

Status check_limit(const char* name, double value, double max) {
  if (!std::isfinite(value) || value <= 0.0 || value > max * (1.0 + 1e-9)) {
    return Error{Errc::kOutOfRange, std::string("kinematics limits: ") + name + " = " +
                                        std::to_string(value) + " is not in (0, " +
                                        std::to_string(max) + "]"};
  }
  return ok_status();
}

// The speed limit that applies at a steering angle (the manual's "> 20 degrees" clause).
double speed_limit_at(double steering, const KinematicsLimits& limits) {
  double limit = limits.max_linear_speed;
  if (std::fabs(steering) > interp::kLargeSteeringThresholdRad) {
    limit = std::min(limit, limits.max_speed_at_large_steering);
  }
  return limit;
}

double saturate_speed(double speed, double limit, std::uint32_t& flags) {
  if (std::fabs(speed) > limit) {
    flags |= kSpeedSaturated;
    return sign(speed) * limit;
  }
  return speed;
}

void solve_ackermann(const BodyTwist& t, const VehicleGeometry& g, const KinematicsLimits& limits,
                     const ProtocolProfile& profile, KinematicsSolution& s) {
  if (std::fabs(t.vy) > kEps) s.flags |= kLateralDropped;
  const double max_steer = limits.max_ackermann_steering;
  double steering = 0.0;       // REP-103: positive = left
  double command_speed = 0.0;  // 0x111 linear speed
  double curvature = 0.0;
  if (std::fabs(t.vx) <= kEps) {
    // A rotation without forward speed has infinite curvature: Ackermann cannot do it. Turn the
    // wheels to full lock towards the rotation (ready to drive it) but do not move.
    if (std::fabs(t.wz) > kEps) {
      steering = sign(t.wz) * max_steer;
      s.flags |= kRotationDropped | kSteeringSaturated;
    }
  } else {
    curvature = t.wz / t.vx;
    const double max_curvature = max_ackermann_curvature(max_steer, g, profile);
    if (std::fabs(curvature) > max_curvature) {
      curvature = sign(curvature) * max_curvature;  // sign kept: the turn is only wider
      s.flags |= kSteeringSaturated;
    }
    // The angle 0x111 carries: the front wheels' mean or the inner wheel (steering_reference).
    steering = std::clamp(
        interp::ackermann_front_angle(curvature, g.wheelbase, g.track, profile.steering_reference),
        -max_steer, max_steer);
    // The speed limits bound the value on the wire; interpretation point 7 relates it to vx.
    command_speed =
        saturate_speed(interp::command_speed_from_body_speed(t.vx, curvature, g.wheelbase, g.track),
                       speed_limit_at(steering, limits), s.flags);
  }
  const double speed =
      interp::body_speed_from_command_speed(command_speed, curvature, g.wheelbase, g.track);
  s.command.linear_speed = command_speed;
  s.command.steering_angle = interp::manual_from_rep103_command_steering(steering);
  s.achieved = BodyTwist{speed, 0.0, curvature * speed};
}

void solve_oblique(const BodyTwist& t, const VehicleGeometry& g, const KinematicsLimits& limits,
                   const ObliqueSideHint& hint, KinematicsSolution& s) {
  if (std::fabs(t.wz) > kEps) s.flags |= kRotationDropped;
  double speed = std::hypot(t.vx, t.vy);
  double direction = 0.0;  // REP-103
  if (speed > kEps) {
    direction = std::atan2(t.vy, t.vx);
    if (fold_half_plane(direction)) speed = -speed;  // a backwards crab
    // Near +-90 deg the two folds are the same wheel line, a hair apart in direction but 180 deg
    // apart for the wheels: take the hinted side (beyond 90 deg the limit below clamps it).
    const bool hint_applies = hint.side != 0.0 && hint.band > 0.0 && hint.band < M_PI / 2;
    if (hint_applies && std::fabs(direction) >= M_PI / 2 - hint.band &&
        sign(direction) != sign(hint.side)) {
      direction += sign(hint.side) * M_PI;
      speed = -speed;
    }
    const double max_steer = limits.max_oblique_steering;
    if (std::fabs(direction) > max_steer) {
      direction = sign(direction) * max_steer;
      s.flags |= kSteeringSaturated;
    }
    speed = saturate_speed(speed, speed_limit_at(direction, limits), s.flags);
  } else {
    speed = 0.0;
  }
  // All wheels parallel: curvature 0, where the body and every wheel move alike (point 7).
  s.command.linear_speed = interp::command_speed_from_body_speed(speed, 0.0, g.wheelbase, g.track);
  s.command.steering_angle = interp::manual_from_rep103_command_steering(direction);
  s.achieved = BodyTwist{speed * std::cos(direction), speed * std::sin(direction), 0.0};
}

void solve_spin(const BodyTwist& t, const VehicleGeometry& g, const KinematicsLimits& limits,
                const ProtocolProfile& profile, KinematicsSolution& s) {
  if (std::fabs(t.vx) > kEps || std::fabs(t.vy) > kEps) s.flags |= kTranslationDropped;
  double wheel_speed = interp::spin_wheel_speed_from_yaw_rate(t.wz, g.wheelbase, g.track);
  if (std::fabs(wheel_speed) > limits.max_spin_wheel_speed) {
    wheel_speed = sign(wheel_speed) * limits.max_spin_wheel_speed;
    s.flags |= kSpinSaturated;
  }
  const double wz = interp::spin_yaw_rate_from_wheel_speed(wheel_speed, g.wheelbase, g.track);
  // The field the chassis reads spin from (spin_field), in its sign (spin_sign).
  if (profile.spin_field == SpinField::kYawRate) {
    s.command.yaw_rate = interp::spin_wire_from_ccw(wz, profile);
  } else {
    s.command.spin_speed = interp::spin_wire_from_ccw(wheel_speed, profile);
  }
  s.achieved = BodyTwist{0.0, 0.0, wz};
}

// Side slip (MINI V1 mode 3, agx_v2 mode 4): every wheel at 90 deg, the body moves sideways.
// Only vy is driven; it goes out in 0x111 bytes 4-5 (the spin wheel-speed field, whose range it
// shares) with the profile's spin sign, left positive.
void solve_side_slip(const BodyTwist& t, const KinematicsLimits& limits,
                     const ProtocolProfile& profile, KinematicsSolution& s) {
  if (std::fabs(t.vx) > kEps) s.flags |= kTranslationDropped;
  if (std::fabs(t.wz) > kEps) s.flags |= kRotationDropped;
  const double max = std::min(limits.max_linear_speed, kMaxSpinSpeedMps);
  double vy = t.vy;
  if (std::fabs(vy) > max) {
    vy = sign(vy) * max;
    s.flags |= kSpeedSaturated;
  }
  s.command.spin_speed = interp::spin_wire_from_ccw(vy, profile);
  s.achieved = BodyTwist{0.0, vy, 0.0};
}

// A steering faster than this (rad/s) is no chassis's: a typo.
constexpr double kMaxSteeringRateRps = 100.0;

}  // namespace

Status KinematicsLimits::validate() const {
  const struct {
    const char* name;
    double value;
    double max;
  } checks[] = {
      {"max_linear_speed", max_linear_speed, interp::kMaxLinearSpeedMps},
      {"max_speed_at_large_steering", max_speed_at_large_steering, interp::kMaxLinearSpeedMps},
      {"max_ackermann_steering", max_ackermann_steering, kMaxAckermannSteeringRad},
      {"max_oblique_steering", max_oblique_steering, kMaxObliqueSteeringRad},
      {"max_spin_wheel_speed", max_spin_wheel_speed, kMaxSpinSpeedMps},
      {"steering_rate", steering_rate, kMaxSteeringRateRps},
  };
  for (const auto& c : checks) {
    Status st = check_limit(c.name, c.value, c.max);
    if (!st) return st;
  }
  return ok_status();
}

std::string kinematics_flags_to_string(std::uint32_t flags) {
  if (flags == kKinematicsExact) return "exact";
  static const struct {
    std::uint32_t bit;
    const char* name;
  } kNames[] = {
      {kSpeedSaturated, "speed_saturated"},   {kSteeringSaturated, "steering_saturated"},
      {kSpinSaturated, "spin_saturated"},     {kLateralDropped, "lateral_dropped"},
      {kRotationDropped, "rotation_dropped"}, {kTranslationDropped, "translation_dropped"}};
  std::string out;
  for (const auto& n : kNames) {
    if (flags & n.bit) {
      if (!out.empty()) out += '|';
      out += n.name;
    }
  }
  return out.empty() ? "unknown_flags" : out;
}

std::string describe_adjustments(std::uint32_t flags, const BodyTwist& asked,
                                 const BodyTwist& driven) {
  const auto twist = [](const BodyTwist& t) {
    return "(" + number_text(t.vx) + " m/s, " + number_text(t.vy) + " m/s, " + number_text(t.wz) +
           " rad/s)";
  };
  return kinematics_flags_to_string(flags) + ": asked (vx, vy, wz) = " + twist(asked) +
         ", driven " + twist(driven);
}

double max_ackermann_curvature(double max_steering, const VehicleGeometry& geometry,
                               const ProtocolProfile& profile) {
  return std::fabs(interp::ackermann_curvature_from_front_angle(
      std::fabs(max_steering), geometry.wheelbase, geometry.track, profile.steering_reference));
}

Result<KinematicsSolution> solve_kinematics(const BodyTwist& twist, MotionMode mode,
                                            const VehicleGeometry& geometry,
                                            const KinematicsLimits& limits,
                                            const ObliqueSideHint& oblique_hint,
                                            const ProtocolProfile& profile) {
  const struct {
    const char* name;
    double value;
  } components[] = {{"vx", twist.vx}, {"vy", twist.vy}, {"wz", twist.wz}};
  for (const auto& c : components) {
    if (!std::isfinite(c.value)) {
      return Error{Errc::kNotFinite, std::string("kinematics: twist.") + c.name + " is " +
                                         (std::isnan(c.value) ? "NaN" : "infinite")};
    }
  }
  if (Status st = limits.validate(); !st) return Error{Errc::kInvalidArgument, st.error().message};
  if (Status st = geometry.validate(); !st)
    return Error{Errc::kInvalidArgument, st.error().message};

  KinematicsSolution s;
  s.mode = mode;
  switch (mode) {
    case MotionMode::kAckermann:
      solve_ackermann(twist, geometry, limits, profile, s);
      break;
    case MotionMode::kOblique:
      solve_oblique(twist, geometry, limits, oblique_hint, s);
      break;
    case MotionMode::kSpin:
      solve_spin(twist, geometry, limits, profile, s);
      break;
    case MotionMode::kSideSlip:
      solve_side_slip(twist, limits, profile, s);
      break;
    default:
      return Error{Errc::kInvalidArgument,
                   "kinematics: unknown motion mode " + std::to_string(static_cast<int>(mode))};
  }
  return s;
}

BodyTwist twist_from_command(const MotionCommand& command, MotionMode mode,
                             const VehicleGeometry& geometry, const ProtocolProfile& profile) {
  switch (mode) {
    case MotionMode::kAckermann: {
      const double steering = interp::rep103_from_manual_command_steering(command.steering_angle);
      const double curvature = interp::ackermann_curvature_from_front_angle(
          steering, geometry.wheelbase, geometry.track, profile.steering_reference);
      // A steering of +-90 deg or more (far outside the 0x111 range) has an infinite curvature:
      // no defined twist, and never a NaN.
      if (!std::isfinite(curvature)) return BodyTwist{};
      const double vx = interp::body_speed_from_command_speed(command.linear_speed, curvature,
                                                              geometry.wheelbase, geometry.track);
      return BodyTwist{vx, 0.0, curvature * vx};
    }
    case MotionMode::kOblique: {
      const double direction = interp::rep103_from_manual_command_steering(command.steering_angle);
      const double speed = interp::body_speed_from_command_speed(
          command.linear_speed, 0.0, geometry.wheelbase, geometry.track);
      return BodyTwist{speed * std::cos(direction), speed * std::sin(direction), 0.0};
    }
    case MotionMode::kSpin: {
      const double wz = profile.spin_field == SpinField::kYawRate
                            ? interp::spin_ccw_from_wire(command.yaw_rate, profile)
                            : interp::spin_yaw_rate_from_wheel_speed(
                                  interp::spin_ccw_from_wire(command.spin_speed, profile),
                                  geometry.wheelbase, geometry.track);
      return BodyTwist{0.0, 0.0, wz};
    }
    case MotionMode::kSideSlip:
      return BodyTwist{0.0, interp::spin_ccw_from_wire(command.spin_speed, profile), 0.0};
    case MotionMode::kPark:  // no motion: the zero twist below
      break;
  }
  return BodyTwist{};
}

std::array<double, kWheelCount> wheel_angles_for_command(const MotionCommand& command,
                                                         MotionMode mode,
                                                         const VehicleGeometry& geometry,
                                                         const ProtocolProfile& profile) {
  std::array<double, kWheelCount> angles{};
  const double steering = interp::rep103_from_manual_command_steering(command.steering_angle);
  for (int i = 0; i < kWheelCount; ++i) {
    const WheelPosition p = geometry.wheel_position(i);
    double angle = 0.0;
    switch (mode) {
      case MotionMode::kAckermann: {
        const double k = interp::ackermann_curvature_from_front_angle(
            steering, geometry.wheelbase, geometry.track, profile.steering_reference);
        // Wheel i rolls along (1 - k y_i, k x_i) for a forward body motion; at |k| = inf (a
        // corrupt angle) the wheels stand tangent to the circle about the body centre.
        angle = std::isfinite(k) ? std::atan2(k * p.x, 1.0 - k * p.y)
                                 : std::atan2(std::copysign(p.x, k), -std::copysign(p.y, k));
        break;
      }
      case MotionMode::kOblique:
        angle = steering;
        break;
      case MotionMode::kSideSlip:
        angle = M_PI / 2.0;
        break;
      default:
        angle = std::atan2(p.x, -p.y);
        break;
    }
    fold_half_plane(angle);
    angles[static_cast<std::size_t>(i)] = angle;
  }
  return angles;
}

BodyTwist fit_body_twist(const std::array<WheelMeasurement, kWheelCount>& wheels,
                         const VehicleGeometry& geometry) {
  // Rows per wheel: [1 0 -y_i] and [0 1 x_i]; normal matrix N = A^T A and right side A^T r.
  double sx = 0.0, sy = 0.0, sr2 = 0.0;
  double bu = 0.0, bw = 0.0, bt = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    const WheelPosition p = geometry.wheel_position(i);
    const WheelMeasurement& m = wheels[static_cast<std::size_t>(i)];
    const double u = m.speed * std::cos(m.angle);
    const double w = m.speed * std::sin(m.angle);
    sx += p.x;
    sy += p.y;
    sr2 += p.x * p.x + p.y * p.y;
    bu += u;
    bw += w;
    bt += p.x * w - p.y * u;
  }
  const double n = kWheelCount;
  // N = [[n, 0, -sy], [0, n, sx], [-sy, sx, sr2]]. Rows 1 and 2 give vx = (bu + sy*wz)/n and
  // vy = (bw - sx*wz)/n; row 3 (-sy*vx + sx*vy + sr2*wz = bt) then yields wz. The denominator is
  // the wheels' spread about their centroid: positive unless all wheels sit on one point.
  const double spread = sr2 - (sx * sx + sy * sy) / n;
  if (!(spread > 1e-12)) return BodyTwist{};
  const double wz = (bt + sy * bu / n - sx * bw / n) / spread;
  return BodyTwist{(bu + sy * wz) / n, (bw - sx * wz) / n, wz};
}

WheelStates wheel_states_from_twist(const BodyTwist& twist, const VehicleGeometry& geometry,
                                    const std::array<double, kWheelCount>& hold_angles) {
  WheelStates wheels{};
  for (int i = 0; i < kWheelCount; ++i) {
    const WheelPosition p = geometry.wheel_position(i);
    const double ux = twist.vx - twist.wz * p.y;
    const double uy = twist.vy + twist.wz * p.x;
    double speed = std::hypot(ux, uy);
    double angle = hold_angles[static_cast<std::size_t>(i)];
    if (speed > kEps) {
      angle = std::atan2(uy, ux);
      if (fold_half_plane(angle)) speed = -speed;
    } else {
      speed = 0.0;
    }
    wheels[static_cast<std::size_t>(i)] = WheelState{angle, speed};
  }
  return wheels;
}

}  // namespace ranger
