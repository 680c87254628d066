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
// time; they are not integrated (and are counted). A gap (the chassis silent, the bus down) is
// not forgotten: the pose variance grows by what the chassis could have moved in it, at its
// limits, and the state says how long it was (last_gap).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
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
  // After a gap of g seconds (a step longer than max_step, not integrated):
  //   var_x, var_y += (max_speed * g)^2,  var_yaw += min((max_yaw_rate * g)^2, pi^2)
  // with max_speed = limits.max_linear_speed and max_yaw_rate the faster of a spin at
  // limits.max_spin_wheel_speed and an Ackermann turn at full speed and full lock.

  // Decoding, and 0x221's readings (steering reference, speed meaning, spin field and sign).
  ProtocolProfile profile;
  // What the chassis can do (the driver gives the controller's): the bound of what it could have
  // moved during a gap in its feedback.
  KinematicsLimits limits;

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
  // Gaps in the feedback: a step longer than max_step (the chassis silent, the bus down), not
  // integrated; the pose variance grew by what the chassis could have moved in it. The latest
  // one's length on the frames' clock and the frame time the feedback returned (0: none since
  // reset), and how many there were.
  std::chrono::nanoseconds last_gap{0};
  Timestamp last_gap_end{0};
  std::uint64_t gaps = 0;
  // What the chassis's own odometer (0x311, else 0x312, where it reports metres: the RANGER MINI
  // 3.0) counted across the latest gap in its frames, m (the mean of its two wheels' distances,
  // unsigned), and was added to the pose along the motion before the gap; 0 = none.
  double last_gap_odometer_distance = 0.0;
};

// The fastest the chassis can turn under `limits` (rad/s): a spin at max_spin_wheel_speed or an
// Ackermann turn at max_linear_speed and full lock, whichever is faster.
double max_yaw_rate(const KinematicsLimits& limits, const VehicleGeometry& geometry,
                    const ProtocolProfile& profile = manual_profile());

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
  // The chassis's own odometer: where it reports metres, the distance it counted across a gap in
  // its frames advances the pose along the path the chassis drove in the gap, as far as the
  // commands tell it (on_command): from the motion before the gap, its steering quantity (the
  // Ackermann front angle, the oblique direction) turning toward what each command asked at
  // limits.steering_rate, its speed toward what each asked at the one constant rate that rolls
  // the distance counted. Without commands (a log without the host's frames), and in spin, side
  // slip and park, along the motion before the gap. The gap's variance (account_gap) stays.
  bool on_odometer(const OdometerFeedback& m, Timestamp stamp);
  // A 0x111 the host sent, stamped on the frames' clock: what the chassis was asked to do while
  // it was silent (on_odometer). Kept until a later one is older than the latest feedback.
  void on_command(const MotionCommand& command, Timestamp stamp);

  // Back to `pose` with the initial covariance; twist, counters and time anchor cleared.
  void reset(const Pose2D& pose = {});
  // Reads later frames under `profile` (a setting learned while driving); the pose stays.
  void set_profile(const ProtocolProfile& profile) { config_.profile = profile; }

  const OdometryState& state() const { return state_; }
  const OdometryConfig& config() const { return config_; }

 private:
  bool wheels_fresh(Timestamp stamp) const;
  void account_gap(std::chrono::nanoseconds gap, Timestamp end);
  bool step(const BodyTwist& twist, Timestamp stamp, OdometrySource source);
  // The pose after rolling `distance` from `start` to `end` as on_odometer says (nullopt: no
  // commands, or a mode or motion the model does not cover).
  std::optional<Pose2D> gap_path(const BodyTwist& motion, Timestamp start, Timestamp end,
                                 double distance) const;

  OdometryConfig config_;
  OdometryState state_;
  bool anchored_ = false;
  BodyTwist previous_twist_;
  BodyTwist gap_twist_;  // previous_twist_ when the latest gap was found: the motion before it

  struct OdometerReading {
    double left = 0.0, right = 0.0;  // m
    Timestamp stamp{0};
    bool rear = false;
  };
  std::optional<OdometerReading> odometer_;  // the latest, of the axle in use (front first)
  struct SentCommand {
    Timestamp stamp{0};
    MotionCommand command;
  };
  std::deque<SentCommand> commands_;  // oldest first; the newest before the feedback's kept

  bool have_angles_ = false;
  SteeringAnglesFeedback angles_;
  Timestamp angles_stamp_{0};
  bool have_speeds_ = false;
  Timestamp speeds_stamp_{0};
  protocol::MotionMode mode_ = protocol::MotionMode::kAckermann;  // power-up default until 0x291
};

}  // namespace ranger
