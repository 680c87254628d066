// Shared value types and the few helpers every layer uses: time stamps, a planar body twist and
// pose (REP-103 / REP-105), one wheel's state, degrees, angle wrapping and duration conversion.
// Nothing here knows the protocol; every layer (wire, transport, control, sim) may include it.
#pragma once

#include <array>
#include <chrono>
#include <cmath>

namespace ranger {

// Time as a clock or a bus stamps it: nanoseconds since an epoch fixed by the clock in use (the
// kernel's CLOCK_REALTIME for SocketCAN's SO_TIMESTAMP, the injected clock elsewhere). Only
// differences between two timestamps of the same source are meaningful.
using Timestamp = std::chrono::nanoseconds;

// A duration in seconds as a double (the one conversion the library uses).
inline double seconds(std::chrono::nanoseconds d) {
  return std::chrono::duration<double>(d).count();
}
// Seconds (double) to a duration, rounded to the nearest nanosecond.
inline std::chrono::nanoseconds from_seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

// One degree in radians: the one conversion between the degrees people read and type and the
// radians everything inside uses.
inline constexpr double kRadPerDeg = M_PI / 180.0;
constexpr double deg_to_rad(double deg) {
  return deg * kRadPerDeg;
}
constexpr double rad_to_deg(double rad) {
  return rad / kRadPerDeg;
}

// Wraps an angle (rad) to (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * M_PI);  // [-pi, pi]
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

// A planar body twist in base_link, REP-103: x forward, y left, yaw counter-clockwise positive.
struct BodyTwist {
  double vx = 0.0;  // m/s
  double vy = 0.0;  // m/s
  double wz = 0.0;  // rad/s
};

// A planar pose in the odom frame (REP-105).
struct Pose2D {
  double x = 0.0;    // m
  double y = 0.0;    // m
  double yaw = 0.0;  // rad, wrapped to (-pi, pi]
};

// The RANGER has four steered, driven wheels (order: control/geometry.hpp, kWheelIndex).
inline constexpr int kWheelCount = 4;

// One wheel's state in REP-103 terms: heading of the wheel's rolling direction relative to the
// body x axis (counter-clockwise positive) and the signed rolling speed along that heading.
struct WheelState {
  double angle = 0.0;  // rad, REP-103
  double speed = 0.0;  // m/s
};
using WheelStates = std::array<WheelState, kWheelCount>;

}  // namespace ranger
