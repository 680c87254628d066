// The RANGER driver's ROS side around libranger_can's driver runtime (ranger::Driver): parameters
// become a DriverConfig, snapshots become messages and diagnostics, the driver's events become log
// lines (one mapping of severities; the text is the library's describe()), ROS callbacks post to
// the driver's mailbox. The node knows no frame: the driver owns the bus, the controller, the
// odometry and the joint tracker on a thread of its own, and decides what is a transition. One
// class behind both front ends: the executable ranger_base_node (ranger_base_node.cpp) and the
// nodelet ranger_base/RangerNodelet (ranger_nodelet.cpp) construct it the same way
// (from_parameters) and run the same code.
//
// All topic and service names are relative (the node works under a namespace); only /tf and
// /diagnostics are global, by their own conventions. Every message is published as a shared
// pointer, so that a subscriber in the same process (a nodelet in the same manager) gets it
// without serialisation.
//
// Threads:
//  * the driver's (the bus, the 0x111 keep-alive): the node only posts to its mailbox and reads
//    its snapshots and events; the node's observers on it (a sent frame, an iteration done, an
//    event) append to a queue or write to an eventfd and never wait for publication or logging;
//  * publication, the node's own (publication_loop): odometry/TF/joints at publish_rate (each
//    estimate once: when the rate is due it waits for the driver's next snapshot with a new
//    estimate), states at state_publish_rate, diagnostics at 1 Hz, cmd_vel_out for every motion
//    frame sent, and the driver's events logged as they come. However slow a subscriber or however
//    much is published, the driver's schedule does not move;
//  * cmd_vel runs on the thread that delivers it (roscpp's network thread, or an in-process
//    publisher's), through an ImmediateCallbackQueue: it posts to the driver's mailbox and
//    returns, never queued behind anything and with no thread woken for it;
//  * one callback queue spun by one thread for the services (which wait for the chassis's
//    answer). No ROS callback touches the bus.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <ranger_msgs/ClearErrors.h>
#include <ranger_msgs/SetDriveMode.h>
#include <ranger_msgs/SetLights.h>
#include <ranger_msgs/SetMotionMode.h>
#include <ranger_msgs/SetUltrasonic.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <topic_tools/shape_shifter.h>

#include <array>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <ranger_can/clock.hpp>
#include <ranger_can/control/driver.hpp>
#include <ranger_can/frontend/cmd_vel_type.hpp>
#include <ranger_can/frontend/publication.hpp>
#include <ranger_can/result.hpp>
#include <ranger_can/sim/sim_bus_source.hpp>

#include "ranger_base/diagnostics.hpp"
#include "ranger_base/immediate_callback_queue.hpp"
#include "ranger_base/parameters.hpp"

namespace ranger_base {

class RangerNode {
 public:
  // Opens the bus source params.port_name names (a SocketCAN interface, sim[:VARIANT] or
  // replay:FILE; a missing interface is no error: the driver retries it) and builds the driver.
  // `nh`: the node's namespace (topics), `private_nh`: its parameters.
  static ranger::Result<std::unique_ptr<RangerNode>> create(const ros::NodeHandle& nh,
                                                            const ros::NodeHandle& private_nh,
                                                            NodeParameters params);
  // Both front ends start here: warns about unknown parameter names, reads and checks the
  // parameters in `private_nh` and creates the node. The error's message names every bad
  // parameter (one per line) or says why the bus source cannot be opened.
  static ranger::Result<std::unique_ptr<RangerNode>> from_parameters(
      const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  ~RangerNode();  // shutdown()
  RangerNode(const RangerNode&) = delete;
  RangerNode& operator=(const RangerNode&) = delete;

  // Starts the driver thread, the publication thread and the spinners.
  void start();
  // Stops the chassis (the driver's zero motion command, logged and published on cmd_vel_out),
  // the driver thread, the publication thread, then the ROS side. Idempotent; returns promptly
  // (services in progress stop waiting).
  void shutdown();

 private:
  RangerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, NodeParameters params,
             std::shared_ptr<ranger::BusSource> source);

  // cmd_vel as the library's rule has it (ranger_can/frontend/cmd_vel_type.hpp): Twist (false),
  // TwistStamped (true), or either (auto: each message as its publisher's type; the rule says
  // each change of type, logged here).
  void subscribe_cmd_vel();
  void on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg);
  void on_cmd_vel_stamped(const geometry_msgs::TwistStamped::ConstPtr& msg);
  void on_cmd_vel_any(const topic_tools::ShapeShifter::ConstPtr& msg);
  // cmd_vel_stamped auto: the master's type of cmd_vel (its latest publisher's) to the rule (the
  // services' thread, every 0.25 s); a subscription of any type takes the first publisher's for
  // good (roscpp), so when the rule switches to the other type (none of the type taken came for
  // ranger::kCmdVelTypeSettle) cmd_vel is subscribed afresh.
  void recheck_cmd_vel_type();
  // A twist to the driver; `stamp` (TwistStamped's, zero: now) gives its age: one older than
  // cmd_vel_timeout is not obeyed (the driver's stale_command, said in system_state).
  void drive(const geometry_msgs::Twist& twist, std::optional<ros::Time> stamp);
  void on_sim_inject(const std_msgs::String::ConstPtr& msg);
  void on_sent(const ranger::SentEvent& event);  // driver thread: queued for publication
  void on_step();  // driver thread: wakes the publication thread if it waits for a snapshot
  bool on_resume(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool on_clear_errors(ranger_msgs::ClearErrors::Request& req,
                       ranger_msgs::ClearErrors::Response& res);
  bool on_set_ultrasonic(ranger_msgs::SetUltrasonic::Request& req,
                         ranger_msgs::SetUltrasonic::Response& res);
  bool on_set_motion_mode(ranger_msgs::SetMotionMode::Request& req,
                          ranger_msgs::SetMotionMode::Response& res);
  bool on_set_lights(ranger_msgs::SetLights::Request& req, ranger_msgs::SetLights::Response& res);
  bool on_park(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);
  bool on_set_drive_mode(ranger_msgs::SetDriveMode::Request& req,
                         ranger_msgs::SetDriveMode::Response& res);
  // The outcome of request `id` (of `kind`) once answered or failed, after the driver's budget
  // for it, or at shutdown.
  ranger::RequestOutcome wait_for(std::uint64_t id, ranger::RequestOutcome::Kind kind) {
    return driver_->wait_for(id, driver_->answer_budget(kind));
  }

  // ---- the publication thread ----
  void publication_loop();
  void wake_publication();  // any thread; never blocks
  void publish_sent();      // cmd_vel_out for the frames queued by on_sent
  // odom, TF, joint_states: what the library's MotionPacer found new in the snapshot.
  void publish_motion(const ranger::DriverSnapshot& s, const ranger::MotionDecision& decision);
  void publish_ground_truth();          // sim/ground_truth
  bool motion_has_subscribers() const;  // odom, /tf, joint_states or sim/ground_truth
  void publish_states();                // ranger_msgs states, battery, ultrasonic
  void publish_diagnostics();
  void log_events();          // the driver's events since the last call, at their severity
  void log_protocol() const;  // at start: the model and where the protocol settings come from

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  ImmediateCallbackQueue cmd_queue_;
  ros::CallbackQueue service_queue_;
  ros::NodeHandle cmd_nh_, service_nh_;  // nh_ with those queues
  const NodeParameters params_;

  // The driver runs on a monotonic clock (timeouts, keep-alive); the bus source on
  // CLOCK_REALTIME, as SocketCAN stamps frames: the virtual chassis and a replayed log stamp their
  // frames with it too, so every frame time is ROS time (ranger_node.cpp: driver_clock(),
  // bus_clock()).
  std::shared_ptr<ranger::BusSource> source_;
  std::shared_ptr<ranger::sim::SimBusSource> sim_;  // port_name sim[:VARIANT] only
  std::unique_ptr<ranger::Driver> driver_;

  ros::Subscriber cmd_vel_sub_, sim_inject_sub_;
  ros::Publisher odom_pub_, joint_state_pub_, system_state_pub_, actuator_state_pub_,
      bms_state_pub_, battery_state_pub_, ultrasonic_state_pub_, cmd_vel_out_pub_,
      ground_truth_pub_, tf_pub_, remote_state_pub_;
  std::array<ros::Publisher, 8> range_pubs_;
  ros::ServiceServer resume_srv_, clear_errors_srv_, set_ultrasonic_srv_, set_motion_mode_srv_,
      set_lights_srv_, park_srv_, set_drive_mode_srv_;

  diagnostic_updater::Updater updater_;
  std::unique_ptr<ChassisDiagnostics> diagnostics_;

  std::unique_ptr<ros::AsyncSpinner> service_spinner_;

  // The publication thread and what wakes it (the driver's observers write to the eventfd; the
  // queue's lock is held only to append or to swap it out).
  std::thread publication_thread_;
  ranger::LoopWaker publication_waker_;  // on the driver's (monotonic) clock
  std::atomic<bool> publication_stop_{false};
  std::atomic<bool> snapshot_wanted_{false};  // publication waits for the driver's next iteration
  struct SentTwist {
    ranger::BodyTwist twist;
    ros::Time stamp;
  };
  std::mutex sent_mutex_;
  std::vector<SentTwist> sent_queue_;  // guarded by sent_mutex_

  // The publication thread only.
  std::array<ranger::Timestamp, 2> last_ultrasonic_stamp_{};
  ranger::Timestamp last_remote_received_{0};  // the driver's clock
  std::uint64_t logged_event_ = 0;             // the sequence number of the last event logged
  std::vector<ranger::DriverEvent> events_;    // log_events' buffer
  bool shut_down_ = false;
  // The type cmd_vel is taken as (the library's rule): any thread that delivers cmd_vel (auto),
  // the services' thread (recheck_cmd_vel_type).
  std::mutex cmd_vel_type_mutex_;
  ranger::CmdVelTypeRule cmd_vel_type_{ranger::CmdVelStamped::kAuto,
                                       ranger::TypeSpelling::kRos1};  // by cmd_vel_type_mutex_
  std::atomic<std::int64_t> last_cmd_vel_ns_{0};  // steady clock: the last cmd_vel taken (auto)
  ros::Timer cmd_vel_type_timer_;
  std::mutex cmd_vel_sub_mutex_;  // cmd_vel_sub_ (re)made or shut down
  bool cmd_vel_closed_ = false;   // by cmd_vel_sub_mutex_: shut down, never made again
};

}  // namespace ranger_base
