// Kinematics: a REP-103 body twist in, the chassis's motion mode and 0x111 command out, and the
// rigid-body relations the odometry and the simulator share.
//
// The RANGER steers all four wheels and has three motion modes (0x141):
//   * dual Ackermann: front and rear wheels steer opposite ways, the centre of rotation lies on the
//     body's y axis; the body moves with vx and wz = curvature * vx (no vy).
//   * oblique (crab): all wheels parallel; the body translates with (vx, vy) and does not rotate.
//   * spin: wheels tangent to a circle around the body centre; the body rotates with wz only.
// Every sign convention and unit conversion between REP-103 and the manual goes through
// interpretation.hpp; every dimension comes from VehicleGeometry.
#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"

namespace ranger {

// Limits the kinematics clamps to. Defaults follow the manual (0x111 ranges, spec sheet speed).
struct KinematicsLimits {
  double max_linear_speed = 1.5;  // m/s, |0x111 linear speed|; capped at
                                  // interpretation::kMaxLinearSpeedMps by validate()
  // The manual names a lower speed limit "when the steering angle > 20 deg" without giving it:
  // applied when |steering| > interpretation::kLargeSteeringThresholdRad (Ackermann and oblique).
  double max_speed_at_large_steering = 1.5;  // m/s
  // Steering and spin default to the protocol's full 0x111 range (codec.hpp).
  double max_ackermann_steering = kMaxAckermannSteeringRad;  // rad, mean front-wheel angle
  double max_oblique_steering = kMaxObliqueSteeringRad;      // rad, direction of travel
  double max_spin_wheel_speed = kMaxSpinSpeedMps;            // m/s wheel tangential speed

  // Every field finite, positive and within the protocol's range; the message names the field.
  Status validate() const;
};

// Why a command differs from the twist that was asked for. Bit flags, combined with |.
enum KinematicsFlag : std::uint32_t {
  kKinematicsExact = 0,
  kSpeedSaturated = 1u << 0,      // linear speed clamped to the (large-steering) speed limit
  kSteeringSaturated = 1u << 1,   // steering clamped; in Ackermann the curvature's sign is kept
  kSpinSaturated = 1u << 2,       // spin wheel speed clamped to max_spin_wheel_speed
  kLateralDropped = 1u << 3,      // vy cannot be expressed in this mode (Ackermann, spin)
  kRotationDropped = 1u << 4,     // wz cannot be expressed (oblique; Ackermann at vx = 0)
  kTranslationDropped = 1u << 5,  // vx/vy cannot be expressed (spin)
};
// "speed_saturated|lateral_dropped", or "exact" for 0.
std::string kinematics_flags_to_string(std::uint32_t flags);

// The chassis command for one twist in one motion mode.
struct KinematicsSolution {
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  MotionCommand command;  // 0x111 fields, manual signs/units (see codec.hpp)
  BodyTwist achieved;     // the twist this command produces (REP-103), after clamping/dropping
  std::uint32_t flags = kKinematicsExact;  // KinematicsFlag bits
};

// Which way an oblique command's wheels should point when the direction of travel is near
// +-90 deg, where the fold into [-90, 90] deg is ambiguous (see ModeSelector::solve).
struct ObliqueSideHint {
  double side = 0.0;  // sign of the preferred REP-103 steering: +1, -1, or 0 (no preference)
  double band = 0.0;  // rad: the hint applies while the direction is within this of +-90 deg
};

// Computes the 0x111 command that realises `twist` as closely as `mode` allows, clamped to
// `limits` (saturate, never wrap). Errors: kNotFinite when a twist component is NaN/inf (the
// message names it). Pure function.
//  * Ackermann: linear_speed = vx (0x111 is read as the body-centre speed: interpretation point
//    7), steering = the mean front-wheel angle for curvature wz/vx
//    (interpretation::ackermann_mean_front_angle). A turn tighter than the
//    steering limit is clamped to the limit with the curvature's sign kept (kSteeringSaturated);
//    vx = 0 with wz != 0 gives zero speed and full lock towards wz (kRotationDropped).
//  * Oblique: linear_speed = +-|(vx, vy)|, steering = direction of travel folded into
//    [-90, 90] deg (a reverse crab is a negative speed); wz is dropped. Within `oblique_hint.band`
//    of +-90 deg the steering takes the hinted side instead (the same wheel line, the speed
//    negated; clamped to the oblique steering limit, kSteeringSaturated).
//  * Spin: spin_speed = wz * hypot(L/2, W/2) (interpretation open point 5); vx, vy dropped.
Result<KinematicsSolution> solve_kinematics(const BodyTwist& twist, protocol::MotionMode mode,
                                            const VehicleGeometry& geometry,
                                            const KinematicsLimits& limits,
                                            const ObliqueSideHint& oblique_hint = {});

// The body twist a 0x111 command produces in `mode` (the inverse of solve_kinematics for
// commands within the limits): what the simulator applies and what tests compare against.
BodyTwist twist_from_command(const MotionCommand& command, protocol::MotionMode mode,
                             const VehicleGeometry& geometry);

// Largest |curvature| (1/m) dual Ackermann reaches at the mean front-wheel angle `max_steering`.
double max_ackermann_curvature(double max_steering, const VehicleGeometry& geometry);

// ---- Per-wheel rigid-body relations (shared by odometry, simulator and tests) ----------------

// Wheel states that realise `twist`: wheel i at (x_i, y_i) moves with
// v_i = (vx - wz*y_i, vy + wz*x_i); its angle is that direction folded into [-90, 90] deg with the
// speed negated when folded. A wheel that does not move keeps `hold_angles[i]` (steering does not
// snap back when the body stops).
WheelStates wheel_states_from_twist(const BodyTwist& twist, const VehicleGeometry& geometry,
                                    const std::array<double, kWheelCount>& hold_angles = {});

// ---- Automatic motion-mode selection with hysteresis and dwell --------------------------------

struct ModeSelectorConfig {
  // Thresholds with hysteresis: a mode is entered above the *_enter level and, once it is the
  // current mode, kept until the request falls below the (looser) *_exit level.
  double lateral_enter = 0.05;   // m/s |vy| above which oblique is chosen
  double lateral_exit = 0.02;    // m/s |vy| below which oblique may be left
  double linear_enter = 0.02;    // m/s |(vx,vy)| below which a rotation is a pure rotation (spin)
  double linear_exit = 0.05;     // m/s |(vx,vy)| above which spin is left
  double rotation_enter = 0.05;  // rad/s |wz| above which a rotation counts (spin; leaving oblique)
  double rotation_exit = 0.02;   // rad/s
  // A different mode must be asked for continuously this long before it is chosen (filters
  // noisy teleop), and the chassis stays in a mode at least min_dwell after entering it.
  std::chrono::nanoseconds confirm_time = std::chrono::milliseconds(100);
  std::chrono::nanoseconds min_dwell = std::chrono::milliseconds(1000);
  // Oblique mode: while the direction of travel is within this band of +-90 deg, the wheels keep
  // the side of the previous oblique command (rad, 0 <= x < 90 deg; 0 disables).
  double oblique_side_band = 5.0 * M_PI / 180.0;

  Status validate() const;
};

// The choices with memory for a stream of twists, so that noisy teleop does not flap:
//  * the motion mode (select): lateral velocity -> oblique, pure rotation -> spin, otherwise dual
//    Ackermann. A zero twist never causes a switch, and oblique is kept while the request has no
//    rotation (oblique drives straight too).
//  * in oblique mode, the side the wheels point to (solve): a pure lateral request with a tiny
//    noisy vx would otherwise swing the wheels by 180 deg (+89.9 deg <-> -89.9 deg with the speed
//    negated) at every sign change of vx.
// Deterministic: time comes from the caller.
class ModeSelector {
 public:
  explicit ModeSelector(ModeSelectorConfig config = {});

  // The mode the classification alone asks for, given the mode the chassis is in (no timing).
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
                                   const VehicleGeometry& geometry, const KinematicsLimits& limits);

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
