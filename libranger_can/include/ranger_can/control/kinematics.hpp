// Kinematics, inverse and forward side by side: a REP-103 body twist in, the 0x111 command of a
// motion mode out (solve_kinematics), the twist a command produces (twist_from_command), and the
// per-wheel rigid-body relations the odometry, the controller and the simulator share. Mode
// selection with memory lives in mode_selector.hpp; the least-squares fit of a twist to measured
// wheels in odometry.hpp.
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

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// Limits the kinematics clamps to. Defaults follow the manual (0x111 ranges, spec sheet speed).
// The steering rate assumed where a model names none (our virtual RANGER's): 90 deg/s.
inline constexpr double kDefaultSteeringRateRps = deg_to_rad(90.0);

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
  // How fast the chassis turns its steering (rad/s of 0x111's steering quantity: the Ackermann
  // front angle, the oblique direction), for what the odometry assumes the wheels did during a
  // silence of the chassis. No manual gives it: the RANGER's is our virtual chassis's 90 deg/s;
  // the RANGER MINI 3.0's the field's 3.26 rad/s (docs/FIELD_FACTS.md). Not a command limit.
  double steering_rate = kDefaultSteeringRateRps;

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
// What became of a request, for a warning: "spin_saturated: asked (vx, vy, wz) = (0 m/s, 0 m/s,
// 1e+06 rad/s), driven (0 m/s, 0 m/s, 1.42 rad/s)".
std::string describe_adjustments(std::uint32_t flags, const BodyTwist& asked,
                                 const BodyTwist& driven);

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
// `limits` (saturate, never wrap), in the chassis's protocol readings `profile`. Errors:
// kNotFinite when a twist component is NaN/inf (the message names it). Pure function.
//  * Ackermann: linear_speed = vx (0x111 is read as the body-centre speed: interpretation point
//    7), steering = the front angle for curvature wz/vx that the profile's steering_reference
//    names (the mean of the two front wheels, or the inner one:
//    interpretation::ackermann_front_angle); the steering limit applies to that angle. A turn
//    tighter than the limit is clamped to it with the curvature's sign kept (kSteeringSaturated);
//    vx = 0 with wz != 0 gives zero speed and full lock towards wz (kRotationDropped).
//  * Oblique: linear_speed = +-|(vx, vy)|, steering = direction of travel folded into
//    [-90, 90] deg (a reverse crab is a negative speed); wz is dropped. Within `oblique_hint.band`
//    of +-90 deg the steering takes the hinted side instead (the same wheel line, the speed
//    negated; clamped to the oblique steering limit, kSteeringSaturated).
//  * Spin: the wheels' tangential speed wz * hypot(L/2, W/2) (open point 5), limited to
//    max_spin_wheel_speed, goes out in the profile's spin_field (spin_speed, bytes 4-5, or
//    yaw_rate, bytes 2-3) with its spin_sign; vx, vy dropped.
Result<KinematicsSolution> solve_kinematics(const BodyTwist& twist, protocol::MotionMode mode,
                                            const VehicleGeometry& geometry,
                                            const KinematicsLimits& limits,
                                            const ObliqueSideHint& oblique_hint = {},
                                            const ProtocolProfile& profile = manual_profile());

// The body twist a 0x111 command produces in `mode` (the inverse of solve_kinematics for
// commands within the limits): what the simulator applies and what tests compare against.
BodyTwist twist_from_command(const MotionCommand& command, protocol::MotionMode mode,
                             const VehicleGeometry& geometry,
                             const ProtocolProfile& profile = manual_profile());

// The REP-103 angle of each wheel (geometry.hpp order) that a 0x111 command in `mode` steers
// to, folded into [-90, 90] deg: what 0x271 should report once the wheels have turned. In
// Ackermann mode from the command's steering (the curvature, whatever the speed), in oblique
// mode the direction of travel for every wheel, in spin mode the tangent of the spin circle.
std::array<double, kWheelCount> wheel_angles_for_command(
    const MotionCommand& command, protocol::MotionMode mode, const VehicleGeometry& geometry,
    const ProtocolProfile& profile = manual_profile());

// Largest |curvature| (1/m) dual Ackermann reaches at the steering limit `max_steering` (the
// angle the profile's steering_reference names).
double max_ackermann_curvature(double max_steering, const VehicleGeometry& geometry,
                               const ProtocolProfile& profile = manual_profile());

// ---- Per-wheel rigid-body relations (shared by odometry, simulator and tests) ----------------

// Per-wheel measurement in REP-103 terms (angle from 0x271, speed from 0x281).
using WheelMeasurement = WheelState;

// Forward kinematics: the least-squares body twist (vx, vy, wz) of four measured wheels at
// `geometry`'s positions (pure function). Each wheel i at (x_i, y_i) with heading th_i and signed
// speed s_i gives vx - wz*y_i = s_i*cos(th_i) and vy + wz*x_i = s_i*sin(th_i): eight equations
// for three unknowns, solved in closed form through the 3x3 normal equations. One formula for
// every motion mode; a wheel turned by 180 deg with a negated speed gives the same fit.
BodyTwist fit_body_twist(const std::array<WheelMeasurement, kWheelCount>& wheels,
                         const VehicleGeometry& geometry);

// Wheel states that realise `twist`: wheel i at (x_i, y_i) moves with
// v_i = (vx - wz*y_i, vy + wz*x_i); its angle is that direction folded into [-90, 90] deg with the
// speed negated when folded. A wheel that does not move keeps `hold_angles[i]` (steering does not
// snap back when the body stops).
WheelStates wheel_states_from_twist(const BodyTwist& twist, const VehicleGeometry& geometry,
                                    const std::array<double, kWheelCount>& hold_angles = {});

}  // namespace ranger
