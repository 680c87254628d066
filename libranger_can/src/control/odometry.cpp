#include "ranger_can/control/odometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

namespace interp = ranger::interpretation;
using protocol::MotionMode;

// Slower than this (m/s, the body's or a spinning wheel's), the motion before a gap says no
// direction for the distance the chassis's odometer counted in it.
constexpr double kStandstillSpeed = 1e-3;
// The gap model (gap_path): its time step (s) and most steps, the speed's rates of change it
// tries (m/s^2, log-spaced), and the most commands it keeps.
constexpr double kGapModelStep = 0.005;
constexpr int kGapModelMaxSteps = 4000;
constexpr double kGapModelMinAccel = 0.05;
constexpr double kGapModelMaxAccel = 50.0;
constexpr int kGapModelAccelerations = 40;
constexpr std::size_t kMaxCommands = 4096;

}  // namespace

Result<OdometrySource> parse_odometry_source(std::string_view text) {
  if (const auto source = kOdometrySourceNames.parse(text)) return *source;
  return Error{Errc::kInvalidArgument,
               "odometry source '" + std::string(text) + "' is neither 'wheels' nor 'motion'"};
}

Status OdometryConfig::validate() const {
  if (Status st = geometry.validate(); !st) return st;
  if (wheel_data_timeout.count() <= 0) {
    return Error{Errc::kOutOfRange, "odometry: wheel_data_timeout must be > 0"};
  }
  if (max_step.count() <= 0) return Error{Errc::kOutOfRange, "odometry: max_step must be > 0"};
  const struct {
    const char* name;
    double value;
  } variances[] = {{"twist_variance_linear", twist_variance_linear},
                   {"twist_variance_angular", twist_variance_angular},
                   {"initial_pose_variance_xy", initial_pose_variance_xy},
                   {"initial_pose_variance_yaw", initial_pose_variance_yaw},
                   {"pose_variance_per_meter", pose_variance_per_meter},
                   {"yaw_variance_per_radian", yaw_variance_per_radian},
                   {"yaw_variance_per_meter", yaw_variance_per_meter}};
  for (const auto& v : variances) {
    if (!std::isfinite(v.value) || v.value < 0.0) {
      return Error{Errc::kOutOfRange, std::string("odometry: ") + v.name + " = " +
                                          std::to_string(v.value) + " must be finite and >= 0"};
    }
  }
  return ok_status();
}

BodyTwist twist_from_motion_feedback(const MotionFeedback& feedback, MotionMode mode,
                                     const VehicleGeometry& geometry,
                                     const ProtocolProfile& profile) {
  // The spin rate as the profile reads 0x221 in spin mode.
  auto spin_rate = [&] {
    return profile.spin_field == SpinField::kYawRate
               ? interp::spin_ccw_from_wire(feedback.yaw_rate, profile)
               : interp::spin_yaw_rate_from_feedback_speed(
                     interp::spin_ccw_from_wire(feedback.speed, profile), geometry.wheelbase,
                     geometry.track);
  };
  switch (mode) {
    case MotionMode::kAckermann: {
      const double steering = interp::rep103_from_manual_steering(feedback.steering_angle);
      const double k = interp::ackermann_curvature_from_front_angle(
          steering, geometry.wheelbase, geometry.track, profile.steering_reference);
      if (std::isinf(k)) {
        // A reported angle of 90 deg or more (a corrupt frame): the limit of the formula below
        // as k grows, a rotation about the body centre at the wheels' speed; inf * 0 would make
        // the twist NaN.
        return BodyTwist{
            0.0, 0.0,
            std::copysign(1.0, k) * interp::spin_yaw_rate_from_feedback_speed(
                                        feedback.speed, geometry.wheelbase, geometry.track)};
      }
      const double vx = interp::ackermann_body_speed_from_feedback_speed(
          feedback.speed, k, geometry.wheelbase, geometry.track, profile.feedback_speed);
      return BodyTwist{vx, 0.0, k * vx};
    }
    case MotionMode::kOblique: {
      const double direction = interp::rep103_from_manual_steering(feedback.steering_angle);
      return BodyTwist{feedback.speed * std::cos(direction), feedback.speed * std::sin(direction),
                       0.0};
    }
    case MotionMode::kSpin:
      return BodyTwist{0.0, 0.0, spin_rate()};
    case MotionMode::kSideSlip:
      // Reading: 0x221's speed is the lateral speed, left positive (the vendor's odometry
      // integrates it at +90 deg).
      return BodyTwist{0.0, feedback.speed, 0.0};
    case MotionMode::kPark:  // no motion: the zero twist below
      break;
  }
  return BodyTwist{};
}

double max_yaw_rate(const KinematicsLimits& limits, const VehicleGeometry& geometry,
                    const ProtocolProfile& profile) {
  const double spin = std::fabs(interp::spin_yaw_rate_from_wheel_speed(
      limits.max_spin_wheel_speed, geometry.wheelbase, geometry.track));
  const double turn = limits.max_linear_speed *
                      max_ackermann_curvature(limits.max_ackermann_steering, geometry, profile);
  return std::max(spin, turn);
}

Pose2D integrate_pose(const Pose2D& pose, const BodyTwist& twist, double dt) {
  const double dyaw = twist.wz * dt;
  // Body-frame displacement along the arc of constant (vx, vy, wz): the integral of
  // R(wz*t) (vx, vy) dt, written with sin(d)/d and (1-cos d)/d to stay exact near d = 0.
  double s_over, c_over;  // sin(d)/d and (1 - cos(d))/d
  if (std::fabs(dyaw) < 1e-6) {
    s_over = 1.0 - dyaw * dyaw / 6.0;
    c_over = dyaw / 2.0 - dyaw * dyaw * dyaw / 24.0;
  } else {
    s_over = std::sin(dyaw) / dyaw;
    c_over = (1.0 - std::cos(dyaw)) / dyaw;
  }
  const double bx = (twist.vx * s_over - twist.vy * c_over) * dt;
  const double by = (twist.vy * s_over + twist.vx * c_over) * dt;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  return Pose2D{pose.x + c * bx - s * by, pose.y + s * bx + c * by, wrap_angle(pose.yaw + dyaw)};
}

Odometry::Odometry(OdometryConfig config) : config_(std::move(config)) {
  reset();
}

void Odometry::reset(const Pose2D& pose) {
  state_ = OdometryState{};
  state_.pose = Pose2D{pose.x, pose.y, wrap_angle(pose.yaw)};
  state_.pose_variance = {config_.initial_pose_variance_xy, config_.initial_pose_variance_xy,
                          config_.initial_pose_variance_yaw};
  state_.twist_variance = {config_.twist_variance_linear, config_.twist_variance_linear,
                           config_.twist_variance_angular};
  state_.active_source = config_.source;
  anchored_ = false;
  previous_twist_ = gap_twist_ = BodyTwist{};
  odometer_.reset();
  commands_.clear();
}

void Odometry::on_command(const MotionCommand& command, Timestamp stamp) {
  if (!commands_.empty() && stamp < commands_.back().stamp) commands_.clear();  // time went back
  commands_.push_back(SentCommand{stamp, command});
  // What a gap starting after the latest feedback needs: the newest command before it, and on.
  const Timestamp heard = odometer_ ? std::min(odometer_->stamp, state_.stamp) : state_.stamp;
  while (commands_.size() >= 2 && (commands_[1].stamp <= heard || commands_.size() > kMaxCommands))
    commands_.pop_front();
}

std::optional<Pose2D> Odometry::gap_path(const BodyTwist& motion, Timestamp start, Timestamp end,
                                         double distance) const {
  const bool ackermann = mode_ == MotionMode::kAckermann;
  const double rate = config_.limits.steering_rate;
  const double span = seconds(end - start);
  if ((!ackermann && mode_ != MotionMode::kOblique) || commands_.empty() || !(rate > 0.0) ||
      !(span > 0.0)) {
    return std::nullopt;
  }
  const VehicleGeometry& g = config_.geometry;
  const SteeringReference reference = config_.profile.steering_reference;
  // The motion before the gap as a signed speed and a steering quantity, and back.
  double v0 = 0.0, q0 = 0.0;
  if (ackermann) {
    if (std::fabs(motion.vx) <= kStandstillSpeed) return std::nullopt;
    v0 = motion.vx;
    q0 = interp::ackermann_front_angle(motion.wz / motion.vx, g.wheelbase, g.track, reference);
  } else {
    v0 = std::hypot(motion.vx, motion.vy);
    if (v0 <= kStandstillSpeed) return std::nullopt;
    q0 = std::atan2(motion.vy, motion.vx);
  }
  const auto twist_of = [&](double v, double q) {
    if (!ackermann) return BodyTwist{v * std::cos(q), v * std::sin(q), 0.0};
    const double k =
        interp::ackermann_curvature_from_front_angle(q, g.wheelbase, g.track, reference);
    return BodyTwist{v, 0.0, std::isfinite(k) ? k * v : 0.0};
  };
  // What was asked, from when (s after the start; a command before the gap counts from it).
  struct Asked {
    double t, speed, quantity;
  };
  std::vector<Asked> asked;
  for (const SentCommand& c : commands_) {
    if (c.stamp >= end) break;
    asked.push_back({std::max(0.0, seconds(c.stamp - start)), c.command.linear_speed,
                     interp::rep103_from_manual_command_steering(c.command.steering_angle)});
  }
  if (asked.empty()) return std::nullopt;
  if (!ackermann && std::fabs(std::remainder(q0 - asked.front().quantity, 2 * M_PI)) > M_PI / 2) {
    q0 = wrap_angle(q0 + M_PI);  // the same motion, reversing along the commanded direction
    v0 = -v0;
  }
  const int n = std::clamp(static_cast<int>(std::ceil(span / kGapModelStep)), 1, kGapModelMaxSteps);
  const double h = span / n;
  const auto approach = [](double x, double goal, double max_step) {
    return std::fabs(goal - x) <= max_step ? goal : x + std::copysign(max_step, goal - x);
  };
  // Rolls through the gap with the speed changing at `accel`: the body centre's path length; with
  // `pose`, advances it along the path scaled by `scale` (the curvature kept).
  const auto roll = [&](double accel, double scale, Pose2D* pose) {
    double v = v0, q = q0, rolled = 0.0;
    std::size_t k = 0;
    for (int i = 0; i < n; ++i) {
      const double t = i * h;
      while (k + 1 < asked.size() && asked[k + 1].t <= t)
        ++k;
      const bool heard = asked[k].t <= t;
      const double vn = approach(v, heard ? asked[k].speed : v, accel * h);
      const double qn = approach(q, heard ? asked[k].quantity : q, rate * h);
      const BodyTwist twist = twist_of((v + vn) / 2, (q + qn) / 2);
      rolled += std::hypot(twist.vx, twist.vy) * h;
      if (pose) *pose = integrate_pose(*pose, twist, h * scale);
      v = vn;
      q = qn;
    }
    return rolled;
  };
  // The speed's rate of change that rolls the distance counted (the closest on a log grid).
  double best_accel = 0.0, best_error = std::numeric_limits<double>::infinity(), best_rolled = 0.0;
  for (int i = 0; i <= kGapModelAccelerations; ++i) {
    const double accel =
        kGapModelMinAccel * std::pow(kGapModelMaxAccel / kGapModelMinAccel,
                                     static_cast<double>(i) / kGapModelAccelerations);
    const double rolled = roll(accel, 0.0, nullptr);
    if (std::fabs(rolled - distance) < best_error) {
      best_error = std::fabs(rolled - distance);
      best_accel = accel;
      best_rolled = rolled;
    }
  }
  if (!(best_rolled > kStandstillSpeed * h)) return std::nullopt;
  Pose2D pose = state_.pose;
  roll(best_accel, distance / best_rolled, &pose);
  return pose;
}

bool Odometry::on_frame(const CanFrame& frame) {
  if (frame.is_error) return false;
  switch (frame.id) {
    case protocol::kMotionFeedbackId:
    case protocol::kSteeringAnglesId:
    case protocol::kWheelSpeedsId:
    case protocol::kMotionModeFeedbackId:
      break;
    default:
      return false;  // not odometry input: skip the decoding
  }
  Result<Message> message = decode(frame, config_.profile);
  if (!message) return false;
  return on_message(*message, frame.stamp);
}

bool Odometry::on_message(const Message& message, Timestamp stamp) {
  return std::visit(
      [&](const auto& m) -> bool {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, SteeringAnglesFeedback>) {
          return on_steering_angles(m, stamp);
        } else if constexpr (std::is_same_v<T, WheelSpeedsFeedback>) {
          return on_wheel_speeds(m, stamp);
        } else if constexpr (std::is_same_v<T, MotionFeedback>) {
          return on_motion_feedback(m, stamp);
        } else if constexpr (std::is_same_v<T, MotionModeFeedback>) {
          return on_motion_mode(m, stamp);
        } else if constexpr (std::is_same_v<T, OdometerFeedback>) {
          return on_odometer(m, stamp);
        } else {
          return false;
        }
      },
      message);
}

bool Odometry::on_steering_angles(const SteeringAnglesFeedback& m, Timestamp stamp) {
  angles_ = m;
  angles_stamp_ = stamp;
  have_angles_ = true;
  return false;
}

bool Odometry::on_motion_mode(const MotionModeFeedback& m, Timestamp) {
  if (m.mode_known) mode_ = m.mode;
  return false;
}

bool Odometry::on_odometer(const OdometerFeedback& m, Timestamp stamp) {
  if (!m.left_distance || !m.right_distance || stamp.count() == 0) return false;  // no unit
  if (odometer_ && m.rear && !odometer_->rear) return false;  // the front axle's is in use
  const OdometerReading now{*m.left_distance, *m.right_distance, stamp, m.rear};
  const auto before = std::exchange(odometer_, now);
  if (!before || before->rear != now.rear || stamp - before->stamp <= config_.max_step) {
    return false;
  }
  // A gap in the odometer's frames. Only where the motion frames were silent too (their gap found
  // since the odometer's last reading, or still to come) is what its wheels rolled in it added,
  // along the motion before it: with motion frames coming, the pose already holds it.
  const bool motion_gap_found = state_.last_gap_end > before->stamp;
  const bool motion_gap_to_come = stamp - state_.stamp > config_.max_step;
  if (!motion_gap_found && !motion_gap_to_come) return false;
  const double d = (std::fabs(now.left - before->left) + std::fabs(now.right - before->right)) / 2;
  const BodyTwist motion = motion_gap_found ? gap_twist_ : previous_twist_;
  const double speed = std::hypot(motion.vx, motion.vy);
  const double spin_radius = std::hypot(config_.geometry.wheelbase, config_.geometry.track) / 2;
  // The time at the motion before the gap that rolls the wheels by d.
  const double rolled_per_second =
      speed > kStandstillSpeed ? speed : std::fabs(motion.wz) * spin_radius;
  if (!std::isfinite(d) || d <= 0.0 || rolled_per_second <= kStandstillSpeed) return false;
  const std::optional<Pose2D> path = gap_path(motion, before->stamp, stamp, d);
  state_.pose = path ? *path : integrate_pose(state_.pose, motion, d / rolled_per_second);
  state_.distance += d;
  state_.last_gap_odometer_distance = d;
  return true;
}

bool Odometry::wheels_fresh(Timestamp stamp) const {
  const auto fresh = [&](Timestamp t) {
    const auto age = stamp - t;
    return (age < Timestamp{0} ? -age : age) <= config_.wheel_data_timeout;
  };
  return have_angles_ && have_speeds_ && fresh(angles_stamp_) && fresh(speeds_stamp_);
}

bool Odometry::on_wheel_speeds(const WheelSpeedsFeedback& m, Timestamp stamp) {
  have_speeds_ = true;
  speeds_stamp_ = stamp;
  if (config_.source != OdometrySource::kWheels || !wheels_fresh(stamp)) return false;
  std::array<WheelMeasurement, kWheelCount> wheels{};
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    wheels[i].angle = interp::rep103_from_manual_wheel_angle(angles_.angles[i]);
    wheels[i].speed = m.speeds[i];
  }
  return step(fit_body_twist(wheels, config_.geometry), stamp, OdometrySource::kWheels);
}

bool Odometry::on_motion_feedback(const MotionFeedback& m, Timestamp stamp) {
  const bool fallback = config_.source == OdometrySource::kWheels;
  if (fallback && wheels_fresh(stamp)) return false;  // the per-wheel fit drives the pose
  const bool advanced =
      step(twist_from_motion_feedback(m, mode_, config_.geometry, config_.profile), stamp,
           OdometrySource::kMotion);
  if (advanced && fallback) ++state_.fallback_steps;
  return advanced;
}

void Odometry::account_gap(std::chrono::nanoseconds gap, Timestamp end) {
  // Nothing was heard for `gap`: the chassis may have moved as far as its limits allow. (Where a
  // chassis reports its own odometer in a known unit, e.g. the RANGER MINI 3.0's 0x311/0x312
  // reading once it is decoded, the distance it reports for the gap belongs here: the pose would
  // advance by it, and only what it does not tell would widen the variance.)
  const double g = seconds(gap);
  const double reach = config_.limits.max_linear_speed * g;
  const double turn =
      std::min(max_yaw_rate(config_.limits, config_.geometry, config_.profile) * g, M_PI);
  state_.pose_variance[0] += reach * reach;
  state_.pose_variance[1] += reach * reach;
  state_.pose_variance[2] += turn * turn;
  state_.last_gap = gap;
  state_.last_gap_end = end;
  ++state_.gaps;
  gap_twist_ = previous_twist_;
}

bool Odometry::step(const BodyTwist& twist, Timestamp stamp, OdometrySource source) {
  if (!std::isfinite(twist.vx) || !std::isfinite(twist.vy) || !std::isfinite(twist.wz)) {
    ++state_.skipped_steps;  // never let one bad estimate poison the pose
    return false;
  }
  state_.twist = twist;
  state_.active_source = source;
  const auto reanchor = [&]() {
    anchored_ = stamp.count() != 0;
    state_.stamp = stamp;
    previous_twist_ = twist;
    ++state_.skipped_steps;
    return false;
  };
  if (stamp.count() == 0 || !anchored_) return reanchor();
  const auto elapsed = stamp - state_.stamp;
  if (elapsed.count() == 0) return false;  // a second frame of the same instant: nothing to add
  if (elapsed > config_.max_step) account_gap(elapsed, stamp);
  if (elapsed.count() < 0 || elapsed > config_.max_step) return reanchor();

  const double dt = seconds(elapsed);
  const BodyTwist mean{(previous_twist_.vx + twist.vx) / 2.0, (previous_twist_.vy + twist.vy) / 2.0,
                       (previous_twist_.wz + twist.wz) / 2.0};
  state_.pose = integrate_pose(state_.pose, mean, dt);
  const double ds = std::hypot(mean.vx, mean.vy) * dt;
  const double dyaw = std::fabs(mean.wz) * dt;
  state_.distance += ds;
  state_.pose_variance[0] += config_.pose_variance_per_meter * ds;
  state_.pose_variance[1] += config_.pose_variance_per_meter * ds;
  state_.pose_variance[2] +=
      config_.yaw_variance_per_radian * dyaw + config_.yaw_variance_per_meter * ds;
  state_.stamp = stamp;
  previous_twist_ = twist;
  ++state_.steps;
  return true;
}

}  // namespace ranger
