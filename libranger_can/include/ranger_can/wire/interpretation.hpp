// The manual's open points, decided once.
//
// shared/reference/PROTOCOL.md lists six places where the RANGER manual is cut off or silent
// (points 1-6); points 7-9 are further readings the code needs that PROTOCOL.md does not list.
// Each decision below is the only place in the code base that encodes it: every other file calls
// these names, so a test on a real chassis that disproves one reading is a one-line change here
// (and docs/PROTOCOL_INTERPRETATIONS.md says why each reading was chosen).
#pragma once

#include <cmath>

namespace ranger::interpretation {

// Open point 1 — 0x111 linear-speed valid range. The manual's sentence is cut off; the spec
// sheet gives 2.6 m/s as the top speed. The encoder saturates to this; kinematics clamps earlier
// to the user's configurable limit. (The manual mentions a different limit when the steering
// angle exceeds 20 degrees, without giving it: the kinematics' configurable
// `max_speed_at_large_steering` covers it.)
inline constexpr double kMaxLinearSpeedMps = 2.6;
inline constexpr double kLargeSteeringThresholdRad = 20.0 * M_PI / 180.0;

// 0x221 steering feedback: the manual states negative = left, positive = right. REP-103 is the
// opposite (positive = left, towards +y).
inline constexpr double kManualSteeringSignVsRep103 = -1.0;
// Open point 2 — 0x111 steering sign: not stated; read as the same convention as 0x221. Kept as a
// constant of its own so that a chassis turning the other way flips the command only, not the
// feedback: code that produces or reads a 0x111 angle uses the *_command_steering functions.
inline constexpr double kCommandSteeringSignVsRep103 = kManualSteeringSignVsRep103;
// Open point 3 — 0x271 per-wheel angle sign: read as the same as 0x221 (positive = right).
inline constexpr double kManualWheelAngleSignVsRep103 = -1.0;

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
// manual lists it as emergency shut-down. Decoded as VehicleStatus::kEmergencyStop.
inline constexpr bool kVehicleStatus1IsEmergencyStop = true;

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
// mean wheel speed, as 0x221 reports) is a change here only.
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

// Point 8 — 0x221 speed in Ackermann mode is the mean of the four wheels' rolling speeds (what
// the firmware measures), so the body centre moves with vx = speed / mean_i |(1 - k y_i, k x_i)|.
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
