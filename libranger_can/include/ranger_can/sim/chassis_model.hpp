// The motion physics of the virtual RANGER: what the body and its four wheels do, in REP-103
// terms, given what the chassis has been asked to do. No CAN here (virtual_chassis.hpp speaks the
// protocol) and no clock (the caller advances time), so the model is exact and deterministic.
//
// The model keeps one body-level steering quantity per motion mode and one speed:
//  * dual Ackermann: the mean front-wheel angle (alpha+beta)/2 (interpretation.hpp, open point 6)
//    and the speed of the body centre; the centre of rotation lies on the body's y axis;
//  * oblique (crab): the direction of travel and the speed along it; no rotation;
//  * spin: the wheels stand tangent to the circle through them; the speed is the wheels'
//    tangential speed (open point 5), counter-clockwise positive;
//  * side slip (MINI V1, agx_v2 mode 4): every wheel at 90 deg; the speed is the body's lateral
//    speed, left positive;
//  * park (agx_v2): the wheels stand as for spin and nothing moves (speed held at zero).
// Steering slews towards its target at a finite rate and the speed follows with finite
// acceleration. The body twist follows from (mode, steering, speed) and each wheel's velocity is
// the rigid-body velocity of its contact point, v_i = (vx - wz*y_i, vy + wz*x_i), so the reported
// wheels always agree with the motion. Each wheel's angle is kept in [-90 deg, 90 deg] with a
// signed speed (a wheel turned by 180 deg is the same wheel running backwards). The relations are
// derived here from interpretation.hpp alone, deliberately not through kinematics.cpp: the
// simulator is the independent oracle the controller's kinematics and odometry are tested against.
//
// A motion-mode switch first brings the body to rest, then turns the wheels from where they stand
// to the new mode's neutral position along a TurnProfile (switch_model.hpp: a set duration, or the
// field's slew); only then is the new mode current.
#pragma once

#include <array>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"  // BodyTwist, WheelState(s)
#include "ranger_can/control/odometry.hpp"    // Pose2D
#include "ranger_can/sim/switch_model.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

struct MotionLimits {
  double max_linear_speed = interpretation::kMaxLinearSpeedMps;  // m/s, Ackermann and oblique
  // m/s, Ackermann and oblique while |steering| > interpretation::kLargeSteeringThresholdRad (the
  // manual's lower limit beyond 20 deg; the MINI 3.0's manual: 0.7 m/s)
  double max_speed_at_large_steering = interpretation::kMaxLinearSpeedMps;
  double max_spin_speed = kMaxSpinSpeedMps;               // m/s wheel speed (0x111's range)
  double max_ackermann_angle = kMaxAckermannSteeringRad;  // rad, mean front angle (0x111's range)
  double max_oblique_angle = kMaxObliqueSteeringRad;      // rad (0x111's range)
  double acceleration = 1.0;                              // m/s^2 when speeding up
  double deceleration = 2.0;                              // m/s^2 when slowing down or stopping
  double emergency_deceleration = 6.0;                    // m/s^2 for e-stop and power cut
  double steering_rate = deg_to_rad(90.0);                // rad/s of the body steering quantity
  // rad/s^2 the steering speeds up and slows down at; 0: at steering_rate at once (a pure rate).
  // The field's profile t = d / rate + lag is a trapezoid of acceleration rate / lag (triangular
  // below rate * lag).
  double steering_acceleration = 0.0;
};

// What the chassis has been asked to do, REP-103 signs (VirtualChassis converts from the wire).
struct MotionTarget {
  // Ackermann and oblique: speed of the body centre (m/s, forward positive).
  // Spin: the wheels' tangential speed (m/s, counter-clockwise positive).
  double speed = 0.0;
  // Ackermann: mean front-wheel angle; oblique: direction of travel (rad, positive = left).
  // Ignored in spin mode.
  double steering = 0.0;
};

class ChassisModel {
 public:
  ChassisModel(const VehicleGeometry& geometry, const MotionLimits& limits);

  // Sets the target; it is clamped to the current mode's limits. Ignored while switching.
  void set_target(const MotionTarget& target);
  // Targets zero speed (steering stays). `emergency` brakes at emergency_deceleration.
  void stop(bool emergency);

  // Starts switching to `mode` (no-op when already there and not switching; a new target mode
  // during a switch restarts it, the wheels turning from where they stand). Returns true if a
  // switch started.
  bool begin_mode_switch(protocol::MotionMode mode, const TurnProfile& turn);
  bool begin_mode_switch(protocol::MotionMode mode, double turn_duration_s) {
    TurnProfile turn;
    turn.fixed_duration = turn_duration_s;
    return begin_mode_switch(mode, turn);
  }
  // While held, a switch never completes (fault injection); releasing lets it finish.
  void hold_mode_switch(bool hold) { hold_switch_ = hold; }
  bool mode_switch_held() const { return hold_switch_; }

  // Advances time by dt seconds (internally in sub-steps of at most 1 ms).
  void advance(double dt);

  // ---- state
  protocol::MotionMode mode() const { return mode_; }
  bool switching() const { return switch_phase_ != SwitchPhase::kNone; }
  protocol::MotionMode switch_target() const { return switch_target_; }
  double speed() const { return speed_; }
  double steering() const { return steering_; }
  const MotionTarget& target() const { return target_; }
  BodyTwist twist() const;
  WheelStates wheels() const;
  // Wheel angular rates (rad/s) over the last advance() call, for the steering motors.
  const std::array<double, kWheelCount>& wheel_angle_rates() const { return wheel_angle_rates_; }
  const Pose2D& pose() const { return pose_; }
  void set_pose(const Pose2D& pose) { pose_ = pose; }
  double distance_travelled() const { return distance_; }  // m, path length of the body centre
  double yaw_travelled() const { return yaw_travelled_; }  // rad, sum of |d yaw|
  const VehicleGeometry& geometry() const { return geometry_; }
  const MotionLimits& limits() const { return limits_; }

  // The wheels' states for a given mode, steering and speed (used for reports and tests).
  WheelStates wheels_for(protocol::MotionMode mode, double steering, double speed) const;
  // The body twist for a given mode, steering and speed.
  BodyTwist twist_for(protocol::MotionMode mode, double steering, double speed) const;

 private:
  enum class SwitchPhase { kNone, kStopping, kTurning };

  void sub_step(double h);
  void start_turning(const WheelStates& now);  // the wheels begin turning from `now`
  double clamp_steering(protocol::MotionMode mode, double steering) const;
  double clamp_speed(protocol::MotionMode mode, double speed) const;

  VehicleGeometry geometry_;
  MotionLimits limits_;
  protocol::MotionMode mode_ = protocol::MotionMode::kAckermann;
  MotionTarget target_;
  bool emergency_ = false;
  double speed_ = 0.0;
  double steering_ = 0.0;
  double steering_velocity_ = 0.0;  // rad/s (steering_acceleration > 0)

  SwitchPhase switch_phase_ = SwitchPhase::kNone;
  protocol::MotionMode switch_target_ = protocol::MotionMode::kAckermann;
  TurnProfile switch_turn_;
  double switch_distance_ = 0.0;  // rad, the largest wheel turn of the switch
  double switch_duration_ = 0.0;
  double switch_elapsed_ = 0.0;
  bool hold_switch_ = false;
  WheelStates switch_from_{};                         // wheel angles when the wheels began turning
  std::array<double, kWheelCount> switch_turn_by_{};  // rad each wheel turns, the short way

  Pose2D pose_;
  double distance_ = 0.0;
  double yaw_travelled_ = 0.0;
  std::array<double, kWheelCount> wheel_angle_rates_{};
};

}  // namespace ranger::sim
