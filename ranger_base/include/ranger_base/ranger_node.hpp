// ranger_base_node's ROS side: subscriptions, publications, services and diagnostics around a
// ChassisLink. All topic and service names are relative (the node works under a namespace);
// only /tf and /diagnostics are global, by their own conventions.
//
// Threads: the CAN thread lives in ChassisLink. Publishing runs on one thread of its own that
// sleeps until the next publication is due (odometry/TF/joints at publish_rate, states at
// state_publish_rate, diagnostics): one wake-up per publication, no timer-to-spinner hand-off.
// Two callback queues are each spun by one thread: cmd_vel (never queued behind anything) and
// the services (which may wait for the chassis to confirm). Every callback and publication reads
// the link through snapshot() or posts to it; none touches the bus.
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
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

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

  // Starts the CAN thread, the publishing thread and the spinners.
  void start();
  // Stops the chassis (zero 0x111) and the CAN thread, then the ROS side. Idempotent.
  void shutdown();

  ChassisLink& link() { return *link_; }

 private:
  void on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg);
  void publish_loop();
  void publish_motion();  // odom, TF, joint_states, sim/ground_truth
  void publish_states();  // ranger_msgs states, battery, ultrasonic
  void publish_diagnostics();
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

  diagnostic_updater::Updater updater_;
  std::unique_ptr<ChassisDiagnostics> diagnostics_;

  std::unique_ptr<ros::AsyncSpinner> cmd_spinner_, service_spinner_;

  std::thread publisher_;
  std::mutex publisher_mutex_;
  std::condition_variable publisher_wake_;
  bool publisher_stop_ = false;  // guarded by publisher_mutex_

  // For logging transitions once instead of every cycle (publishing thread only).
  std::optional<ranger::MotionRefusal> last_refusal_;
  std::optional<ranger::LinkState> last_link_;
  std::string last_bus_error_;
  std::uint32_t last_error_bits_ = 0;
  bool shut_down_ = false;
};

}  // namespace ranger_base
