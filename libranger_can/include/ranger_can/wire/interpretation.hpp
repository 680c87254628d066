// The manual's open points and the field interpretations, decided once.
//
// shared/reference/PROTOCOL.md lists the places where the RANGER manual is cut off or silent;
// points 7-9 below are further readings the code needs. Where a reading differs between the
// manual and the vendor's later revision (PROTOCOL_AGX_V2.md), it is a run-time setting of the
// protocol profile (profile.hpp) and the functions here take the profile's value; the constants
// here are then the manual's reading (its preset). Every other file calls these names, and
// docs/PROTOCOL_INTERPRETATIONS.md says why each reading was chosen.
//
// Decoded messages carry the manual's signs whatever the profile (the codec converts), so the
// REP-103 conversions below hold for every revision.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "ranger_can/types.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::interpretation {

// Open point 1 — 0x111 linear-speed valid range. The manual's sentence is cut off; the spec
// sheet gives 2.6 m/s as the top speed. The encoder saturates to this; kinematics clamps earlier
// to the user's configurable limit. (The manual mentions a different limit when the steering
// angle exceeds 20 degrees, without giving it: the kinematics' configurable
// `max_speed_at_large_steering` covers it.)
inline constexpr double kMaxLinearSpeedMps = 2.6;
inline constexpr double kLargeSteeringThresholdRad = deg_to_rad(20.0);

// 0x221 steering feedback: the manual states negative = left, positive = right. REP-103 is the
// opposite (positive = left, towards +y). Decoded messages always use the manual's sign; the
// sign on the wire is the profile's steering_sign_221, applied by the codec.
inline constexpr double kManualSteeringSignVsRep103 = -1.0;
// Open point 2 — 0x111 steering sign: not stated; the manual preset reads it as 0x221's
// (profile: steering_sign_111, applied by the codec). Decoded and encoded MotionCommands use the
// manual's sign; code that produces or reads a 0x111 angle uses the *_command_steering functions.
inline constexpr double kCommandSteeringSignVsRep103 = kManualSteeringSignVsRep103;
// Open point 3 — 0x271 per-wheel angle sign: not stated; the manual preset reads it as 0x221's
// (positive = right; profile: steering_sign_271, applied by the codec).
inline constexpr double kManualWheelAngleSignVsRep103 = -1.0;

// A steering angle beyond any model's reach: the largest angle any RANGER model steers is 90 deg
// (oblique mode), the spin position about 58 deg. A 0x221 or 0x271 angle beyond this (after the
// profile's unit) cannot be true under that profile; the codec refuses it (Errc::kOutOfRange,
// naming the ID and the value), so a wrong unit shows as counted errors, never as motion.
inline constexpr double kMaxPlausibleSteeringRad = deg_to_rad(100.0);

// Converts a steering/wheel angle between the manual's convention and REP-103's (involutions).
// 0x221 (feedback) steering:
inline double rep103_from_manual_steering(double manual_rad) {
  return kManualSteeringSignVsRep103 * manual_rad;
}
inline double manual_from_rep103_steering(double rep103_rad) {
  return kManualSteeringSignVsRep103 * rep103_rad;
}
// 0x111 (command) steering:
inline double rep103_from_manual_command_steering(double manual_rad) {
  return kCommandSteeringSignVsRep103 * manual_rad;
}
inline double manual_from_rep103_command_steering(double rep103_rad) {
  return kCommandSteeringSignVsRep103 * rep103_rad;
}
// 0x271 per-wheel angles:
inline double rep103_from_manual_wheel_angle(double manual_rad) {
  return kManualWheelAngleSignVsRep103 * manual_rad;
}
inline double manual_from_rep103_wheel_angle(double rep103_rad) {
  return kManualWheelAngleSignVsRep103 * rep103_rad;
}

// Open point 4 — 0x211 byte 0 = 0x01 is absent from this manual's table; another printing of the
// manual lists it as emergency shut-down. Decoded as VehicleStatus::kEmergencyStop. The profile's
// vehicle_status_1_is_estop is the run-time setting (the codec uses it); this is its default.
inline constexpr bool kVehicleStatus1IsEmergencyStop = true;

// ---- 0x211 error word: the critical set (per layout) -------------------------------------------
// Faults after which the chassis does not drive until they are cleared (their own 0x441 code or
// KEY1; 0x441 code 0x00 clears only the others): collision, driver, communication and sensor
// faults, protections, calibration faults, battery under-voltage. Warnings (steering servo,
// battery warning), host-link loss (cured by commanding again), ultrasonic triggering and
// remote-control loss are transient conditions and do not count. Motor-numbered faults count for
// every motor. The fault table (protocol::kFaultTable, column `critical`) holds this reading.
const std::vector<protocol::Fault>& critical_faults();
// The bits of the critical rows of the fault table in a layout's error word.
std::uint32_t critical_error_mask(ErrorWordLayout layout);

// ---- Ultrasonic (0x342, 0x343) ----------------------------------------------------------------
// The manual: a positive value is a distance (printed "nm"; millimetres is the plausible unit), a
// negative value a code. 0 is neither: read as "no reading" (no echo, or nothing measured yet),
// never as an obstacle touching the sensor.
inline constexpr std::int16_t kUltrasonicNoReading = 0;
inline constexpr double kUltrasonicMetresPerUnit = 0.001;
// The distance in metres for a raw value that is one; nullopt for "no reading" and the codes.
inline std::optional<double> ultrasonic_distance_m(std::int16_t raw) {
  if (raw <= kUltrasonicNoReading) return std::nullopt;
  return raw * kUltrasonicMetresPerUnit;
}

// ---- BMS current sign (0x361 bytes 4-5) --------------------------------------------------------
// The manual does not say which way the current counts; the profile's bms_current_sign does.
// These give the current as a discharge (positive = the pack supplies the chassis) from the wire's
// value and back (involutions).
inline double bms_discharge_current(double wire_current, const ProtocolProfile& profile) {
  return wire_current * profile.bms_current_sign;
}
inline double bms_wire_current(double discharge_current, const ProtocolProfile& profile) {
  return discharge_current * profile.bms_current_sign;
}

// ---- Spin sign ---------------------------------------------------------------------------------
// A spin value as on the wire (0x111 spin speed or yaw rate, 0x221 in spin mode) to
// counter-clockwise positive and back (the profile's spin_sign; involutions). The codec passes
// spin values as they are on the wire; the kinematics, odometry and virtual chassis call these.
inline double spin_ccw_from_wire(double wire_value, const ProtocolProfile& profile) {
  return wire_value * profile.spin_sign;
}
inline double spin_wire_from_ccw(double ccw_value, const ProtocolProfile& profile) {
  return ccw_value * profile.spin_sign;
}

// Open point 5 — spin speed (0x111 bytes 4-5, mm/s, counter-clockwise positive) is the wheels'
// tangential speed, so the body yaw rate is omega = v / hypot(wheelbase/2, track/2).
inline double spin_yaw_rate_from_wheel_speed(double wheel_speed_mps, double wheelbase_m,
                                             double track_m) {
  return wheel_speed_mps / std::hypot(wheelbase_m / 2.0, track_m / 2.0);
}
inline double spin_wheel_speed_from_yaw_rate(double yaw_rate_rps, double wheelbase_m,
                                             double track_m) {
  return yaw_rate_rps * std::hypot(wheelbase_m / 2.0, track_m / 2.0);
}

// Open point 6 — in Ackermann mode 0x111 steers the same quantity that 0x221 reports: the mean
// (alpha + beta) / 2 of the two front wheels' angles. In dual Ackermann the centre of rotation
// lies on the body's y axis (x = 0), so with R the turn radius of the body centre the front
// wheels need tan(alpha) = (L/2) / (R - W/2) and tan(beta) = (L/2) / (R + W/2). These two
// functions are that reading and its inverse (REP-103 signs: positive angle = left turn =
// positive curvature).
//
// Written in curvature k = 1/R so that k = 0 (straight) and |k| -> inf (turning about the body
// centre) need no special case: the inner wheel's angle passes 90 degrees when R < W/2, and the
// mean rises strictly from 0 (k = 0) to pi/2 (|k| = inf), odd in k. The RANGER's +-40 degree
// Ackermann limit is far inside that range.
inline double ackermann_mean_front_angle(double curvature, double wheelbase_m, double track_m) {
  if (curvature == 0.0) return 0.0;
  const double k = std::fabs(curvature);
  const double inner = std::atan2(wheelbase_m / 2.0 * k, 1.0 - track_m / 2.0 * k);
  const double outer = std::atan2(wheelbase_m / 2.0 * k, 1.0 + track_m / 2.0 * k);
  return std::copysign((inner + outer) / 2.0, curvature);
}
// Inverse of ackermann_mean_front_angle, in closed form: with m the mean angle, tan(2m) =
// tan(alpha + beta) gives (L/2)^2+(W/2)^2 = D, D k^2 sin2m + L k cos2m - sin2m = 0, whose positive
// root is taken in the cancellation-free form for each sign of cos 2m. The result has the sign of
// `mean_angle`; |mean_angle| >= pi/2 gives +-infinity (turning about the body centre); NaN or a
// non-positive/non-finite wheelbase or track gives NaN.
double ackermann_curvature_from_mean_angle(double mean_angle, double wheelbase_m, double track_m);

// The other reading of point 6 (the manual's 0x221 table says "actual inner steering angle"; the
// vendor's drivers steer the inner front wheel): the inner front wheel's angle,
// tan(inner) = (L/2)|k| / (1 - (W/2)|k|), with the sign of k. It passes 90 deg at R = W/2 and
// reaches pi - atan(L/W) (about 122 deg on a RANGER) at |k| = inf.
inline double ackermann_inner_front_angle(double curvature, double wheelbase_m, double track_m) {
  if (curvature == 0.0) return 0.0;
  const double k = std::fabs(curvature);
  if (std::isinf(k)) return std::copysign(std::atan2(wheelbase_m / 2.0, -track_m / 2.0), curvature);
  return std::copysign(std::atan2(wheelbase_m / 2.0 * k, 1.0 - track_m / 2.0 * k), curvature);
}
// Its inverse in closed form: k = sin a / ((L/2) cos a + (W/2) sin a) for the magnitude a, with
// the sign of `inner_angle`; |inner_angle| >= pi - atan(L/W) gives +-infinity; NaN or a bad
// geometry gives NaN.
double ackermann_curvature_from_inner_angle(double inner_angle, double wheelbase_m, double track_m);

// Point 6 by the profile's steering_reference: the angle 0x111 steers (and 0x221 reports) in
// Ackermann mode for body-centre curvature k, and its inverse (REP-103 signs).
inline double ackermann_front_angle(double curvature, double wheelbase_m, double track_m,
                                    SteeringReference reference) {
  return reference == SteeringReference::kInnerFront
             ? ackermann_inner_front_angle(curvature, wheelbase_m, track_m)
             : ackermann_mean_front_angle(curvature, wheelbase_m, track_m);
}
inline double ackermann_curvature_from_front_angle(double angle, double wheelbase_m, double track_m,
                                                   SteeringReference reference) {
  return reference == SteeringReference::kInnerFront
             ? ackermann_curvature_from_inner_angle(angle, wheelbase_m, track_m)
             : ackermann_curvature_from_mean_angle(angle, wheelbase_m, track_m);
}

// ---- Readings beyond PROTOCOL.md's list ------------------------------------------------------

// Geometry, not a reading: in dual Ackermann at body-centre curvature k, wheel i at (x_i, y_i)
// rolls |(1 - k y_i, k x_i)| times as fast as the body centre; this is the mean of that factor
// over the four wheels at (+-L/2, +-W/2). 1 at k = 0; +inf at |k| = inf.
inline double ackermann_mean_wheel_speed_factor(double curvature, double wheelbase_m,
                                                double track_m) {
  const double along = curvature * wheelbase_m / 2.0;
  return (std::hypot(1.0 - curvature * track_m / 2.0, along) +
          std::hypot(1.0 + curvature * track_m / 2.0, along)) /
         2.0;
}

// Point 7 — 0x111 linear speed (Ackermann and oblique mode) is the speed of the body centre.
// In oblique mode every wheel rolls at the body's speed, so only Ackermann can tell the readings
// apart; oblique callers pass curvature 0, where every reading agrees. The curvature and the
// geometry are unused under this reading: they are parameters so that another reading (e.g. the
// mean wheel speed, as the manual's 0x221 reports) is a change here only.
inline double body_speed_from_command_speed(double command_speed_mps,
                                            [[maybe_unused]] double curvature,
                                            [[maybe_unused]] double wheelbase_m,
                                            [[maybe_unused]] double track_m) {
  return command_speed_mps;
}
inline double command_speed_from_body_speed(double body_speed_mps,
                                            [[maybe_unused]] double curvature,
                                            [[maybe_unused]] double wheelbase_m,
                                            [[maybe_unused]] double track_m) {
  return body_speed_mps;
}

// Point 8 — 0x221 speed in Ackermann mode is, in the manual's reading (feedback_speed
// mean_wheel), the mean of the four wheels' rolling speeds (what the firmware measures), so the
// body centre moves with vx = speed / mean_i |(1 - k y_i, k x_i)|; the vendor's revision reports
// the body centre's speed itself (feedback_speed body_centre, the overload below).
// At |k| = inf (a corrupt angle of 90 deg or more) the body-centre speed is 0.
inline double ackermann_body_speed_from_feedback_speed(double feedback_speed_mps, double curvature,
                                                       double wheelbase_m, double track_m) {
  const double factor = ackermann_mean_wheel_speed_factor(curvature, wheelbase_m, track_m);
  return factor > 0.0 ? feedback_speed_mps / factor : 0.0;
}
inline double ackermann_feedback_speed_from_body_speed(double body_speed_mps, double curvature,
                                                       double wheelbase_m, double track_m) {
  return body_speed_mps * ackermann_mean_wheel_speed_factor(curvature, wheelbase_m, track_m);
}
// Point 8 by the profile's feedback_speed: kMeanWheel as above, kBodyCentre the identity.
inline double ackermann_body_speed_from_feedback_speed(double feedback_speed_mps, double curvature,
                                                       double wheelbase_m, double track_m,
                                                       FeedbackSpeed reading) {
  return reading == FeedbackSpeed::kBodyCentre
             ? feedback_speed_mps
             : ackermann_body_speed_from_feedback_speed(feedback_speed_mps, curvature, wheelbase_m,
                                                        track_m);
}
inline double ackermann_feedback_speed_from_body_speed(double body_speed_mps, double curvature,
                                                       double wheelbase_m, double track_m,
                                                       FeedbackSpeed reading) {
  return reading == FeedbackSpeed::kBodyCentre
             ? body_speed_mps
             : ackermann_feedback_speed_from_body_speed(body_speed_mps, curvature, wheelbase_m,
                                                        track_m);
}

// Point 9 — 0x221 speed in spin mode is the wheels' signed tangential speed, counter-clockwise
// positive (the same quantity 0x111's spin speed commands, point 5, but a reading of its own so
// that a chassis reporting, say, a yaw rate changes the feedback only).
inline double spin_yaw_rate_from_feedback_speed(double feedback_speed_mps, double wheelbase_m,
                                                double track_m) {
  return feedback_speed_mps / std::hypot(wheelbase_m / 2.0, track_m / 2.0);
}
inline double spin_feedback_speed_from_yaw_rate(double yaw_rate_rps, double wheelbase_m,
                                                double track_m) {
  return yaw_rate_rps * std::hypot(wheelbase_m / 2.0, track_m / 2.0);
}

}  // namespace ranger::interpretation
