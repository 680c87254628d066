// Odometry: the body twist estimated from the chassis's feedback, integrated into a planar pose
// in the odom frame (REP-105: odom -> base_link), with covariances.
//
// Primary source (`kWheels`): a least-squares fit of the body twist (vx, vy, wz) to the four
// measured wheel angles (0x271) and speeds (0x281). Each wheel i at (x_i, y_i) with REP-103
// heading th_i and signed speed s_i gives two equations
//     vx - wz*y_i = s_i*cos(th_i),    vy + wz*x_i = s_i*sin(th_i),
// eight equations for three unknowns, solved through the 3x3 normal equations. One formula for
// every motion mode, and a wheel flipped by 180 deg with a negated speed yields the same fit.
// Fallback (`kMotion`): 0x221 speed + steering interpreted per the 0x291 motion mode; used when
// configured, or automatically while per-wheel frames are missing or stale.
//
// Integration runs on the frames' own timestamps (CanFrame::stamp), one step per 0x281 (wheels)
// or 0x221 (motion) frame, with the exact arc for the mean of the previous and the new twist.
// The first frame, a timestamp going backwards and a gap longer than max_step only re-anchor the
// time; they are not integrated (and are counted).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <string_view>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

enum class OdometrySource {
  kWheels,  // per-wheel fit (0x271 + 0x281), falling back to kMotion while those are stale
  kMotion,  // 0x221 + 0x291 only
};
inline constexpr auto kOdometrySourceNames = text::enum_names<OdometrySource>({
    {OdometrySource::kWheels, "wheels"},
    {OdometrySource::kMotion, "motion"},
});
inline std::string_view to_string(OdometrySource s) {
  return kOdometrySourceNames.name(s);
}
// Parses "wheels" / "motion"; kInvalidArgument otherwise.
Result<OdometrySource> parse_odometry_source(std::string_view text);

struct OdometryConfig {
  VehicleGeometry geometry;
  OdometrySource source = OdometrySource::kWheels;
  // Per-wheel frames (0x271 and 0x281) older than this, measured on frame timestamps, count as
  // missing and the motion fallback takes over.
  std::chrono::nanoseconds wheel_data_timeout = std::chrono::milliseconds(100);
  // Steps longer than this (or going backwards) are not integrated: the time is re-anchored.
  std::chrono::nanoseconds max_step = std::chrono::milliseconds(500);

  // Covariance model (diagonals, SI units squared). Twist variances are constant; the pose
  // variance starts at the initial values and grows with the distance and angle travelled:
  //   var_xy  += pose_variance_per_meter * |ds|,  var_yaw += yaw_variance_per_radian * |dyaw|
  //            + yaw_variance_per_meter * |ds|
  double twist_variance_linear = 1e-3;      // (m/s)^2 for vx and vy
  double twist_variance_angular = 2e-3;     // (rad/s)^2 for wz
  double initial_pose_variance_xy = 1e-6;   // m^2
  double initial_pose_variance_yaw = 1e-6;  // rad^2
  double pose_variance_per_meter = 1e-3;    // m^2 per m travelled
  double yaw_variance_per_radian = 1e-3;    // rad^2 per rad turned
  double yaw_variance_per_meter = 1e-4;     // rad^2 per m travelled

  // Decoding, and 0x221's readings (steering reference, speed meaning, spin field and sign).
  ProtocolProfile profile;

  Status validate() const;  // geometry valid, durations positive, variances finite and >= 0
};

struct OdometryState {
  Timestamp stamp{0};  // timestamp of the last integrated (or anchoring) frame; 0 = none yet
  Pose2D pose;
  BodyTwist twist;                                         // latest estimate, base_link
  std::array<double, 3> pose_variance{};                   // x, y, yaw
  std::array<double, 3> twist_variance{};                  // vx, vy, wz
  OdometrySource active_source = OdometrySource::kWheels;  // what produced the last step
  double distance = 0.0;                                   // m, path length integrated since reset
  std::uint64_t steps = 0;                                 // integrated steps
  std::uint64_t skipped_steps = 0;   // first frame, backwards time, gaps > max_step, zero stamps
  std::uint64_t fallback_steps = 0;  // steps from 0x221 while the configured source was kWheels
};

// The forward kinematics the primary source uses, fit_body_twist (the least-squares body twist
// of four measured wheels), sits beside the inverse ones in kinematics.hpp.

// The body twist from 0x221 in `mode`, in the profile's readings (pure function):
//  * Ackermann: the steering angle (the front wheels' mean or the inner one: steering_reference)
//    -> curvature k (interpretation::ackermann_curvature_from_front_angle); 0x221's speed is the
//    mean of the four wheel speeds or the body centre's (feedback_speed:
//    interpretation::ackermann_body_speed_from_feedback_speed); wz = k * vx.
//  * Oblique: vx = speed*cos(angle), vy = speed*sin(angle) (angle in REP-103 signs).
//  * Spin: the wheels' tangential speed in bytes 0-1 (point 9) or the yaw rate in bytes 2-3
//    (spin_field), in the profile's spin_sign.
BodyTwist twist_from_motion_feedback(const MotionFeedback& feedback, protocol::MotionMode mode,
                                     const VehicleGeometry& geometry,
                                     const ProtocolProfile& profile = manual_profile());

// Advances `pose` by the constant body twist `twist` for `dt` seconds along the exact arc.
Pose2D integrate_pose(const Pose2D& pose, const BodyTwist& twist, double dt);

class Odometry {
 public:
  // An invalid config is not rejected here: call config.validate() first (the CLI and the node
  // do); with invalid numbers the estimates are meaningless but nothing crashes.
  explicit Odometry(OdometryConfig config = {});

  // Feeds one received frame; uses its stamp. Frames other than 0x221, 0x271, 0x281 and 0x291
  // (and undecodable frames) are ignored. Returns true when the pose was advanced.
  bool on_frame(const CanFrame& frame);
  // The same for an already decoded message received at `stamp` (frame timestamps' clock).
  bool on_message(const Message& message, Timestamp stamp);

  bool on_steering_angles(const SteeringAnglesFeedback& m, Timestamp stamp);
  bool on_wheel_speeds(const WheelSpeedsFeedback& m, Timestamp stamp);
  bool on_motion_feedback(const MotionFeedback& m, Timestamp stamp);
  bool on_motion_mode(const MotionModeFeedback& m, Timestamp stamp);

  // Back to `pose` with the initial covariance; twist, counters and time anchor cleared.
  void reset(const Pose2D& pose = {});
  // Reads later frames under `profile` (a setting learned while driving); the pose stays.
  void set_profile(const ProtocolProfile& profile) { config_.profile = profile; }

  const OdometryState& state() const { return state_; }
  const OdometryConfig& config() const { return config_; }

 private:
  bool wheels_fresh(Timestamp stamp) const;
  bool step(const BodyTwist& twist, Timestamp stamp, OdometrySource source);

  OdometryConfig config_;
  OdometryState state_;
  bool anchored_ = false;
  BodyTwist previous_twist_;

  bool have_angles_ = false;
  SteeringAnglesFeedback angles_;
  Timestamp angles_stamp_{0};
  bool have_speeds_ = false;
  Timestamp speeds_stamp_{0};
  protocol::MotionMode mode_ = protocol::MotionMode::kAckermann;  // power-up default until 0x291
};

}  // namespace ranger
