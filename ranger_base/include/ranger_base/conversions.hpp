// Conversions between libranger_can's types and ROS messages. Pure functions: no protocol
// knowledge (names, units and signs come from libranger_can), no I/O, unit-tested.
//
// Time: every stamp the driver hands over is either the bus clock (CanFrame::stamp: the kernel's
// CLOCK_REALTIME receive time for SocketCAN, the node's SystemClock for `sim` and `replay:FILE`),
// which is ROS time as it is, or the driver's monotonic clock (DriverSnapshot::now, Stamped::
// received), which is only compared with itself (freshness).
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <ranger_msgs/ActuatorStateArray.h>
#include <ranger_msgs/BmsStateArray.h>
#include <ranger_msgs/RemoteState.h>
#include <ranger_msgs/SetLights.h>
#include <ranger_msgs/SystemState.h>
#include <ranger_msgs/UltrasonicState.h>
#include <ros/time.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/Range.h>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include <ranger_can/control/diagnostics.hpp>
#include <ranger_can/control/driver.hpp>
#include <ranger_can/control/vocabulary.hpp>
#include <ranger_can/sim/virtual_chassis.hpp>

#include "ranger_base/parameters.hpp"

namespace ranger_base {

// A bus-clock timestamp (nanoseconds since the Unix epoch) as ROS time; zero stays zero ("never").
ros::Time to_ros_time(ranger::Timestamp bus_stamp);

// ---- cmd_vel ----------------------------------------------------------------------------------
// The planar part of a Twist (linear.x, linear.y, angular.z) as a REP-103 body twist. The other
// components cannot be commanded on a ground vehicle and are ignored.
ranger::BodyTwist to_body_twist(const geometry_msgs::Twist& twist);
// The whole Twist as the driver's request: the planar part, and the other three for the library's
// check (a NaN or an infinity in any of the six refuses the request: ranger::check_finite).
ranger::MotionRequest to_motion_request(const geometry_msgs::Twist& twist);
// True if a component the chassis ignores (linear.z, angular.x, angular.y) is non-zero.
bool has_non_planar_components(const geometry_msgs::Twist& twist);
geometry_msgs::TwistStamped to_twist_stamped(const ranger::BodyTwist& twist, const ros::Time& stamp,
                                             const std::string& frame_id);
// What cmd_vel_out publishes for a frame the driver sent: the twist a motion command realises
// (zero for a stop, the shutdown's included); nullopt for every other kind of frame.
std::optional<ranger::BodyTwist> achieved_twist(const ranger::SentEvent& event);

// ---- odometry, TF, joints ---------------------------------------------------------------------
// Pose covariance = diag(pose_covariance_diagonal) + the odometry's growing x/y/yaw variance;
// twist covariance = diag(twist_covariance_diagonal) (ranger::pose_covariance). Stamped with the
// odometry's own stamp (the frames that produced it).
nav_msgs::Odometry to_odometry(const ranger::OdometryState& odometry, const NodeParameters& params);
geometry_msgs::TransformStamped to_transform(const nav_msgs::Odometry& odometry);
// The time of the newest per-wheel frame behind `feedback`'s joints (zero: none yet): the
// library's.
using ranger::joints_stamp;
sensor_msgs::JointState to_joint_state(const ranger::WheelJoints& joints, const ros::Time& stamp);
// The virtual chassis's ground truth, as an Odometry in the odom frame (zero covariance: exact).
nav_msgs::Odometry to_ground_truth(const ranger::sim::ChassisSnapshot& sim,
                                   const NodeParameters& params, const ros::Time& stamp);

// ---- chassis state ----------------------------------------------------------------------------
// The words (why motion is refused, the stop causes by name) are the library's
// (ranger_can/control/diagnostics.hpp: describe_refusal, refusal_name, cause_names).
ranger_msgs::SystemState to_system_state(const ranger::DriverSnapshot& snapshot,
                                         const ros::Time& stamp);
// ---- the vendor's additions (agx_v2) ------------------------------------------------------------
ranger_msgs::RemoteState to_remote_state(const ranger::RemoteState& remote, const ros::Time& stamp);
// The service's request as the driver's (ranger::lights_request: the library's check and words);
// kInvalidArgument naming the field for a mode above CUSTOM or a brightness above 100 (a
// brightness outside CUSTOM is ignored: sent as 0).
ranger::Result<ranger::LightsRequest> to_lights_request(const ranger_msgs::SetLights::Request& r);
// The lights the chassis last reported (0x231) into the response; nothing when it never did.
void fill_lights_response(const std::optional<ranger::LightsState>& lights,
                          ranger_msgs::SetLights::Response& out);

// Sets the SystemErrors fields by meaning: each fault the library's table gives for `layout`
// (ranger::fault_flags) sets the field of its name; the others stay as they are.
void fill_system_errors(std::uint32_t error_word, ranger::ErrorWordLayout layout,
                        ranger_msgs::SystemErrors& out);
ranger_msgs::DriverStatus to_driver_status(std::uint8_t status);
ranger_msgs::BmsFlags to_bms_flags(std::uint8_t status1, std::uint8_t status2);

ranger_msgs::ActuatorStateArray to_actuator_state(const ranger::ChassisFeedback& feedback,
                                                  const ros::Time& stamp);
// `now`: the driver's clock (DriverSnapshot::now), for the present flags.
ranger_msgs::BmsStateArray to_bms_state(const ranger::ChassisFeedback& feedback,
                                        ranger::Timestamp now, const ros::Time& stamp);

// The whole pack (the BMS reports, or the system status's voltage until it does). percentage in
// 0..1; technology LiFePO4 (ranger::vehicle_spec); cell_voltage / cell_temperature carry one entry
// per battery slot 1..4, NaN for an empty slot (ranger_msgs/BmsStateArray has the per-slot details
// and present flags).
sensor_msgs::BatteryState to_battery_state(const ranger::ChassisFeedback& feedback,
                                           ranger::Timestamp now, const ros::Time& stamp);
ranger_msgs::UltrasonicState to_ultrasonic_state(const ranger::DriverSnapshot& snapshot,
                                                 const ros::Time& stamp);
// One sensor (1..8) as sensor_msgs/Range in frame <frame_prefix>ultrasonic_<sensor>_link
// (ranger_description). range in m; NaN for every raw value the library does not call "ok"
// (no reading, an error code); +inf beyond max_range (REP-117).
sensor_msgs::Range to_range(int sensor, std::int16_t raw, const NodeParameters& params,
                            const ros::Time& stamp);
std::string ultrasonic_frame_id(const std::string& frame_prefix, int sensor);
// The distance a raw ultrasonic value stands for, in m (ranger::ultrasonic_range); NaN unless
// the library calls it "ok".
float ultrasonic_range_m(std::int16_t raw);

// ---- named-bit tables (message field <- libranger_can's name); tests check they are complete ---
using SystemErrorField = std::uint8_t ranger_msgs::SystemErrors::*;
using DriverStatusField = std::uint8_t ranger_msgs::DriverStatus::*;
using BmsFlagField = std::uint8_t ranger_msgs::BmsFlags::*;
const std::map<std::string_view, SystemErrorField>& system_error_fields();
const std::map<std::string_view, DriverStatusField>& driver_status_fields();
const std::map<std::string_view, BmsFlagField>& bms_flag_fields();

}  // namespace ranger_base
