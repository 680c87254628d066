#include "ranger_can/sim/switch_model.hpp"

#include <algorithm>
#include <cmath>

namespace ranger::sim {

SwitchModelConfig field_switch_model() {
  SwitchModelConfig c;
  c.report = SwitchReport::kAtOnce;
  c.flag_share = kFieldFlagShare;
  c.turn = SwitchTurn::kSlew;
  return c;
}

SwitchModelConfig mode_left_switch_model() {
  return SwitchModelConfig{};
}

double TurnProfile::duration(double distance) const {
  if (rate <= 0.0) return std::max(0.0, fixed_duration);
  const double d = std::abs(distance);
  // Trapezoid: d / rate + rate / a; triangle (d < rate^2 / a): 2 sqrt(d / a).
  const double t = d >= rate * rate / acceleration ? d / rate + rate / acceleration
                                                   : 2.0 * std::sqrt(d / acceleration);
  return std::max(t, minimum_time);
}

double TurnProfile::fraction(double t, double distance) const {
  if (t <= 0.0) return 0.0;
  if (rate <= 0.0) return fixed_duration <= 0.0 ? 1.0 : std::min(1.0, t / fixed_duration);
  const double d = std::abs(distance);
  if (d <= 0.0) return 1.0;
  const double a = acceleration;
  const double ramp = std::min(rate / a, std::sqrt(d / a));  // time to the peak rate
  const double peak = a * ramp;
  const double cruise = d / peak - ramp;  // time at the peak rate (0 for a triangle)
  const double total = 2.0 * ramp + cruise;
  double s;
  if (t >= total) {
    s = d;
  } else if (t < ramp) {
    s = 0.5 * a * t * t;
  } else if (t < ramp + cruise) {
    s = 0.5 * a * ramp * ramp + peak * (t - ramp);
  } else {
    const double left = total - t;
    s = d - 0.5 * a * left * left;
  }
  return std::clamp(s / d, 0.0, 1.0);
}

SwitchModel::SwitchModel(const SwitchModelConfig& config, double fixed_duration_s)
    : config_(config), fixed_duration_s_(fixed_duration_s), rng_(config.seed) {}

TurnProfile SwitchModel::turn_profile() const {
  TurnProfile p;
  p.fixed_duration = fixed_duration_s_;
  if (config_.turn == SwitchTurn::kSlew && config_.slew_rate > 0.0) {
    p.rate = config_.slew_rate;
    p.acceleration = config_.slew_lag > 0.0 ? config_.slew_rate / config_.slew_lag : 1e9;
    p.minimum_time = config_.minimum_time;
  }
  return p;
}

void SwitchModel::on_switch_started() {
  // mt19937 is specified to the bit: the same seed draws the same flags everywhere.
  const double u = static_cast<double>(rng_()) / 4294967296.0;
  flag_ = u < config_.flag_share;
}

SwitchReportValue SwitchModel::report(protocol::MotionMode mode, bool switching,
                                      protocol::MotionMode target, bool held) const {
  if (config_.report == SwitchReport::kModeLeft) return {mode, switching};
  return {switching ? target : mode, switching && (flag_ || held)};
}

}  // namespace ranger::sim
