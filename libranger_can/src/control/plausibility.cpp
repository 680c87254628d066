#include "ranger_can/control/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <variant>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using protocol::MotionMode;
using text::degrees;
using text::format;
using S = ProtocolSetting;

// The other value of a two-valued setting, as text ("left_positive" for "right_positive").
std::string other_value(const ProtocolProfile& profile, ProtocolSetting setting) {
  const Result<std::string> now = get_setting(profile, setting);
  for (std::string_view v : profile_setting(setting).values) {
    if (!now || v != *now) return std::string(v);
  }
  return "?";
}

// A finding that names `setting` and its other value.
PlausibilityFinding finding(std::string check, ProtocolSetting setting,
                            const ProtocolProfile& profile, std::string detail) {
  PlausibilityFinding x;
  x.check = std::move(check);
  x.setting = std::string(to_string(setting));
  x.try_value = other_value(profile, setting);
  x.detail = std::move(detail);
  return x;
}

// What a steering mismatch says and which setting it suspects (`or_setting`: a second suspect
// the evidence cannot tell from the first). The text is `before`, then (with `how`) "several
// times more/less", then `after`.
struct MismatchText {
  SteeringMismatch mismatch;
  ProtocolSetting setting;
  std::optional<ProtocolSetting> or_setting;
  const char* before;
  bool how;
  const char* after;
};
constexpr MismatchText kMismatchTexts[] = {
    {SteeringMismatch::kSign111, S::kSteeringSign111, std::nullopt,
     "the wheels turned the other way (0x221 agrees with them)", false, ""},
    {SteeringMismatch::kSign271, S::kSteeringSign271, std::nullopt,
     "0x271 shows the other way, 0x221 the commanded one", false, ""},
    {SteeringMismatch::kSign111Or271, S::kSteeringSign111, S::kSteeringSign271,
     "the wheels turned the other way", false, ""},
    {SteeringMismatch::kUnit111, S::kSteeringUnit111, std::nullopt, "the wheels steered ", true,
     " than asked (0x221 agrees with them)"},
    {SteeringMismatch::kUnit271, S::kSteeringUnit271, std::nullopt, "0x271 shows ", true,
     " than asked, 0x221 what was asked"},
    {SteeringMismatch::kUnit111Or271, S::kSteeringUnit111, S::kSteeringUnit271,
     "the wheels steered ", true, " than asked"},
    {SteeringMismatch::kSign221, S::kSteeringSign221, std::nullopt, "0x221 reports the other way",
     false, ""},
    {SteeringMismatch::kUnit221, S::kSteeringUnit221, std::nullopt,
     "0x221 reports several times more or less", false, ""},
};

bool steerable(MotionMode m) {
  return m == MotionMode::kAckermann || m == MotionMode::kOblique;
}

}  // namespace

std::string PlausibilityFinding::text() const {
  return setting + ": try " + try_value + " (" + detail + ")";
}

SteeringJudgement judge_steering(double s271, std::optional<double> s221, double unit_ratio) {
  const double r = unit_ratio;
  auto close = [](double a, double b) {
    return std::fabs(a - b) <= 0.3 * std::max(1.0, std::fabs(b));
  };
  auto off_unit = [r](double s) { return std::fabs(s) > r || std::fabs(s) < 1.0 / r; };
  SteeringJudgement j;
  if (s271 < -0.3) {
    if (s221 && *s221 < -0.3) {
      j.mismatch = SteeringMismatch::kSign111;
    } else if (s221 && *s221 > 0.3) {
      j.mismatch = SteeringMismatch::kSign271;
    } else {
      j.mismatch = SteeringMismatch::kSign111Or271;
    }
  } else if (off_unit(s271)) {
    j.more = std::fabs(s271) > r;
    if (s221 && close(*s221, s271)) {
      j.mismatch = SteeringMismatch::kUnit111;
    } else if (s221 && close(*s221, 1.0)) {
      j.mismatch = SteeringMismatch::kUnit271;
    } else {
      j.mismatch = SteeringMismatch::kUnit111Or271;
    }
  } else if (s221 && *s221 < -0.3) {
    j.mismatch = SteeringMismatch::kSign221;
  } else if (s221 && off_unit(*s221)) {
    j.mismatch = SteeringMismatch::kUnit221;
  }
  return j;
}

ReferenceJudgement judge_reference(const std::array<double, kWheelCount>& measured,
                                   const std::array<double, kWheelCount>& ours,
                                   const std::array<double, kWheelCount>& other) {
  ReferenceJudgement j;
  for (int i = 0; i < kWheelCount; ++i) {
    j.error = std::max(j.error, std::fabs(measured[i] - ours[i]));
    j.error_other = std::max(j.error_other, std::fabs(measured[i] - other[i]));
    j.gap = std::max(j.gap, std::fabs(ours[i] - other[i]));
  }
  j.other_fits =
      j.error >= 0.5 * j.gap && j.error_other <= 0.3 * j.gap && j.error >= deg_to_rad(0.15);
  return j;
}

FeedbackSpeedJudgement judge_feedback_speed(double reported, double mean_wheel, double body_centre,
                                            FeedbackSpeed ours) {
  FeedbackSpeedJudgement j;
  j.mean_wheel = mean_wheel;
  j.body_centre = body_centre;
  const double gap = std::fabs(mean_wheel - body_centre);
  const bool ours_mean = ours == FeedbackSpeed::kMeanWheel;
  const double expected = ours_mean ? mean_wheel : body_centre;
  const double other = ours_mean ? body_centre : mean_wheel;
  j.other_fits =
      std::fabs(reported - expected) >= 0.7 * gap && std::fabs(reported - other) <= 0.3 * gap;
  return j;
}

Status PlausibilityConfig::validate() const {
  if (stop_after.count() <= 0 || feedback_freshness.count() <= 0 || steering_settle.count() < 0 ||
      warn_after.count() < 0 || subtle_stop_after.count() < 0 || yaw_settle.count() < 0) {
    return Error{
        Errc::kOutOfRange,
        "plausibility: stop_after and feedback_freshness must be > 0, the other durations >= 0"};
  }
  if (!(unit_ratio > 1.0) || !(min_steering > 0.0) || !(min_reference_angle > 0.0) ||
      !(min_yaw_rate > 0.0) || !(min_speed_difference > 0.0) || !(min_speed > 0.0) ||
      out_of_range_frames < 1 || !(rigid_residual > 0.0) || !(margin > 1.0)) {
    return Error{Errc::kOutOfRange,
                 "plausibility: unit_ratio must be > 1, the angles, rates and speeds > 0, "
                 "out_of_range_frames >= 1"};
  }
  return ok_status();
}

PlausibilityMonitor::PlausibilityMonitor(PlausibilityConfig config, VehicleGeometry geometry,
                                         ProtocolProfile profile)
    : config_(config), geometry_(geometry), profile_(std::move(profile)) {
  reset();
}

void PlausibilityMonitor::set_profile(const ProtocolProfile& profile) {
  profile_ = profile;
  reset();
}

void PlausibilityMonitor::reset() {
  status_ = PlausibilityStatus{};
  steer_cmd_.reset();
  steer_mode_.reset();
  yaw_cmd_sign_ = 0.0;
  out_of_range_ = 0;
  byte7_.reset();
  byte7_steps_ = byte7_increments_ = 0;
  for (Timer* t : {&steering_, &reference_, &yaw_, &speed_, &rigid_, &range_, &counter_, &bms_})
    t->clear();
  // Sign and unit mismatches stop after stop_after; subtle ones warn, then stop.
  for (Timer* t : {&steering_, &yaw_, &rigid_, &range_, &counter_}) {
    t->warn_after = std::chrono::nanoseconds(0);
    t->stop_after = config_.stop_after;
  }
  for (Timer* t : {&reference_, &speed_}) {
    t->warn_after = config_.warn_after;
    t->stop_after = config_.subtle_stop_after;
  }
  bms_.warn_after = config_.warn_after;
  bms_.stop_after = std::chrono::nanoseconds(0);  // a wrong scale misreads a voltage: warn only
}

void PlausibilityMonitor::hold(Timer& t, PlausibilityFinding f, Timestamp now,
                               std::chrono::nanoseconds, std::chrono::nanoseconds) {
  if (t.finding && t.finding->setting == f.setting && t.finding->try_value == f.try_value) {
    f.since = t.finding->since;
  } else {
    f.since = now;
  }
  f.stops = false;
  t.finding = std::move(f);
}

// ---- frames ------------------------------------------------------------------------------------

void PlausibilityMonitor::on_frame(const CanFrame& frame, Timestamp now) {
  if (!config_.enabled || frame.is_error) return;
  if (frame.id == protocol::kSteeringAnglesId || frame.id == protocol::kMotionFeedbackId) {
    if (frame.id == out_of_range_id_) {
      out_of_range_ = 0;  // the same ID decoded again: the run is over
      range_.clear();
    }
    return;
  }
  if (frame.id == protocol::kSystemStatusId) {
    ProtocolProfile agx = profile_;
    agx.error_word = ErrorWordLayout::kAgxV2_16;
    const Result<Message> m = decode(frame, agx);
    if (!m) return;
    const auto& st = std::get<SystemStatus>(*m);
    status_voltage_ = st.battery_voltage;
    if (profile_.error_word != ErrorWordLayout::kManual32) return;
    const std::uint8_t b7 = st.counter.value_or(0);
    if (byte7_) {
      ++byte7_steps_;
      if (b7 == static_cast<std::uint8_t>(*byte7_ + 1)) ++byte7_increments_;
    }
    byte7_ = b7;
    if (byte7_steps_ >= 10 && byte7_increments_ * 10 >= byte7_steps_ * 9) {
      hold(counter_,
           finding("error_word", S::kErrorWord, profile_,
                   "0x211 byte 7 rises by one per frame (" + std::to_string(byte7_increments_) +
                       " of " + std::to_string(byte7_steps_) +
                       "): a counter, read as phantom motor faults under manual32"),
           now, {}, {});
    } else if (byte7_steps_ >= 10) {
      counter_.clear();
    }
    if (byte7_steps_ >= 50) byte7_steps_ = byte7_increments_ = 0;  // a sliding judgement
    return;
  }
  if (frame.id == protocol::kBmsBaseId && status_voltage_) {
    const Result<Message> m = decode(frame, profile_);
    if (!m) return;
    const double v = std::get<BmsData>(*m).voltage;
    const double other_scale = profile_.bms_voltage_scale == 0.1 ? 0.01 : 0.1;
    const double v_other = v / profile_.bms_voltage_scale * other_scale;
    const double ref = *status_voltage_;
    const double tol = std::max(2.0, 0.05 * ref);
    if (std::fabs(v - ref) > tol && std::fabs(v_other - ref) <= tol) {
      hold(bms_,
           finding("bms_voltage", S::kBmsVoltageScale, profile_,
                   "0x361 reads " + format("%.2f", v) + " V where 0x211 reports " +
                       format("%.1f", ref) + " V"),
           now, {}, {});
    } else {
      bms_.clear();
    }
  }
}

void PlausibilityMonitor::on_rejected(const CanFrame& frame, Errc code, Timestamp now) {
  if (!config_.enabled || code != Errc::kOutOfRange) return;
  if (frame.id != protocol::kSteeringAnglesId && frame.id != protocol::kMotionFeedbackId) return;
  if (frame.id != out_of_range_id_) out_of_range_ = 0;
  out_of_range_id_ = frame.id;
  if (++out_of_range_ < config_.out_of_range_frames) return;
  const bool is_271 = frame.id == protocol::kSteeringAnglesId;
  hold(range_,
       finding("steering_unit", is_271 ? S::kSteeringUnit271 : S::kSteeringUnit221, profile_,
               std::to_string(out_of_range_) + " frames of " + (is_271 ? "0x271" : "0x221") +
                   " in a row read as beyond 100 deg"),
       now, {}, {});
  range_.finding->since = now - range_.stop_after;  // the run itself was the persistence
}

// ---- while driving -----------------------------------------------------------------------------

void PlausibilityMonitor::update(Timestamp now, const ControllerState& c, const ChassisFeedback& fb,
                                 const OdometryState& odo) {
  if (!config_.enabled) return;
  const bool judging = c.refusal == MotionRefusal::kNone && c.motion_mode && !c.chassis_switching &&
                       c.mode_switch.phase == ModeSwitchPhase::kIdle &&
                       c.last_motion_command.has_value() && c.link == LinkState::kConnected;
  if (!judging) {
    steer_cmd_.reset();
    yaw_cmd_sign_ = 0.0;
    steering_.clear();
    reference_.clear();
    yaw_.clear();
    speed_.clear();
    rigid_.clear();
  } else {
    check_steering(now, c, fb);
    check_yaw(now, c, odo);
    check_speed(now, c, fb);
    check_rigid(now, fb);
  }
  publish(now);
}

void PlausibilityMonitor::check_steering(Timestamp now, const ControllerState& c,
                                         const ChassisFeedback& fb) {
  const MotionMode mode = *c.motion_mode;
  const MotionCommand& cmd = *c.last_motion_command;
  if (!steerable(mode)) {
    steer_cmd_.reset();
    steering_.clear();
    reference_.clear();
    return;
  }
  if (!steer_cmd_ || steer_mode_ != mode ||
      std::fabs(cmd.steering_angle - *steer_cmd_) > kRadPerDeg) {
    steer_cmd_ = cmd.steering_angle;
    steer_mode_ = mode;
    steer_since_ = now;
  }
  if (now - steer_since_ < config_.steering_settle ||
      !is_fresh(fb.steering_angles, now, config_.feedback_freshness)) {
    return;
  }
  const auto wanted = wheel_angles_for_command(cmd, mode, geometry_, profile_);
  std::array<double, kWheelCount> measured{};
  double widest = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    measured[i] =
        interpretation::rep103_from_manual_wheel_angle(fb.steering_angles->value.angles[i]);
    widest = std::max(widest, std::fabs(wanted[i]));
  }
  if (widest < config_.min_steering) {
    steering_.clear();
    reference_.clear();
    return;
  }
  ++status_.checks;
  // Least-squares scale of the measured angles over the commanded ones.
  double num_ = 0.0, den = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    num_ += wanted[i] * measured[i];
    den += wanted[i] * wanted[i];
  }
  const double s271 = num_ / den;
  // 0x221's witness: what it should report for the commanded angle, and the scale it shows.
  std::optional<double> s221;
  if (is_fresh(fb.motion, now, config_.feedback_freshness)) {
    const double reported =
        interpretation::rep103_from_manual_steering(fb.motion->value.steering_angle);
    // Oblique: the direction; Ackermann: the commanded reference.
    const double expected = interpretation::rep103_from_manual_command_steering(cmd.steering_angle);
    if (std::fabs(expected) > 1e-6) s221 = reported / expected;
  }
  const SteeringJudgement j = judge_steering(s271, s221, config_.unit_ratio);
  if (j.mismatch == SteeringMismatch::kNone) {
    steering_.clear();
    if (mode == MotionMode::kAckermann && widest >= config_.min_reference_angle) {
      check_reference(now, cmd, wanted, measured);
    } else {
      reference_.clear();
    }
    return;
  }
  reference_.clear();
  // The finding's text (built only now: this check runs at every driver step).
  const MismatchText* m =
      std::find_if(std::begin(kMismatchTexts), std::end(kMismatchTexts),
                   [&](const MismatchText& t) { return t.mismatch == j.mismatch; });
  if (m == std::end(kMismatchTexts)) return;
  const std::string how = !m->how ? "" : j.more ? "several times more" : "several times less";
  PlausibilityFinding x =
      finding("steering", m->setting, profile_,
              m->before + how + m->after + ": commanded " +
                  degrees((wanted[kRightFront] + wanted[kLeftFront]) / 2) +
                  " at the front wheels, 0x271 shows " +
                  degrees((measured[kRightFront] + measured[kLeftFront]) / 2) +
                  (s221 ? ", 0x221 scale " + format("%.2f", *s221) : std::string()));
  if (m->or_setting) x.setting += " or " + std::string(to_string(*m->or_setting));
  hold(steering_, x, now, {}, {});
}

void PlausibilityMonitor::check_reference(Timestamp now, const MotionCommand& cmd,
                                          const std::array<double, kWheelCount>& wanted,
                                          const std::array<double, kWheelCount>& measured) {
  ProtocolProfile other = profile_;
  other.steering_reference = profile_.steering_reference == SteeringReference::kMeanFront
                                 ? SteeringReference::kInnerFront
                                 : SteeringReference::kMeanFront;
  const auto wanted_other = wheel_angles_for_command(cmd, MotionMode::kAckermann, geometry_, other);
  const ReferenceJudgement j = judge_reference(measured, wanted, wanted_other);
  if (!j.other_fits) {
    reference_.clear();
    return;
  }
  const std::string other_reading = other_value(profile_, S::kSteeringReference);
  hold(reference_,
       finding("steering_reference", S::kSteeringReference, profile_,
               "the wheels stand as the other reading commands (off by " + degrees(j.error) +
                   ", the " + other_reading + " reading by " + degrees(j.error_other) + ")"),
       now, {}, {});
}

void PlausibilityMonitor::check_yaw(Timestamp now, const ControllerState& c,
                                    const OdometryState& odo) {
  const double wz_cmd = c.last_solution ? c.last_solution->achieved.wz : 0.0;
  const bool commanding = std::fabs(wz_cmd) >= config_.min_yaw_rate && c.steer_first_factor >= 1.0;
  const double sign = commanding ? (wz_cmd > 0 ? 1.0 : -1.0) : 0.0;
  if (sign != yaw_cmd_sign_) {
    yaw_cmd_sign_ = sign;
    yaw_since_ = now;
  }
  if (sign == 0.0 || now - yaw_since_ < config_.yaw_settle ||
      odo.active_source != OdometrySource::kWheels) {
    yaw_.clear();
    return;
  }
  ++status_.checks;
  const double wz = odo.twist.wz;
  const MotionMode mode = *c.motion_mode;
  ProtocolSetting setting;
  std::string what;
  if (wz * wz_cmd < 0 && std::fabs(wz) >= 0.3 * std::fabs(wz_cmd)) {
    setting = mode == MotionMode::kSpin ? S::kSpinSign : S::kSteeringSign111;
    what = "turns the other way: ";
  } else if (mode == MotionMode::kSpin && std::fabs(wz) < 0.1 * std::fabs(wz_cmd)) {
    setting = S::kSpinField;
    what = "nothing turns: ";
  } else {
    yaw_.clear();
    return;
  }
  hold(yaw_,
       finding("yaw", setting, profile_,
               what + "commanded " + format("%.2f", wz_cmd) + " rad/s, the wheels show " +
                   format("%.2f", wz) + " rad/s"),
       now, {}, {});
}

void PlausibilityMonitor::check_speed(Timestamp now, const ControllerState& c,
                                      const ChassisFeedback& fb) {
  const auto fresh = config_.feedback_freshness;
  if (*c.motion_mode != MotionMode::kAckermann || c.steer_first_factor < 1.0 ||
      !is_fresh(fb.motion, now, fresh) || !is_fresh(fb.wheel_speeds, now, fresh) ||
      !is_fresh(fb.steering_angles, now, fresh)) {
    speed_.clear();
    return;
  }
  std::array<WheelMeasurement, kWheelCount> wheels{};
  double mean = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    wheels[i] = {
        interpretation::rep103_from_manual_wheel_angle(fb.steering_angles->value.angles[i]),
        fb.wheel_speeds->value.speeds[i]};
    mean += std::fabs(wheels[i].speed) / kWheelCount;
  }
  const BodyTwist t = fit_body_twist(wheels, geometry_);
  if (std::fabs(t.vx) < config_.min_speed) {
    speed_.clear();
    return;
  }
  mean = std::copysign(mean, t.vx);
  if (std::fabs(mean - t.vx) < config_.min_speed_difference) {
    speed_.clear();
    return;
  }
  ++status_.checks;
  const double reported = fb.motion->value.speed;
  const FeedbackSpeedJudgement j =
      judge_feedback_speed(reported, mean, t.vx, profile_.feedback_speed);
  if (!j.other_fits) {
    speed_.clear();
    return;
  }
  hold(speed_,
       finding("feedback_speed", S::kFeedbackSpeed, profile_,
               "0x221 reports " + format("%.3f", reported) +
                   " m/s while turning: the wheels' mean " + format("%.3f", mean) +
                   " m/s, the body centre's " + format("%.3f", t.vx) + " m/s"),
       now, {}, {});
}

void PlausibilityMonitor::check_rigid(Timestamp now, const ChassisFeedback& fb) {
  if (!is_fresh(fb.wheel_speeds, now, config_.feedback_freshness) ||
      !is_fresh(fb.steering_angles, now, config_.feedback_freshness)) {
    rigid_.clear();
    return;
  }
  if (fb.wheel_speeds->received == rigid_sample_) return;  // judged this sample already
  rigid_sample_ = fb.wheel_speeds->received;
  const auto& speeds = fb.wheel_speeds->value.speeds;
  double norm = 0.0, fastest = 0.0;
  for (double v : speeds) {
    norm += v * v;
    fastest = std::max(fastest, std::fabs(v));
  }
  if (fastest < config_.min_speed) {
    rigid_.clear();
    return;
  }
  // The angles as the wire carried them, read under each 0x271 unit and sign.
  const Result<CanFrame> wire = encode(fb.steering_angles->value, profile_);
  if (!wire) return;
  const AngleUnit units[2] = {AngleUnit::kCentidegree, AngleUnit::kMilliradian};
  const SteeringSign signs[2] = {SteeringSign::kRightPositive, SteeringSign::kLeftPositive};
  double ours = -1.0, best = 1e9;
  int best_h = -1;
  for (int h = 0; h < 4; ++h) {
    ProtocolProfile p = profile_;
    p.steering_unit_271 = units[h / 2];
    p.steering_sign_271 = signs[h % 2];
    const Result<Message> m = decode(*wire, p);
    if (!m) continue;
    const auto& a = std::get<SteeringAnglesFeedback>(*m).angles;
    std::array<WheelMeasurement, kWheelCount> wheels{};
    for (int i = 0; i < kWheelCount; ++i)
      wheels[i] = {interpretation::rep103_from_manual_wheel_angle(a[i]), speeds[i]};
    const BodyTwist t = fit_body_twist(wheels, geometry_);
    double r = 0.0;
    for (int i = 0; i < kWheelCount; ++i) {
      const WheelPosition pos = geometry_.wheel_position(i);
      const double ex = t.vx - t.wz * pos.y - speeds[i] * std::cos(wheels[i].angle);
      const double ey = t.vy + t.wz * pos.x - speeds[i] * std::sin(wheels[i].angle);
      r += ex * ex + ey * ey;
    }
    r = std::sqrt(r / norm);
    const bool is_ours = p.steering_unit_271 == profile_.steering_unit_271 &&
                         p.steering_sign_271 == profile_.steering_sign_271;
    if (is_ours) {
      ours = r;
    } else if (r < best) {
      best = r;
      best_h = h;
    }
  }
  if (ours < 0.0) return;
  ++status_.checks;
  if (best_h < 0 || ours < config_.rigid_residual || ours < config_.margin * best) {
    rigid_.clear();
    return;
  }
  PlausibilityFinding x;
  x.check = "rigid_body";
  std::string settings, values;
  if (units[best_h / 2] != profile_.steering_unit_271) {
    settings = std::string(to_string(S::kSteeringUnit271));
    values = std::string(to_string(units[best_h / 2]));
  }
  if (signs[best_h % 2] != profile_.steering_sign_271) {
    settings +=
        std::string(settings.empty() ? "" : " and ") + std::string(to_string(S::kSteeringSign271));
    values +=
        std::string(values.empty() ? "" : " and ") + std::string(to_string(signs[best_h % 2]));
  }
  x.setting = settings;
  x.try_value = values;
  x.detail =
      "the wheels' angles and speeds are no rigid-body motion under the settings (residual " +
      format("%.3f", ours) + "), they are under " + values + " (" + format("%.3f", best) +
      "); check the 0x111 steering settings with them";
  hold(rigid_, x, now, {}, {});
}

void PlausibilityMonitor::publish(Timestamp now) {
  status_.warnings.clear();
  for (Timer* t : {&range_, &counter_, &rigid_, &steering_, &yaw_, &reference_, &speed_, &bms_}) {
    if (!t->finding) continue;
    const auto held = now - t->finding->since;
    if (held >= t->warn_after) status_.warnings.push_back(*t->finding);
    if (t->stop_after.count() > 0 && held >= t->stop_after && !status_.stop) {
      PlausibilityFinding f = *t->finding;
      f.stops = true;
      status_.stop = f;
    }
  }
}

}  // namespace ranger
