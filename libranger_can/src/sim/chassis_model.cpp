#include "ranger_can/sim/chassis_model.hpp"

#include <algorithm>
#include <cmath>

namespace ranger::sim {

namespace {

using protocol::MotionMode;

constexpr double kMaxSubStep = 1e-3;  // s; keeps the trapezoidal pose integration sub-micrometre

// Folds a wheel heading into [-pi/2, pi/2]; `sign` becomes -1 when the wheel is read as turned by
// 180 degrees (so its speed is negated).
double fold_wheel_angle(double a, double& sign) {
  sign = 1.0;
  if (a > M_PI / 2) {
    a -= M_PI;
    sign = -1.0;
  } else if (a < -M_PI / 2) {
    a += M_PI;
    sign = -1.0;
  }
  return a;
}

double clamp_abs(double v, double limit) {
  if (!std::isfinite(v)) return 0.0;
  return std::clamp(v, -limit, limit);
}

}  // namespace

ChassisModel::ChassisModel(const VehicleGeometry& geometry, const MotionLimits& limits)
    : geometry_(geometry), limits_(limits) {}

double ChassisModel::clamp_steering(MotionMode mode, double steering) const {
  switch (mode) {
    case MotionMode::kAckermann:
      return clamp_abs(steering, limits_.max_ackermann_angle);
    case MotionMode::kOblique:
      return clamp_abs(steering, limits_.max_oblique_angle);
    default:
      return 0.0;
  }
}

double ChassisModel::clamp_speed(MotionMode mode, double speed) const {
  if (mode == MotionMode::kPark) return 0.0;
  return clamp_abs(speed,
                   mode == MotionMode::kSpin ? limits_.max_spin_speed : limits_.max_linear_speed);
}

void ChassisModel::set_target(const MotionTarget& target) {
  if (switching()) return;
  target_.steering = clamp_steering(mode_, target.steering);
  target_.speed = clamp_speed(mode_, target.speed);
  if (std::fabs(target_.steering) > interpretation::kLargeSteeringThresholdRad) {
    target_.speed = clamp_abs(target_.speed, limits_.max_speed_at_large_steering);
  }
  emergency_ = false;
}

void ChassisModel::stop(bool emergency) {
  target_.speed = 0.0;
  emergency_ = emergency;
}

bool ChassisModel::begin_mode_switch(MotionMode mode, const TurnProfile& turn) {
  if (!switching() && mode == mode_) return false;
  if (switching() && mode == switch_target_) return false;
  const WheelStates standing = wheels();  // before the target changes
  switch_target_ = mode;
  switch_turn_ = turn;
  if (switch_phase_ == SwitchPhase::kTurning) {
    start_turning(standing);  // from wherever the wheels stand now towards the new target
  } else if (switch_phase_ == SwitchPhase::kNone) {
    switch_phase_ = SwitchPhase::kStopping;
    target_.speed = 0.0;
  }
  return true;
}

void ChassisModel::start_turning(const WheelStates& now) {
  const WheelStates to = wheels_for(switch_target_, 0.0, 0.0);
  switch_distance_ = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    // The short way: a wheel at +90 deg stands as one at -90 deg (running backwards), so no
    // wheel turns by more than 90 deg (the field's longest switch, 1.57 rad in 0.54 s).
    switch_from_[i] = {now[i].angle, 0.0};
    switch_turn_by_[i] = std::remainder(to[i].angle - now[i].angle, M_PI);
    switch_distance_ = std::max(switch_distance_, std::abs(switch_turn_by_[i]));
  }
  switch_duration_ = switch_turn_.duration(switch_distance_);
  switch_elapsed_ = 0.0;
  switch_phase_ = SwitchPhase::kTurning;
}

BodyTwist ChassisModel::twist_for(MotionMode mode, double steering, double speed) const {
  switch (mode) {
    case MotionMode::kAckermann: {
      const double curvature = steering == 0.0
                                   ? 0.0
                                   : interpretation::ackermann_curvature_from_mean_angle(
                                         steering, geometry_.wheelbase, geometry_.track);
      return {speed, 0.0, speed * curvature};
    }
    case MotionMode::kOblique:
      return {speed * std::cos(steering), speed * std::sin(steering), 0.0};
    case MotionMode::kSideSlip:
      return {0.0, speed, 0.0};
    case MotionMode::kPark:
      return {};
    default:
      return {0.0, 0.0,
              interpretation::spin_yaw_rate_from_wheel_speed(speed, geometry_.wheelbase,
                                                             geometry_.track)};
  }
}

WheelStates ChassisModel::wheels_for(MotionMode mode, double steering, double speed) const {
  // The direction each wheel must point is that of its contact point's velocity for a unit
  // motion in this mode; it exists even at rest, which is where the wheels stand when stopped.
  const BodyTwist unit = [&] {
    switch (mode) {
      case MotionMode::kAckermann:
        return twist_for(mode, steering, 1.0);
      case MotionMode::kOblique:
        return BodyTwist{std::cos(steering), std::sin(steering), 0.0};
      case MotionMode::kPark:  // the wheels stand as for spin: nothing can roll the body
        return twist_for(MotionMode::kSpin, 0.0, 1.0);
      default:
        return twist_for(mode, 0.0, 1.0);
    }
  }();
  WheelStates out{};
  for (int i = 0; i < kWheelCount; ++i) {
    const WheelPosition p = geometry_.wheel_position(i);
    const double vx = unit.vx - unit.wz * p.y;
    const double vy = unit.vy + unit.wz * p.x;
    double sign = 1.0;
    out[i].angle = fold_wheel_angle(std::atan2(vy, vx), sign);
    out[i].speed = speed * sign * std::hypot(vx, vy);
  }
  return out;
}

BodyTwist ChassisModel::twist() const {
  return twist_for(mode_, steering_, speed_);
}

WheelStates ChassisModel::wheels() const {
  if (switch_phase_ != SwitchPhase::kTurning) return wheels_for(mode_, steering_, speed_);
  const double frac =
      switch_duration_ <= 0.0 ? 1.0 : switch_turn_.fraction(switch_elapsed_, switch_distance_);
  WheelStates out{};
  for (int i = 0; i < kWheelCount; ++i) {
    double sign = 1.0;
    out[i].angle = fold_wheel_angle(switch_from_[i].angle + switch_turn_by_[i] * frac, sign);
    out[i].speed = 0.0;
  }
  return out;
}

void ChassisModel::advance(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) return;
  const WheelStates before = wheels();
  const int n = static_cast<int>(std::ceil(dt / kMaxSubStep));
  const double h = dt / n;
  for (int k = 0; k < n; ++k)
    sub_step(h);
  const WheelStates after = wheels();
  for (int i = 0; i < kWheelCount; ++i)
    wheel_angle_rates_[i] = (after[i].angle - before[i].angle) / dt;
}

void ChassisModel::sub_step(double h) {
  if (switch_phase_ == SwitchPhase::kStopping && speed_ == 0.0) start_turning(wheels());

  const BodyTwist before = twist();

  if (switch_phase_ == SwitchPhase::kNone && mode_ != MotionMode::kSpin) {
    const double delta = target_.steering - steering_;
    const double a = limits_.steering_acceleration;
    if (a > 0.0) {
      // Trapezoidal: as fast as the rate and the acceleration allow while the speed at the end of
      // the sub-step still stops at the target (v_end^2 = 2 a (dist - (v + v_end) h / 2), solved).
      const double dir = delta > 0.0 ? 1.0 : -1.0;
      const double dist = std::abs(delta);
      const double v = steering_velocity_ * dir;  // toward the target
      const double disc = a * a * h * h + 4.0 * (2.0 * a * dist - a * h * v);
      const double v_brake = std::max(0.0, (-a * h + std::sqrt(std::max(0.0, disc))) / 2.0);
      const double vn = std::max(std::min({limits_.steering_rate, v + a * h, v_brake}), v - a * h);
      const double step = (v + vn) / 2.0 * h;
      if (dist < 1e-9 || step >= dist - 1e-12) {
        steering_ = target_.steering;
        steering_velocity_ = 0.0;
      } else {
        steering_ += dir * step;
        steering_velocity_ = dir * vn;
      }
    } else {
      const double max_step = limits_.steering_rate * h;
      steering_ = std::abs(delta) <= max_step ? target_.steering
                                              : steering_ + std::copysign(max_step, delta);
    }
  }

  const double goal = switching() ? 0.0 : target_.speed;
  const bool speeding_up =
      std::abs(goal) > std::abs(speed_) && (speed_ == 0.0 || (speed_ > 0) == (goal > 0));
  const double rate = speeding_up
                          ? limits_.acceleration
                          : (emergency_ ? limits_.emergency_deceleration : limits_.deceleration);
  const double delta_v = goal - speed_;
  const double max_dv = rate * h;
  if (std::abs(delta_v) <= max_dv) {
    speed_ = goal;
  } else {
    const double next = speed_ + std::copysign(max_dv, delta_v);
    // Slowing down through zero: stop exactly at zero first, then speed up the other way.
    speed_ = (!speeding_up && speed_ != 0.0 && (next > 0) != (speed_ > 0)) ? 0.0 : next;
  }

  // Trapezoidal twist over the sub-step, integrated along the exact arc.
  const BodyTwist after = twist();
  const double vx = (before.vx + after.vx) / 2, vy = (before.vy + after.vy) / 2;
  const double wz = (before.wz + after.wz) / 2;
  const double dtheta = wz * h;
  double dx, dy;  // displacement in the body frame at the start of the sub-step
  if (std::abs(dtheta) < 1e-9) {
    dx = (vx - vy * dtheta / 2) * h;
    dy = (vy + vx * dtheta / 2) * h;
  } else {
    const double s = std::sin(dtheta), c = 1.0 - std::cos(dtheta);
    dx = (vx * s - vy * c) / wz;
    dy = (vx * c + vy * s) / wz;
  }
  const double cy = std::cos(pose_.yaw), sy = std::sin(pose_.yaw);
  pose_.x += cy * dx - sy * dy;
  pose_.y += sy * dx + cy * dy;
  pose_.yaw = wrap_angle(pose_.yaw + dtheta);
  distance_ += std::hypot(vx, vy) * h;
  yaw_travelled_ += std::abs(dtheta);

  if (switch_phase_ == SwitchPhase::kTurning) {
    switch_elapsed_ += h;
    if (switch_elapsed_ >= switch_duration_ - 1e-9 && !hold_switch_) {
      switch_elapsed_ = switch_duration_;
      mode_ = switch_target_;
      steering_ = 0.0;
      steering_velocity_ = 0.0;
      target_ = MotionTarget{};
      emergency_ = false;
      switch_phase_ = SwitchPhase::kNone;
    }
  }
}

}  // namespace ranger::sim
