// Conversions between libranger_can's types and ROS messages. Pure functions: no protocol
// knowledge (bit positions, signs, units all come from libranger_can), no I/O, unit-tested.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <ranger_msgs/ActuatorStateArray.h>
#include <ranger_msgs/BmsStateArray.h>
#include <ranger_msgs/SystemState.h>
#include <ranger_msgs/UltrasonicState.h>
#include <ros/time.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/Range.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include <ranger_can/control/controller.hpp>
#include <ranger_can/control/odometry.hpp>
#include <ranger_can/sim/virtual_chassis.hpp>

#include "ranger_base/parameters.hpp"
#include "ranger_base/wheel_joints.hpp"

namespace ranger_base {

// Maps the link's monotonic clock to ROS time, from one pair of readings taken together.
class TimeMapper {
 public:
  TimeMapper(const ros::Time& ros_now, ranger::Timestamp link_now)
      : ros_now_(ros_now), link_now_(link_now) {}
  // Zero (ros::Time()) for a zero timestamp, i.e. "never".
  ros::Time to_ros(ranger::Timestamp t) const;

 private:
  ros::Time ros_now_;
  ranger::Timestamp link_now_;
};

// Feedback older than this many nominal periods counts as absent (e.g. an unfitted battery).
inline constexpr int kStalePeriods = 3;

// ---- cmd_vel ----------------------------------------------------------------------------------
// The planar part of a Twist (linear.x, linear.y, angular.z) as a REP-103 body twist. The other
// components cannot be commanded on a ground vehicle and are ignored.
ranger::BodyTwist to_body_twist(const geometry_msgs::Twist& twist);
// True if a component the chassis ignores (linear.z, angular.x, angular.y) is non-zero.
bool has_non_planar_components(const geometry_msgs::Twist& twist);
geometry_msgs::TwistStamped to_twist_stamped(const ranger::BodyTwist& twist, const ros::Time& stamp,
                                             const std::string& frame_id);

// ---- odometry, TF, joints ---------------------------------------------------------------------
// Pose covariance = diag(pose_covariance_diagonal) + the odometry's growing x/y/yaw variance;
// twist covariance = diag(twist_covariance_diagonal).
nav_msgs::Odometry to_odometry(const ranger::OdometryState& odometry, const NodeParameters& params,
                               const ros::Time& stamp);
geometry_msgs::TransformStamped to_transform(const nav_msgs::Odometry& odometry);
sensor_msgs::JointState to_joint_state(const WheelJoints& joints, const ros::Time& stamp);
// The virtual chassis's ground truth, as an Odometry in the odom frame (zero covariance: exact).
nav_msgs::Odometry to_ground_truth(const ranger::sim::ChassisSnapshot& sim,
                                   const NodeParameters& params, const ros::Time& stamp);

// ---- chassis state ----------------------------------------------------------------------------
ranger_msgs::SystemState to_system_state(const ranger::ControllerState& state,
                                         const ros::Time& stamp);
// Sets every SystemErrors field from the 0x211 error word, through libranger_can's bit names.
void fill_system_errors(std::uint32_t error_word, ranger_msgs::SystemErrors& out);
ranger_msgs::DriverStatus to_driver_status(std::uint8_t status);
ranger_msgs::BmsFlags to_bms_flags(std::uint8_t status1, std::uint8_t status2);

ranger_msgs::ActuatorStateArray to_actuator_state(const ranger::ChassisFeedback& feedback,
                                                  const TimeMapper& time, const ros::Time& stamp);
ranger_msgs::BmsStateArray to_bms_state(const ranger::ChassisFeedback& feedback,
                                        const TimeMapper& time, ranger::Timestamp link_now,
                                        const ros::Time& stamp);
// The whole pack (BMS 0x361/0x362, or 0x211's voltage until the BMS reports). percentage in 0..1;
// cell_voltage / cell_temperature carry one entry per battery slot 1..4, NaN for an empty slot
// (ranger_msgs/BmsStateArray has the per-slot details and present flags).
sensor_msgs::BatteryState to_battery_state(const ranger::ControllerState& state,
                                           ranger::Timestamp link_now, const ros::Time& stamp);
ranger_msgs::UltrasonicState to_ultrasonic_state(const ranger::ControllerState& state,
                                                 const ros::Time& stamp);
// One sensor (1..8) as sensor_msgs/Range in frame ultrasonic_<sensor>_link (ranger_description).
// range = raw / 1000 m; NaN for an error code; +inf beyond max_range (REP-117).
sensor_msgs::Range to_range(int sensor, std::int16_t raw, const UltrasonicRangeParameters& params,
                            const ros::Time& stamp);
std::string ultrasonic_frame_id(int sensor);

// ---- named-bit tables (message field <- libranger_can bit name); tests check they are complete --
using SystemErrorField = std::uint8_t ranger_msgs::SystemErrors::*;
using DriverStatusField = std::uint8_t ranger_msgs::DriverStatus::*;
using BmsFlagField = std::uint8_t ranger_msgs::BmsFlags::*;
const std::map<std::string_view, SystemErrorField>& system_error_fields();
const std::map<std::string_view, DriverStatusField>& driver_status_fields();
const std::map<std::string_view, BmsFlagField>& bms_flag_fields();

}  // namespace ranger_base
