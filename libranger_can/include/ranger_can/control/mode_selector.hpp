// Automatic motion-mode selection for a stream of twists, with hysteresis and dwell, and the
// oblique side memory: the choices with memory that sit between a caller's twist and the pure
// kinematics (kinematics.hpp), so that noisy teleop does not flap between modes.
#pragma once

#include <chrono>
#include <cmath>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

struct ModeSelectorConfig {
  // Thresholds with hysteresis: a mode is entered above the *_enter level and, once it is the
  // current mode, kept until the request falls below the (looser) *_exit level.
  double lateral_enter = 0.05;   // m/s |vy| above which oblique is chosen (whatever vx)
  double lateral_exit = 0.02;    // m/s |vy| below which oblique may be left
  double linear_enter = 0.02;    // m/s |(vx,vy)| below which a rotation is a pure rotation (spin)
  double linear_exit = 0.05;     // m/s |(vx,vy)| above which spin is left
  double rotation_enter = 0.05;  // rad/s |wz| above which a rotation leaves oblique
  double rotation_exit = 0.02;   // rad/s
  // The chassis's resolution: 0x111 carries 1 mm/s (and a spin wheel speed of 1 mm/s). A twist
  // whose every component is below these is not a motion the chassis can express: it is refused
  // with a named reason (ModeSelector::below_minimum) instead of being silently dropped. Any
  // twist above them drives: a small lateral velocity picks oblique when it is the larger
  // component, a small rotation without translation picks spin.
  double min_linear_speed = 0.001;  // m/s
  double min_yaw_rate = 0.002;      // rad/s
  // A different mode must be asked for continuously this long before it is chosen (filters
  // noisy teleop), and the chassis stays in a mode at least min_dwell after entering it.
  std::chrono::nanoseconds confirm_time = std::chrono::milliseconds(100);
  std::chrono::nanoseconds min_dwell = std::chrono::milliseconds(1000);
  // Oblique mode: while the direction of travel is within this band of +-90 deg, the wheels keep
  // the side of the previous oblique command (rad, 0 <= x < 90 deg; 0 disables).
  double oblique_side_band = deg_to_rad(5.0);

  Status validate() const;
};

class ModeSelector {
 public:
  explicit ModeSelector(ModeSelectorConfig config = {});

  // True when `twist` is not zero but every component is below the chassis's resolution
  // (min_linear_speed, min_yaw_rate): nothing would move.
  bool below_minimum(const BodyTwist& twist) const;

  // The mode the classification alone asks for, given the mode the chassis is in (no timing):
  //  * a rotation without (meaningful) translation: spin;
  //  * a lateral velocity above lateral_enter, or the larger of the two translation components:
  //    oblique;
  //  * a translation without rotation keeps oblique (oblique drives straight too);
  //  * otherwise dual Ackermann. A zero (or below-minimum) twist never causes a switch.
  protocol::MotionMode classify(const BodyTwist& twist, protocol::MotionMode current) const;

  // The mode to drive `twist` in, given the chassis's current mode (from 0x291) at time `now`.
  // Returns `current` until a different classification has held for confirm_time and the
  // chassis has been in `current` for min_dwell (the selector notices changes of `current`).
  protocol::MotionMode select(const BodyTwist& twist, protocol::MotionMode current, Timestamp now);

  // solve_kinematics with the oblique side hysteresis: while the direction of travel is within
  // config().oblique_side_band of +-90 deg, the steering keeps the sign of the previous moving
  // oblique command; beyond the band the pure solution (and its side) is taken. A non-oblique
  // solution forgets the side (a mode switch turns the wheels to the new mode's neutral).
  Result<KinematicsSolution> solve(const BodyTwist& twist, protocol::MotionMode mode,
                                   const VehicleGeometry& geometry, const KinematicsLimits& limits,
                                   const ProtocolProfile& profile = manual_profile());

  // Forgets pending candidates, dwell timing and the oblique side (e.g. after the link was lost).
  void reset();

  const ModeSelectorConfig& config() const { return config_; }

 private:
  ModeSelectorConfig config_;
  bool have_current_ = false;
  protocol::MotionMode current_ = protocol::MotionMode::kAckermann;
  Timestamp current_since_{0};
  bool have_candidate_ = false;
  protocol::MotionMode candidate_ = protocol::MotionMode::kAckermann;
  Timestamp candidate_since_{0};
  double oblique_side_ = 0.0;  // sign of the last moving oblique command's steering, 0 = none
};

}  // namespace ranger
