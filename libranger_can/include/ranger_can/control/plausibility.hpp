// Plausibility monitors: while driving, what the chassis reports is compared with what it should
// report if the protocol settings are right, whatever the settings came from (identification,
// a forced preset, a commissioning file). A wrong sign or unit is a runaway in waiting: detect,
// stop, say why.
//
// Pure and clock-free, like the controller: the driver feeds raw frames (on_frame), the frames
// the codec refused (on_rejected), and after every controller tick the controller's state, the
// feedback store and the odometry's twist (update). status().stop, once set, names the setting
// and the value to try; the driver passes it to ChassisController::set_implausible (a latched
// stop cause: kImplausible, re-armed only by resume(), which also clears the monitor).
//
// The checks (every threshold is a field of PlausibilityConfig, defaults below):
//  * steering (Ackermann, oblique): once the commanded angle has stood still for
//    `steering_settle`, the measured wheel angles (0x271) against wheel_angles_for_command, as a
//    least-squares scale s of measured over commanded. s < -0.3: the wheels turned the other way
//    (sign); s beyond `unit_ratio` or below its inverse: several times more or less than asked
//    (unit). 0x221's angle is the tie-breaker between the 0x111 and the 0x271 setting (two
//    witnesses against one); a 0x221 alone off is its own setting. Stops after `stop_after`.
//  * steering reference (Ackermann, >= `min_reference_angle`): the wheels fit the other reading
//    (inner front wheel vs the front wheels' mean) clearly better: warns after `warn_after`,
//    stops after `subtle_stop_after` (the robot turns about 6 % tighter or wider than asked).
//  * yaw (every mode): the commanded yaw rate (the last solution's) against the odometry's fitted
//    twist once the command has held for `yaw_settle`: the other way round is a sign (spin mode:
//    spin_sign; Ackermann: steering_sign_111); nothing turning in spin mode is the spin field.
//    Stops after `stop_after`.
//  * 0x221 speed (Ackermann, turning): the reported speed against the mean wheel speed and the
//    body centre's speed of the wheels' fit (0x281, 0x271) where the two differ by at least
//    `min_speed_difference`: warns "feedback_speed: try body_centre", stops after
//    `subtle_stop_after`.
//  * rigid body (every mode, wheels rolling at >= `min_speed`): the four wheels' angles (0x271)
//    and speeds (0x281) form one rigid-body motion (fit_body_twist) under the right 0x271 unit
//    and sign only. Another reading fitting `margin` times better while ours is off by more than
//    `rigid_residual` (relative RMS) names that reading (stops). This catches what the steering
//    check cannot: a 0x111 and a 0x271 setting both wrong the same way (a manual driver on an
//    agx_v2 chassis reads back exactly what it asked for, while the chassis steers elsewhere).
//  * 0x271/0x221 refused as beyond any model's reach (kOutOfRange), `out_of_range_frames` in a
//    row: the unit (stops).
//  * 0x211 byte 7 counting up under the manual's 32-bit error word: error_word (stops; the
//    counter reads as phantom motor faults). 0x361's voltage agreeing with 0x211's only under the
//    other scale: bms_voltage_scale (warns).
// Transients (acceleration, steer-first, mode switches, the command changing) reset the timers:
// nothing is judged while the chassis switches modes, while motion is refused, or before the
// command has held for the settle time. Feedback older than `feedback_freshness` is not judged.
// Each check decides with a pure function returning a value (judge_steering, judge_reference,
// judge_feedback_speed below); the finding's text is written from that value
// only when something is off.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

struct PlausibilityConfig {
  bool enabled = true;
  // The commanded steering must have held (within 1 deg) this long before the wheels are judged.
  std::chrono::nanoseconds steering_settle = std::chrono::milliseconds(800);
  // A sign or unit mismatch persisting this long stops.
  std::chrono::nanoseconds stop_after = std::chrono::milliseconds(500);
  // A subtle mismatch (reference, 0x221 speed, BMS scale) persisting this long warns...
  std::chrono::nanoseconds warn_after = std::chrono::milliseconds(1000);
  // ... and this long stops (0: warn only).
  std::chrono::nanoseconds subtle_stop_after = std::chrono::milliseconds(2000);
  double min_steering = deg_to_rad(3.0);         // rad: smaller commanded angles are not judged
  double min_reference_angle = deg_to_rad(5.0);  // rad: the reference needs a real turn
  double unit_ratio = 2.0;    // measured/commanded beyond this (or below 1/this): a unit mismatch
  double min_yaw_rate = 0.1;  // rad/s commanded for the yaw check
  std::chrono::nanoseconds yaw_settle = std::chrono::milliseconds(1000);
  double min_speed_difference = 0.005;  // m/s between mean wheel and body-centre speed
  double min_speed = 0.1;               // m/s for the 0x221 speed check
  int out_of_range_frames = 10;
  double rigid_residual = 0.05;  // relative RMS velocity error of the wheels' rigid-body fit
  double margin = 3.0;           // another reading must fit this many times better
  // Feedback (0x221, 0x271, 0x281) older than this is not judged: one 50 Hz period and a half of
  // jitter margin would do; 100 ms also covers a chassis sending at half rate.
  std::chrono::nanoseconds feedback_freshness = std::chrono::milliseconds(100);

  // durations >= 0 (stop_after, feedback_freshness > 0), ratios > 1, angles > 0
  Status validate() const;
};

// ---- the decisions, as values --------------------------------------------------------------
// The steering check's verdict: which setting the measured wheels (0x271, scale s271 of measured
// over commanded) and 0x221's witness (scale s221) point at.
enum class SteeringMismatch {
  kNone,
  kSign111,       // the wheels turned the other way, 0x221 agrees with them
  kSign271,       // 0x271 shows the other way, 0x221 the commanded one
  kSign111Or271,  // the wheels turned the other way, no witness to tell which
  kUnit111,       // several times more or less than asked, 0x221 agrees with the wheels
  kUnit271,       // 0x271 several times off, 0x221 shows what was asked
  kUnit111Or271,  // several times off, no witness to tell which
  kSign221,       // the wheels are right, 0x221 reports the other way
  kUnit221,       // the wheels are right, 0x221 several times off
};
struct SteeringJudgement {
  SteeringMismatch mismatch = SteeringMismatch::kNone;
  bool more = false;  // unit mismatches: the wheels steered more than asked (else less)
};
// `s271`: least-squares scale of the measured over the commanded wheel angles; `s221`: 0x221's
// reported over its expected angle (nullopt: stale or nothing to compare); `unit_ratio` as in
// PlausibilityConfig.
SteeringJudgement judge_steering(double s271, std::optional<double> s221, double unit_ratio);

// The steering reference check: the commanded wheel angles under our reading and under the other
// one, against the measured ones (max abs errors, rad). `other_fits`: the other reading fits
// clearly better.
struct ReferenceJudgement {
  double error = 0.0;        // measured against our reading
  double error_other = 0.0;  // ... against the other reading
  double gap = 0.0;          // between the two readings' commands
  bool other_fits = false;
};
ReferenceJudgement judge_reference(const std::array<double, kWheelCount>& measured,
                                   const std::array<double, kWheelCount>& ours,
                                   const std::array<double, kWheelCount>& other);

// The 0x221 speed check: the reported speed against the wheels' mean and the body centre's.
// `other_fits`: the reading that is not ours explains it, ours does not.
struct FeedbackSpeedJudgement {
  double mean_wheel = 0.0;   // m/s, signed as the body's vx
  double body_centre = 0.0;  // m/s
  bool other_fits = false;
};
FeedbackSpeedJudgement judge_feedback_speed(double reported, double mean_wheel, double body_centre,
                                            FeedbackSpeed ours);

// One mismatch: which check, the suspected setting and the value to try, what was seen.
struct PlausibilityFinding {
  std::string check;      // "steering", "steering_reference", "yaw", "feedback_speed", ...
  std::string setting;    // "steering_sign_111" (may name two: "a or b")
  std::string try_value;  // "left_positive"
  std::string detail;     // what was measured against what was commanded
  bool stops = false;     // a sign/unit mismatch (or a subtle one past subtle_stop_after)
  Timestamp since{0};     // when it began (persisting since)

  // "steering_sign_111: try left_positive (the wheels turned right ...)"
  std::string text() const;
};

struct PlausibilityStatus {
  std::vector<PlausibilityFinding> warnings;  // persistent mismatches now (WARN)
  std::optional<PlausibilityFinding> stop;    // the first one that tripped (latched until reset)
  std::uint64_t checks = 0;                   // judgements made (for diagnostics)
};

class PlausibilityMonitor {
 public:
  explicit PlausibilityMonitor(PlausibilityConfig config = {}, VehicleGeometry geometry = {},
                               ProtocolProfile profile = {});

  void set_profile(const ProtocolProfile& profile);  // also resets
  // Every received frame (0x211 byte 7, 0x361's voltage).
  void on_frame(const CanFrame& frame, Timestamp now);
  // A frame the codec refused under the profile (0x271/0x221 kOutOfRange count; others ignored).
  void on_rejected(const CanFrame& frame, Errc code, Timestamp now);
  // After every controller tick.
  void update(Timestamp now, const ControllerState& controller, const ChassisFeedback& feedback,
              const OdometryState& odometry);
  // Forget everything (resume, a new profile).
  void reset();

  const PlausibilityStatus& status() const { return status_; }

 private:
  struct Timer {
    std::optional<PlausibilityFinding> finding;
    std::chrono::nanoseconds warn_after{0};
    std::chrono::nanoseconds stop_after{0};  // 0: never stops
    void clear() { finding.reset(); }
  };
  void hold(Timer& t, PlausibilityFinding f, Timestamp now, std::chrono::nanoseconds stop_after,
            std::chrono::nanoseconds warn_after);
  void check_steering(Timestamp now, const ControllerState& c, const ChassisFeedback& fb);
  void check_reference(Timestamp now, const MotionCommand& cmd,
                       const std::array<double, kWheelCount>& wanted,
                       const std::array<double, kWheelCount>& measured);
  void check_yaw(Timestamp now, const ControllerState& c, const OdometryState& odo);
  void check_speed(Timestamp now, const ControllerState& c, const ChassisFeedback& fb);
  void check_rigid(Timestamp now, const ChassisFeedback& fb);
  void publish(Timestamp now);

  PlausibilityConfig config_;
  VehicleGeometry geometry_;
  ProtocolProfile profile_;
  PlausibilityStatus status_;

  // steering
  std::optional<double> steer_cmd_;  // the commanded angle being held (manual sign, rad)
  std::optional<protocol::MotionMode> steer_mode_;
  Timestamp steer_since_{0};
  Timer steering_, reference_;
  // yaw
  double yaw_cmd_sign_ = 0.0;
  Timestamp yaw_since_{0};
  Timer yaw_;
  // speed, rigid body
  Timer speed_, rigid_;
  Timestamp rigid_sample_{0};
  // frames
  int out_of_range_ = 0;
  std::uint32_t out_of_range_id_ = 0;
  Timer range_;
  std::optional<std::uint8_t> byte7_;
  int byte7_steps_ = 0, byte7_increments_ = 0;
  Timer counter_;
  std::optional<double> status_voltage_;
  Timer bms_;
};

}  // namespace ranger
