// ranger_base_node's ROS side: subscriptions, publications, services and diagnostics around a
// ChassisLink. All topic and service names are relative (the node works under a namespace);
// only /tf and /diagnostics are global, by their own conventions.
//
// Threads: the CAN thread lives in ChassisLink. Here, three callback queues are each spun by one
// thread: cmd_vel (so a command is never queued behind publishing), the publish timers (global
// queue), and the services (which may wait for the chassis to confirm). Every callback reads the
// link through snapshot() or posts to it; none touches the bus.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Twist.h>
#include <ranger_msgs/ClearErrors.h>
#include <ranger_msgs/SetMotionMode.h>
#include <ranger_msgs/SetUltrasonic.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <array>
#include <memory>
#include <optional>

#include <ranger_can/clock.hpp>

#include "ranger_base/chassis_link.hpp"
#include "ranger_base/diagnostics.hpp"
#include "ranger_base/parameters.hpp"

namespace ranger_base {

class RangerNode {
 public:
  // `nh`: the node's namespace (topics), `private_nh`: its parameters.
  RangerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, NodeParameters params);
  ~RangerNode();  // shutdown()

  // Starts the CAN thread, the timers and the spinners.
  void start();
  // Stops the chassis (zero 0x111) and the CAN thread, then the ROS side. Idempotent.
  void shutdown();

  ChassisLink& link() { return *link_; }

 private:
  void on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg);
  void on_publish_timer(const ros::SteadyTimerEvent& event);
  void on_state_timer(const ros::SteadyTimerEvent& event);
  void on_diagnostics_timer(const ros::SteadyTimerEvent& event);
  void on_motion_command(const MotionCommandEvent& event);  // CAN thread
  bool on_clear_errors(ranger_msgs::ClearErrors::Request& req,
                       ranger_msgs::ClearErrors::Response& res);
  bool on_set_ultrasonic(ranger_msgs::SetUltrasonic::Request& req,
                         ranger_msgs::SetUltrasonic::Response& res);
  bool on_set_motion_mode(ranger_msgs::SetMotionMode::Request& req,
                          ranger_msgs::SetMotionMode::Response& res);
  void log_state_changes(const LinkSnapshot& s);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  ros::CallbackQueue cmd_queue_, service_queue_;
  ros::NodeHandle cmd_nh_, service_nh_;  // nh_ with those queues
  const NodeParameters params_;
  ranger::SteadyClock clock_;
  std::unique_ptr<ChassisLink> link_;

  ros::Subscriber cmd_vel_sub_;
  ros::Publisher odom_pub_, joint_state_pub_, system_state_pub_, actuator_state_pub_,
      bms_state_pub_, battery_state_pub_, ultrasonic_state_pub_, cmd_vel_out_pub_,
      ground_truth_pub_;
  std::array<ros::Publisher, 8> range_pubs_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::ServiceServer clear_errors_srv_, set_ultrasonic_srv_, set_motion_mode_srv_;
  ros::SteadyTimer publish_timer_, state_timer_, diagnostics_timer_;

  diagnostic_updater::Updater updater_;
  std::unique_ptr<ChassisDiagnostics> diagnostics_;

  std::unique_ptr<ros::AsyncSpinner> spinner_, cmd_spinner_, service_spinner_;

  // For logging transitions once instead of every cycle (state timer thread only).
  std::optional<ranger::MotionRefusal> last_refusal_;
  std::optional<ranger::LinkState> last_link_;
  std::string last_bus_error_;
  std::uint32_t last_error_bits_ = 0;
  bool shut_down_ = false;
};

}  // namespace ranger_base
