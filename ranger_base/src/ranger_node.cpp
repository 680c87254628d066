#include "ranger_base/ranger_node.hpp"

#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <ranger_msgs/ActuatorStateArray.h>
#include <ranger_msgs/BmsStateArray.h>
#include <ranger_msgs/SystemState.h>
#include <ranger_msgs/UltrasonicState.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/Range.h>

#include <pthread.h>

#include <chrono>
#include <cmath>
#include <string>

#include <ranger_can/wire/protocol.hpp>

#include "ranger_base/conversions.hpp"

namespace ranger_base {
namespace {

namespace protocol = ranger::protocol;

ChassisLinkOptions link_options(const NodeParameters& p) {
  ChassisLinkOptions o;
  o.port_name = p.port_name;
  o.controller = p.controller;
  o.odometry = p.odometry;
  o.reconnect_interval = p.reconnect_interval;
  if (p.is_sim()) {
    o.sim = p.sim;
    o.sim_error_bits = p.sim_error_bits;
  }
  return o;
}

// Longest a service waits for the chassis to confirm a setting.
std::chrono::nanoseconds confirmation_budget(const ranger::ControllerConfig& c) {
  return c.ultrasonic_confirm_timeout * (c.ultrasonic_max_attempts + 1);
}

}  // namespace

RangerNode::RangerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                       NodeParameters params)
    : nh_(nh),
      private_nh_(private_nh),
      cmd_nh_(nh),
      service_nh_(nh),
      params_(std::move(params)),
      link_(std::make_unique<ChassisLink>(link_options(params_), clock_)),
      updater_(nh, private_nh) {
  cmd_nh_.setCallbackQueue(&cmd_queue_);
  service_nh_.setCallbackQueue(&service_queue_);

  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  system_state_pub_ = nh_.advertise<ranger_msgs::SystemState>("system_state", 10);
  actuator_state_pub_ = nh_.advertise<ranger_msgs::ActuatorStateArray>("actuator_state", 10);
  bms_state_pub_ = nh_.advertise<ranger_msgs::BmsStateArray>("bms_state", 10);
  battery_state_pub_ = nh_.advertise<sensor_msgs::BatteryState>("battery_state", 10);
  ultrasonic_state_pub_ = nh_.advertise<ranger_msgs::UltrasonicState>("ultrasonic_state", 10);
  for (std::size_t i = 0; i < range_pubs_.size(); ++i) {
    range_pubs_[i] =
        nh_.advertise<sensor_msgs::Range>("ultrasonic/range_" + std::to_string(i + 1), 10);
  }
  if (params_.publish_cmd) {
    cmd_vel_out_pub_ = nh_.advertise<geometry_msgs::TwistStamped>("cmd_vel_out", 100);
  }
  if (params_.is_sim()) {
    ground_truth_pub_ = nh_.advertise<nav_msgs::Odometry>("sim/ground_truth", 10);
  }

  updater_.setHardwareID("ranger:" + params_.port_name);
  diagnostics_ = std::make_unique<ChassisDiagnostics>(updater_, *link_);
}

RangerNode::~RangerNode() {
  shutdown();
}

void RangerNode::start() {
  link_->start([this](const MotionCommandEvent& e) { on_motion_command(e); });

  // Latest command wins: a queue of one drops stale twists under a flood instead of replaying
  // them late; TCP_NODELAY keeps the latency down.
  cmd_vel_sub_ = cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel, this,
                                   ros::TransportHints().tcpNoDelay());
  clear_errors_srv_ =
      service_nh_.advertiseService("clear_errors", &RangerNode::on_clear_errors, this);
  set_ultrasonic_srv_ =
      service_nh_.advertiseService("set_ultrasonic", &RangerNode::on_set_ultrasonic, this);
  set_motion_mode_srv_ =
      service_nh_.advertiseService("set_motion_mode", &RangerNode::on_set_motion_mode, this);

  cmd_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &cmd_queue_);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  cmd_spinner_->start();
  service_spinner_->start();
  publisher_ = std::thread([this] { publish_loop(); });
  ROS_INFO("ranger_base_node: %s, publishing odom at %.1f Hz (%s -> %s%s)",
           params_.is_sim() ? "in-process virtual chassis (port_name = sim)"
                            : ("CAN interface " + params_.port_name).c_str(),
           params_.publish_rate, params_.odom_frame.c_str(), params_.base_frame.c_str(),
           params_.publish_odom_tf ? ", TF on" : ", TF off");
}

void RangerNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  // Commands stop first: no cmd_vel may restart the chassis after the stop.
  cmd_vel_sub_.shutdown();
  link_->stop();  // zero 0x111, then the CAN thread ends
  {
    std::lock_guard<std::mutex> lock(publisher_mutex_);
    publisher_stop_ = true;
  }
  publisher_wake_.notify_all();
  if (publisher_.joinable()) publisher_.join();
  if (cmd_spinner_) cmd_spinner_->stop();
  if (service_spinner_) service_spinner_->stop();
}

void RangerNode::on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg) {
  const ranger::BodyTwist twist = to_body_twist(*msg);
  if (has_non_planar_components(*msg)) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel: linear.z, angular.x and angular.y are ignored (planar base)");
  }
  const ranger::Status st = link_->set_command(ranger::MotionRequest{twist, std::nullopt});
  if (!st) {
    if (st.error().code == ranger::Errc::kNotFinite) {
      ROS_ERROR_THROTTLE(1.0, "cmd_vel refused, chassis stopped: %s", st.error().message.c_str());
    } else {
      ROS_WARN_THROTTLE(5.0, "cmd_vel not applied: %s", st.error().message.c_str());
    }
  }
}

void RangerNode::on_motion_command(const MotionCommandEvent& e) {
  if (!params_.publish_cmd) return;
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(e.sent.time_since_epoch());
  ros::Time stamp;
  stamp.fromNSec(static_cast<std::uint64_t>(ns.count()));
  const ranger::BodyTwist achieved = e.solution ? e.solution->achieved : ranger::BodyTwist{};
  // A zero 0x111 (refusal, timeout, stop) realises a zero twist whatever the last solution was.
  const bool zero = e.command.linear_speed == 0.0 && e.command.spin_speed == 0.0;
  cmd_vel_out_pub_.publish(
      to_twist_stamped(zero ? ranger::BodyTwist{} : achieved, stamp, params_.base_frame));
}

void RangerNode::publish_loop() {
  ::pthread_setname_np(::pthread_self(), "ranger_publish");
  using Clock = std::chrono::steady_clock;
  const auto period = [](double rate) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate));
  };
  struct Task {
    Clock::duration period;
    void (RangerNode::*publish)();
    Clock::time_point due;
  };
  const auto start = Clock::now();
  Task tasks[] = {{period(params_.publish_rate), &RangerNode::publish_motion, start},
                  {period(params_.state_publish_rate), &RangerNode::publish_states, start},
                  {period(4.0), &RangerNode::publish_diagnostics, start}};
  std::unique_lock<std::mutex> lock(publisher_mutex_);
  while (!publisher_stop_) {
    const auto now = Clock::now();
    Clock::time_point next = Clock::time_point::max();
    for (auto& task : tasks) {
      if (now >= task.due) {
        lock.unlock();
        try {
          (this->*task.publish)();
        } catch (const std::exception& e) {  // nothing may escape the thread
          ROS_ERROR_THROTTLE(5.0, "publishing failed: %s", e.what());
        }
        lock.lock();
        // Fixed rate; after a stall, resume from now instead of publishing a burst.
        task.due += task.period;
        if (task.due < now) task.due = now + task.period;
      }
      next = std::min(next, task.due);
    }
    publisher_wake_.wait_until(lock, next, [this] { return publisher_stop_; });
  }
}

void RangerNode::publish_motion() {
  const LinkSnapshot s = link_->snapshot();
  const ros::Time stamp = ros::Time::now();
  const nav_msgs::Odometry odom = to_odometry(s.odometry, params_, stamp);
  odom_pub_.publish(odom);
  if (params_.publish_odom_tf) tf_broadcaster_.sendTransform(to_transform(odom));
  joint_state_pub_.publish(to_joint_state(s.joints, stamp));
  if (s.sim && ground_truth_pub_) {
    ground_truth_pub_.publish(to_ground_truth(*s.sim, params_, stamp));
  }
}

void RangerNode::publish_states() {
  const LinkSnapshot s = link_->snapshot();
  const ros::Time stamp = ros::Time::now();
  const TimeMapper time(stamp, s.now);
  const auto& c = s.controller;
  system_state_pub_.publish(to_system_state(c, stamp));
  actuator_state_pub_.publish(to_actuator_state(c.feedback, time, stamp));
  bms_state_pub_.publish(to_bms_state(c.feedback, time, s.now, stamp));
  battery_state_pub_.publish(to_battery_state(c, s.now, stamp));
  ultrasonic_state_pub_.publish(to_ultrasonic_state(c, stamp));
  for (const auto& group : c.feedback.ultrasonic) {
    if (!group) continue;
    for (int k = 0; k < 4; ++k) {
      const int sensor = group->value.first_sensor + k;
      if (sensor < 1 || sensor > static_cast<int>(range_pubs_.size())) continue;
      range_pubs_[static_cast<std::size_t>(sensor - 1)].publish(
          to_range(sensor, group->value.raw[static_cast<std::size_t>(k)], params_.ultrasonic,
                   time.to_ros(group->received)));
    }
  }
  log_state_changes(s);
}

void RangerNode::log_state_changes(const LinkSnapshot& s) {
  if (s.bus_error != last_bus_error_) {
    if (!s.bus_error.empty()) {
      ROS_ERROR("CAN interface %s: %s (retrying every %.1f s)", s.port_name.c_str(),
                s.bus_error.c_str(),
                std::chrono::duration<double>(params_.reconnect_interval).count());
    } else {
      ROS_INFO("CAN interface %s open", s.port_name.c_str());
    }
    last_bus_error_ = s.bus_error;
  }
  if (!s.has_controller) return;
  const auto& c = s.controller;
  if (!last_link_ || *last_link_ != c.link) {
    if (c.link == ranger::LinkState::kConnected) {
      ROS_INFO("chassis connected on %s", s.port_name.c_str());
    } else if (c.link == ranger::LinkState::kStale) {
      ROS_ERROR("chassis silent on %s: no system status (0x211); commands stopped",
                s.port_name.c_str());
    }
    last_link_ = c.link;
  }
  if (!last_refusal_ || *last_refusal_ != c.refusal) {
    if (c.refusal == ranger::MotionRefusal::kNone) {
      ROS_INFO("chassis accepts motion commands");
    } else if (c.refusal == ranger::MotionRefusal::kCmdTimeout) {
      ROS_INFO("no cmd_vel for cmd_vel_timeout (%.2f s): chassis commanded to stop",
               std::chrono::duration<double>(params_.controller.cmd_timeout).count());
    } else {
      ROS_WARN("chassis motion inhibited: %s", std::string(ranger::to_string(c.refusal)).c_str());
    }
    last_refusal_ = c.refusal;
  }
  if (c.error_bits != last_error_bits_) {
    std::string names;
    for (const auto& n : protocol::error_bit_names(c.error_bits))
      names += " " + n;
    ROS_WARN("chassis error word 0x%08X:%s", c.error_bits,
             names.empty() ? " (clear)" : names.c_str());
    last_error_bits_ = c.error_bits;
  }
  if (c.last_solution && c.last_solution->flags != ranger::kKinematicsExact) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel adjusted to what the chassis can do: %s",
                      ranger::kinematics_flags_to_string(c.last_solution->flags).c_str());
  }
}

void RangerNode::publish_diagnostics() {
  diagnostics_->refresh();
  updater_.update();
}

bool RangerNode::on_clear_errors(ranger_msgs::ClearErrors::Request& req,
                                 ranger_msgs::ClearErrors::Response& res) {
  if (req.code > protocol::kMaxErrorClearCode) {
    res.success = false;
    res.message = "code " + std::to_string(req.code) + " is not an error-clearing code (valid 0.." +
                  std::to_string(protocol::kMaxErrorClearCode) + ")";
  } else if (const ranger::Status st = link_->clear_errors(req.code); !st) {
    res.success = false;
    res.message = st.error().message;
  } else {
    res.success = true;
    res.message = "sent 0x441 code " + std::to_string(req.code) + ": clears " +
                  protocol::error_clear_description(req.code);
  }
  res.error_word = link_->snapshot().controller.error_bits;
  if (res.success) ROS_INFO("clear_errors: %s", res.message.c_str());
  return true;
}

bool RangerNode::on_set_ultrasonic(ranger_msgs::SetUltrasonic::Request& req,
                                   ranger_msgs::SetUltrasonic::Response& res) {
  if (const ranger::Status st = link_->set_ultrasonic(req.enable); !st) {
    res.success = false;
    res.message = st.error().message;
    return true;
  }
  // Wait (on this service thread only) until the chassis confirms via 0x45A or the controller
  // gives up; the controller resends meanwhile.
  const auto deadline = std::chrono::steady_clock::now() + confirmation_budget(params_.controller);
  while (ros::ok()) {
    const auto c = link_->snapshot().controller;
    if (c.ultrasonic_enabled && *c.ultrasonic_enabled == req.enable && !c.ultrasonic_requested) {
      res.success = true;
      res.enabled = req.enable;
      res.message = std::string("ultrasonic avoidance ") + (req.enable ? "enabled" : "disabled") +
                    " (confirmed by the chassis)";
      return true;
    }
    if (c.ultrasonic_failed || std::chrono::steady_clock::now() > deadline) {
      res.success = false;
      res.enabled = c.ultrasonic_enabled.value_or(false);
      res.message = "the chassis did not confirm the ultrasonic setting (0x45A)";
      return true;
    }
    ros::WallDuration(0.01).sleep();
  }
  res.success = false;
  res.message = "shutting down";
  return true;
}

bool RangerNode::on_set_motion_mode(ranger_msgs::SetMotionMode::Request& req,
                                    ranger_msgs::SetMotionMode::Response& res) {
  using Req = ranger_msgs::SetMotionMode::Request;
  std::optional<protocol::MotionMode> mode;
  switch (req.mode) {
    case Req::ACKERMANN:
      mode = protocol::MotionMode::kAckermann;
      break;
    case Req::OBLIQUE:
      mode = protocol::MotionMode::kOblique;
      break;
    case Req::SPIN:
      mode = protocol::MotionMode::kSpin;
      break;
    case Req::AUTOMATIC:
      break;
    default:
      res.success = false;
      res.message = "mode " + std::to_string(req.mode) +
                    " unknown: use 0 (Ackermann), 1 (oblique), 2 (spin) or 255 (automatic)";
      return true;
  }
  link_->request_motion_mode(mode);
  res.success = true;
  res.message = mode ? "motion mode pinned to " + std::string(protocol::to_string(*mode)) +
                           " (the switch happens at standstill)"
                     : "automatic motion-mode selection";
  ROS_INFO("set_motion_mode: %s", res.message.c_str());
  return true;
}

}  // namespace ranger_base
