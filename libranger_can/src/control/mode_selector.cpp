#include "ranger_can/control/mode_selector.hpp"

#include <cmath>
#include <string>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {

using protocol::MotionMode;
namespace interp = ranger::interpretation;

Status ModeSelectorConfig::validate() const {
  const struct {
    const char* name;
    double value;
  } values[] = {{"lateral_enter", lateral_enter},       {"lateral_exit", lateral_exit},
                {"linear_enter", linear_enter},         {"linear_exit", linear_exit},
                {"rotation_enter", rotation_enter},     {"rotation_exit", rotation_exit},
                {"min_linear_speed", min_linear_speed}, {"min_yaw_rate", min_yaw_rate}};
  for (const auto& v : values) {
    if (!std::isfinite(v.value) || v.value < 0.0) {
      return Error{Errc::kOutOfRange, std::string("mode selection: ") + v.name + " = " +
                                          std::to_string(v.value) + " must be finite and >= 0"};
    }
  }
  if (lateral_exit > lateral_enter) {
    return Error{Errc::kInvalidArgument, "mode selection: lateral_exit must be <= lateral_enter"};
  }
  if (rotation_exit > rotation_enter) {
    return Error{Errc::kInvalidArgument, "mode selection: rotation_exit must be <= rotation_enter"};
  }
  if (linear_exit < linear_enter) {
    return Error{Errc::kInvalidArgument, "mode selection: linear_exit must be >= linear_enter"};
  }
  if (confirm_time.count() < 0 || min_dwell.count() < 0) {
    return Error{Errc::kOutOfRange, "mode selection: confirm_time and min_dwell must be >= 0"};
  }
  if (!(oblique_side_band >= 0.0 && oblique_side_band < M_PI / 2)) {
    return Error{Errc::kOutOfRange,
                 "mode selection: oblique_side_band = " + std::to_string(oblique_side_band) +
                     " is not in [0, pi/2) rad"};
  }
  return ok_status();
}

ModeSelector::ModeSelector(ModeSelectorConfig config) : config_(config) {}

bool ModeSelector::below_minimum(const BodyTwist& t) const {
  const bool zero = t.vx == 0.0 && t.vy == 0.0 && t.wz == 0.0;
  return !zero && std::hypot(t.vx, t.vy) < config_.min_linear_speed &&
         std::fabs(t.wz) < config_.min_yaw_rate;
}

MotionMode ModeSelector::classify(const BodyTwist& t, MotionMode current) const {
  const ModeSelectorConfig& c = config_;
  const double linear = std::hypot(t.vx, t.vy);
  const bool rotating = std::fabs(t.wz) >= c.min_yaw_rate;
  const bool translating = linear >= c.min_linear_speed;
  const double linear_threshold = current == MotionMode::kSpin ? c.linear_exit : c.linear_enter;
  const double lateral_threshold =
      current == MotionMode::kOblique ? c.lateral_exit : c.lateral_enter;

  // (Almost) no translation: a rotation is a spin; standing still never switches.
  if (linear <= linear_threshold && rotating) return MotionMode::kSpin;
  if (!translating) return current;
  // A lateral velocity beyond the noise level, or the main thing asked for, needs oblique.
  if (std::fabs(t.vy) > lateral_threshold ||
      (std::fabs(t.vy) >= c.min_linear_speed && std::fabs(t.vy) >= std::fabs(t.vx))) {
    return MotionMode::kOblique;
  }
  // Translation without a lateral component: oblique drives straight as well, so it is kept
  // until a real rotation is asked for; otherwise dual Ackermann.
  if (current == MotionMode::kOblique && std::fabs(t.wz) <= c.rotation_enter) {
    return MotionMode::kOblique;
  }
  return MotionMode::kAckermann;
}

MotionMode ModeSelector::select(const BodyTwist& twist, MotionMode current, Timestamp now) {
  if (!have_current_ || current != current_) {
    // The first mode seen is treated as long established (no dwell at start-up).
    current_since_ = have_current_ ? now : now - config_.min_dwell;
    current_ = current;
    have_current_ = true;
    have_candidate_ = false;
  }
  const MotionMode wanted = classify(twist, current);
  if (wanted == current) {
    have_candidate_ = false;
    return current;
  }
  if (!have_candidate_ || candidate_ != wanted) {
    candidate_ = wanted;
    candidate_since_ = now;
    have_candidate_ = true;
  }
  if (now - candidate_since_ >= config_.confirm_time && now - current_since_ >= config_.min_dwell) {
    return wanted;
  }
  return current;
}

Result<KinematicsSolution> ModeSelector::solve(const BodyTwist& twist, MotionMode mode,
                                               const VehicleGeometry& geometry,
                                               const KinematicsLimits& limits,
                                               const ProtocolProfile& profile) {
  Result<KinematicsSolution> solution =
      solve_kinematics(twist, mode, geometry, limits,
                       ObliqueSideHint{oblique_side_, config_.oblique_side_band}, profile);
  if (!solution) return solution;
  if (solution->mode != MotionMode::kOblique) {
    oblique_side_ = 0.0;
  } else if (solution->command.linear_speed != 0.0) {
    // A stopped command (steering 0) names no side: the previous one is kept.
    const double steering =
        interp::rep103_from_manual_command_steering(solution->command.steering_angle);
    oblique_side_ = steering > 0.0 ? 1.0 : (steering < 0.0 ? -1.0 : 0.0);
  }
  return solution;
}

void ModeSelector::reset() {
  have_current_ = false;
  have_candidate_ = false;
  oblique_side_ = 0.0;
}

}  // namespace ranger
