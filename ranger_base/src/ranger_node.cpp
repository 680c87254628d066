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
#include <tf2_msgs/TFMessage.h>

#include <pthread.h>

#include <boost/make_shared.hpp>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <map>
#include <string>

#include <ranger_can/sim/chassis_commands.hpp>
#include <ranger_can/text.hpp>
#include <ranger_can/transport/bus_source.hpp>

#include "ranger_base/conversions.hpp"

namespace ranger_base {
namespace {

using std::chrono::nanoseconds;
using Kind = ranger::RequestOutcome::Kind;
using State = ranger::RequestOutcome::State;

const ranger::Clock& driver_clock() {
  static const ranger::SteadyClock clock;
  return clock;
}
const ranger::Clock& bus_clock() {
  static const ranger::SystemClock clock;
  return clock;
}

using ranger::text::join;

// "name<separator>value, ..." of (name, value) pairs, for the log.
std::string join_pairs(const std::vector<std::pair<std::string, std::string>>& pairs,
                       const char* separator) {
  std::vector<std::string> items;
  for (const auto& [name, value] : pairs)
    items.push_back(name + separator + value);
  return join(items);
}

// Publishes a message as a shared pointer: a subscriber in the same process gets this very
// message, without serialisation.
template <class M>
void publish_shared(const ros::Publisher& pub, M&& message) {
  pub.publish(boost::make_shared<std::decay_t<M>>(std::forward<M>(message)));
}

// Builds and publishes a message only for a topic someone listens to (nothing is lost: the
// states are published whole at every period, there is no history to keep up).
template <class Make>
void publish_if_heard(const ros::Publisher& pub, Make make) {
  if (pub.getNumSubscribers() > 0) publish_shared(pub, make());
}

// The driver's event in the log at its severity: the one mapping from the library's events.
void log_event(const ranger::DriverEvent& event) {
  using Level = ros::console::levels::Level;
  static constexpr Level kLevel[] = {Level::Debug, Level::Info, Level::Warn, Level::Error};
  ROS_LOG(kLevel[static_cast<int>(event.severity)], ROSCONSOLE_DEFAULT_NAME, "%s",
          ranger::describe(event).c_str());
}

// A publication is due from this long before its time (the estimates come with the driver's
// iterations, which jitter), never more than a quarter of its period.
std::chrono::steady_clock::duration early_margin(std::chrono::steady_clock::duration period) {
  return std::min<std::chrono::steady_clock::duration>(std::chrono::milliseconds(5), period / 4);
}

std::chrono::steady_clock::duration period_of(double rate_hz) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz));
}

// A fixed-rate schedule: the next publication is due one period after the previous due time, so
// the average rate is the configured one; after a stall it restarts from now instead of
// publishing a burst.
void advance(std::chrono::steady_clock::time_point& next,
             std::chrono::steady_clock::duration period,
             std::chrono::steady_clock::time_point now) {
  next += period;
  if (next < now) next = now + period;
}
}  // namespace

ranger::Result<std::unique_ptr<RangerNode>> RangerNode::create(const ros::NodeHandle& nh,
                                                               const ros::NodeHandle& private_nh,
                                                               NodeParameters params) {
  auto source = ranger::sim::open_bus_source(params.port_name, bus_clock(), params.sim);
  if (!source) {
    return ranger::Error{source.error().code,
                         "port_name \"" + params.port_name + "\": " + source.error().message};
  }
  return std::unique_ptr<RangerNode>(new RangerNode(nh, private_nh, std::move(params), *source));
}

ranger::Result<std::unique_ptr<RangerNode>> RangerNode::from_parameters(
    const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) {
  const NodeHandleParameterSource source(private_nh);
  for (const auto& name : ranger::unknown_parameter_names(source, kAlsoRead)) {
    ROS_WARN("unknown parameter %s ignored (see ranger_base/README.md for the names)",
             source.display_name(name).c_str());
  }
  auto params = load_parameters(source);
  if (!params) return params.error();
  return create(nh, private_nh, std::move(*params));
}

RangerNode::RangerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                       NodeParameters params, std::shared_ptr<ranger::BusSource> source)
    : nh_(nh),
      private_nh_(private_nh),
      cmd_nh_(nh),
      service_nh_(nh),
      params_(std::move(params)),
      source_(std::move(source)),
      sim_(std::dynamic_pointer_cast<ranger::sim::SimBusSource>(source_)),
      driver_(std::make_unique<ranger::Driver>(params_.driver, source_, driver_clock())),
      updater_(nh, private_nh),
      publication_waker_(driver_clock()) {
  cmd_nh_.setCallbackQueue(&cmd_queue_);
  service_nh_.setCallbackQueue(&service_queue_);

  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  system_state_pub_ = nh_.advertise<ranger_msgs::SystemState>("system_state", 10);
  actuator_state_pub_ = nh_.advertise<ranger_msgs::ActuatorStateArray>("actuator_state", 10);
  bms_state_pub_ = nh_.advertise<ranger_msgs::BmsStateArray>("bms_state", 10);
  battery_state_pub_ = nh_.advertise<sensor_msgs::BatteryState>("battery_state", 10);
  ultrasonic_state_pub_ = nh_.advertise<ranger_msgs::UltrasonicState>("ultrasonic_state", 10);
  // Published only on a chassis that sends 0x241 (the vendor's revision).
  remote_state_pub_ = nh_.advertise<ranger_msgs::RemoteState>("remote_state", 10);
  for (std::size_t i = 0; i < range_pubs_.size(); ++i) {
    range_pubs_[i] =
        nh_.advertise<sensor_msgs::Range>("ultrasonic/range_" + std::to_string(i + 1), 10);
  }
  if (params_.publish_cmd) {
    cmd_vel_out_pub_ = nh_.advertise<geometry_msgs::TwistStamped>("cmd_vel_out", 100);
  }
  if (sim_) ground_truth_pub_ = nh_.advertise<nav_msgs::Odometry>("sim/ground_truth", 10);

  if (params_.publish_odom_tf) tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);

  diagnostics_ = std::make_unique<ChassisDiagnostics>(
      updater_, [this] { return driver_->snapshot(); },
      ranger::DiagnosticContext{params_.port_name, params_.protocol.source, nh_.getNamespace()});
  // Both observers run on the driver thread: they queue, or wake the publication thread, and
  // return (publication never runs on the thread that owns the 0x111 keep-alive).
  // The send's wall time is read only for cmd_vel_out.
  driver_->set_sent_observer([this](const ranger::SentEvent& e) { on_sent(e); },
                             params_.publish_cmd);
  driver_->set_step_observer(
      [this](const std::shared_ptr<const ranger::DriverSnapshot>&) { on_step(); });
  // The driver's events are logged by the publication thread (log_events), never on its own.
  driver_->set_event_observer([this](const ranger::DriverEvent&) { wake_publication(); });
}

RangerNode::~RangerNode() {
  shutdown();
}

void RangerNode::start() {
  driver_->start();
  publication_thread_ = std::thread([this] { publication_loop(); });

  // Latest command wins: a queue of one drops stale twists under a flood instead of replaying
  // them late; TCP_NODELAY keeps the latency down.
  cmd_vel_sub_ = cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel, this,
                                   ros::TransportHints().tcpNoDelay());
  if (sim_) {
    sim_inject_sub_ = service_nh_.subscribe("sim/inject", 10, &RangerNode::on_sim_inject, this);
  }
  resume_srv_ = service_nh_.advertiseService("resume", &RangerNode::on_resume, this);
  clear_errors_srv_ =
      service_nh_.advertiseService("clear_errors", &RangerNode::on_clear_errors, this);
  set_ultrasonic_srv_ =
      service_nh_.advertiseService("set_ultrasonic", &RangerNode::on_set_ultrasonic, this);
  set_motion_mode_srv_ =
      service_nh_.advertiseService("set_motion_mode", &RangerNode::on_set_motion_mode, this);
  set_lights_srv_ = service_nh_.advertiseService("set_lights", &RangerNode::on_set_lights, this);
  park_srv_ = service_nh_.advertiseService("park", &RangerNode::on_park, this);

  service_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &service_queue_);
  service_spinner_->start();
  ROS_INFO("ranger_base_node on %s (%s), publishing odom at %.1f Hz (%s -> %s%s)",
           params_.port_name.c_str(),
           sim_ ? "the in-process virtual chassis"
                : (source_->read_only() ? "a replayed log: nothing is sent" : "SocketCAN"),
           params_.publish_rate, params_.odom_frame.c_str(), params_.base_frame.c_str(),
           params_.publish_odom_tf ? ", TF on" : ", TF off");
  log_protocol();
}

void RangerNode::log_protocol() const {
  const auto& pp = params_.protocol;
  const auto& c = params_.driver.controller;
  ROS_INFO("model %s (%s): wheelbase %.3f m, track %.3f m, wheel radius %.3f m, max speed %.2f m/s",
           pp.model.c_str(), pp.model_display_name.c_str(), c.geometry.wheelbase, c.geometry.track,
           c.geometry.wheel_radius, c.limits.max_linear_speed);
  if (params_.driver.protocol == ranger::ProtocolChoice::kAuto) {
    ROS_INFO(
        "protocol auto: the settings are identified from the chassis before anything moves "
        "(listening first, then a few degrees of steering at zero speed; identify_timeout %.1f "
        "s); nothing is driven until then, and the plausibility monitors check them while "
        "driving",
        ranger::seconds(params_.driver.identification.timeout));
    if (!pp.model_settings.empty()) {
      ROS_INFO(
          "the %s's own readings (%s) are not assumed with protocol auto: the identification "
          "decides what it can at rest, the plausibility monitors the rest on first motion; set "
          "protocol: %s to force the model's profile",
          pp.model_display_name.c_str(), join_pairs(pp.model_settings, "=").c_str(),
          c.profile.revision.c_str());
    }
  } else if (pp.auto_overridden) {
    ROS_WARN(
        "protocol auto, but interpretation parameters are set (%s): the driver cannot keep "
        "single settings forced on top of an identification, so identification is off and the "
        "settings are forced: %s (the plausibility monitors still check them while driving)",
        join_pairs(pp.settings, ": ").c_str(), ranger::describe(c.profile).c_str());
  } else {
    ROS_INFO("protocol settings %s (%s); the plausibility monitors check them while driving",
             ranger::describe(c.profile).c_str(), pp.source.c_str());
  }
}

void RangerNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  // Commands stop first: no cmd_vel may restart the chassis after the stop.
  cmd_vel_sub_.shutdown();
  sim_inject_sub_.shutdown();
  driver_->stop();  // the zero motion command (an event says it), then the driver thread ends
  publication_stop_ = true;
  wake_publication();
  // cmd_vel_out has the stop, the log the driver's event about it.
  if (publication_thread_.joinable()) publication_thread_.join();
  // A disabled queue wakes its spinner thread at once instead of after its poll timeout.
  cmd_queue_.disable();
  service_queue_.disable();
  if (service_spinner_) service_spinner_->stop();
}

// ---- callbacks
// -----------------------------------------------------------------------------------

void RangerNode::on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg) {
  const ranger::BodyTwist twist = to_body_twist(*msg);
  if (has_non_planar_components(*msg)) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel: linear.z, angular.x and angular.y are ignored (planar base)");
  }
  // A refusal (NaN, not connected) is the driver's event, logged with the others.
  (void)driver_->command(ranger::MotionRequest{twist, std::nullopt});
}

void RangerNode::on_sent(const ranger::SentEvent& e) {
  const auto achieved = achieved_twist(e);
  if (!achieved || !params_.publish_cmd) return;  // not a motion command, or not published
  ros::Time stamp;
  stamp.fromNSec(static_cast<std::uint64_t>(
      std::chrono::duration_cast<nanoseconds>(e.wall.time_since_epoch()).count()));
  {
    std::lock_guard<std::mutex> lock(sent_mutex_);  // the publication thread only swaps it out
    sent_queue_.push_back(SentTwist{*achieved, stamp});
  }
  wake_publication();
}

void RangerNode::on_step() {
  if (snapshot_wanted_.exchange(false)) wake_publication();
}

void RangerNode::wake_publication() {
  publication_waker_.wake();
}

void RangerNode::on_sim_inject(const std_msgs::String::ConstPtr& msg) {
  if (!sim_) return;
  const std::string& line = msg->data;
  const auto said = sim_->with_chassis(
      [&](ranger::sim::VirtualChassis& c) { return ranger::sim::apply_chassis_command(line, c); });
  if (!said) {
    ROS_WARN("sim/inject \"%s\" not applied: %s (valid commands: %s; see ranger_base/README.md)",
             line.c_str(), said.error().message.c_str(),
             join(ranger::sim::chassis_command_names()).c_str());
    return;
  }
  ROS_INFO("sim/inject \"%s\" applied to the virtual chassis%s%s", line.c_str(),
           said->empty() ? "" : ": ", said->c_str());
}

bool RangerNode::on_resume(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const auto before = driver_->snapshot();
  if (!before->bus_open) {
    res.success = false;
    res.message = "resume refused: not connected to " + params_.port_name +
                  (before->bus_error.empty() ? "" : ": " + before->bus_error);
    ROS_WARN("%s", res.message.c_str());
    return true;
  }
  const auto outcome = wait_for(driver_->resume(), Kind::kResume);
  // (The outcome is logged as the driver's event.)
  res.success = outcome.state == State::kAnswered;
  res.message = res.success ? "re-armed: cmd_vel drives the chassis again"
                : outcome.message.empty()
                    ? "resume not applied (" + std::string(ranger::to_string(outcome.state)) + ")"
                    : outcome.message;
  return true;
}

bool RangerNode::on_clear_errors(ranger_msgs::ClearErrors::Request& req,
                                 ranger_msgs::ClearErrors::Response& res) {
  res.success = false;
  const auto posted = driver_->clear_errors(req.code);
  if (!posted) {
    res.message = posted.error().message;
    res.error_word = driver_->snapshot()->controller.error_bits;
    return true;
  }
  const auto outcome = wait_for(*posted, Kind::kClearErrors);
  const std::string asked = "clear_errors code " + std::to_string(req.code) + " (" +
                            ranger::error_clear_description(req.code) + ")";
  if (outcome.state == State::kAnswered && outcome.error_word) {
    res.success = true;
    res.error_word = *outcome.error_word;
    const auto names = ranger::fault_names(res.error_word, driver_->snapshot()->profile.error_word);
    res.message = asked + ": the chassis answered with error word " +
                  ranger::text::hex(res.error_word, 8) +
                  (names.empty() ? " (no errors)" : " (" + join(names) + ")");
  } else {
    res.error_word = driver_->snapshot()->controller.error_bits;
    res.message = asked + ": " +
                  (outcome.state == State::kFailed ? outcome.message
                                                   : std::string("the chassis did not answer"));
  }
  return true;
}

bool RangerNode::on_set_ultrasonic(ranger_msgs::SetUltrasonic::Request& req,
                                   ranger_msgs::SetUltrasonic::Response& res) {
  const auto known = driver_->snapshot()->controller.ultrasonic_enabled;
  res.enabled = known.value_or(false);
  if (req.enable == req.disable) {
    res.success = false;
    res.message = std::string(req.enable ? "contradictory request (enable and disable both true)"
                                         : "empty request (neither enable nor disable)") +
                  ": set exactly one of them; nothing sent";
    return true;
  }
  const auto outcome = wait_for(driver_->set_ultrasonic(req.enable), Kind::kUltrasonic);
  res.success = outcome.state == State::kAnswered;
  res.enabled = driver_->snapshot()->controller.ultrasonic_enabled.value_or(false);
  res.message = outcome.message.empty()
                    ? "the chassis did not confirm the ultrasonic setting in time"
                    : outcome.message;
  return true;
}

bool RangerNode::on_set_motion_mode(ranger_msgs::SetMotionMode::Request& req,
                                    ranger_msgs::SetMotionMode::Response& res) {
  using Req = ranger_msgs::SetMotionMode::Request;
  using M = ranger::MotionMode;
  static const std::map<std::uint8_t, std::optional<M>> kModes = {{Req::ACKERMANN, M::kAckermann},
                                                                  {Req::OBLIQUE, M::kOblique},
                                                                  {Req::SPIN, M::kSpin},
                                                                  {Req::SIDE_SLIP, M::kSideSlip},
                                                                  {Req::AUTOMATIC, std::nullopt}};
  const auto known = kModes.find(req.mode);
  if (known == kModes.end()) {
    res.success = false;
    res.message = "mode " + std::to_string(req.mode) +
                  " unknown: use 0 (Ackermann), 1 (oblique), 2 (spin), 4 (side slip) or 255 "
                  "(automatic)";
    return true;
  }
  const std::optional<M> mode = known->second;
  if (mode) {
    const auto s = driver_->snapshot();
    if (!ranger::can_drive_in(*mode, s->profile)) {
      res.success = false;
      res.message = std::string(ranger::to_string(*mode)) + ": unsupported by protocol " +
                    s->profile.revision + " (its motion-mode numbering has no " +
                    std::string(ranger::to_string(*mode)) + " mode; side slip is the MINI V1's)";
      ROS_WARN("set_motion_mode: %s", res.message.c_str());
      return true;
    }
  }
  driver_->set_motion_mode(mode);
  res.success = true;
  res.message = mode ? "motion mode pinned to " + std::string(ranger::to_string(*mode)) +
                           " (the switch happens at standstill)"
                     : "automatic motion-mode selection";
  return true;
}

bool RangerNode::on_set_lights(ranger_msgs::SetLights::Request& req,
                               ranger_msgs::SetLights::Response& res) {
  res.success = false;
  const auto wanted = to_lights_request(req);
  if (!wanted) {
    res.message = wanted.error().message + ": nothing sent";
    fill_lights_response(driver_->snapshot()->lights, res);
    return true;
  }
  const auto posted = driver_->set_lights(*wanted);
  if (!posted) {
    res.message = posted.error().message;
    return true;
  }
  const auto outcome = wait_for(*posted, Kind::kLights);
  res.success = outcome.state == State::kAnswered;
  res.message = outcome.message.empty() ? "the chassis did not report its lights in time (" +
                                              std::string(ranger::to_string(outcome.state)) + ")"
                                        : outcome.message;
  fill_lights_response(driver_->snapshot()->lights, res);
  return true;
}

bool RangerNode::on_park(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  const auto outcome = wait_for(driver_->set_park(req.data), Kind::kPark);
  res.success = outcome.state == State::kAnswered;
  res.message = outcome.message.empty()
                    ? std::string(req.data ? "park" : "release") + " not confirmed in time (" +
                          std::string(ranger::to_string(outcome.state)) + ")"
                    : outcome.message;
  return true;
}

// ---- publishing
// ----------------------------------------------------------------------------------

void RangerNode::publication_loop() {
  ::pthread_setname_np(::pthread_self(), "ranger_publish");
  using Clock = std::chrono::steady_clock;
  const auto motion_period = period_of(params_.publish_rate);
  const auto state_period = period_of(params_.state_publish_rate);
  const auto diagnostics_period = period_of(1.0);
  const auto motion_early = early_margin(motion_period);
  const auto state_early = early_margin(state_period);
  const auto start = Clock::now();
  next_motion_publication_ = next_state_publication_ = next_diagnostics_publication_ = start;
  bool waiting_for_snapshot = false;  // motion is due, the latest snapshot had nothing new
  while (!publication_stop_) {
    try {
      log_events();
      publish_sent();
      const auto now = Clock::now();
      const bool motion_heard = motion_has_subscribers();
      if (now >= next_motion_publication_ - motion_early && !motion_heard) {
        // Nobody listens: nothing is built, and the thread sleeps until the states are due
        // (which see a new subscriber within one state period).
        waiting_for_snapshot = false;
        advance(next_motion_publication_, motion_period, now);
      } else if (now >= next_motion_publication_ - motion_early) {
        // Wanted before the snapshot is read: an iteration that ends meanwhile wakes us.
        snapshot_wanted_ = true;
        if (publish_motion(*driver_->snapshot())) {
          snapshot_wanted_ = false;
          waiting_for_snapshot = false;
          if (sim_ && ground_truth_pub_.getNumSubscribers() > 0) publish_ground_truth();
          advance(next_motion_publication_, motion_period, now);
        } else {
          waiting_for_snapshot = true;
        }
      }
      if (now >= next_state_publication_ - state_early) {
        publish_states();
        advance(next_state_publication_, state_period, now);
      }
      if (now >= next_diagnostics_publication_) {
        publish_diagnostics();
        advance(next_diagnostics_publication_, diagnostics_period, now);
      }
    } catch (const std::exception& e) {  // nothing may escape the thread
      ROS_ERROR_THROTTLE(5.0, "publishing failed: %s", e.what());
    }
    // Until the next publication is due, a frame was sent, or (motion due) the driver's next
    // iteration.
    auto until = std::min(next_state_publication_ - state_early, next_diagnostics_publication_);
    if (!waiting_for_snapshot && motion_has_subscribers()) {
      until = std::min(until, next_motion_publication_ - motion_early);
    }
    publication_waker_.sleep_until(ranger::Timestamp(until.time_since_epoch()));
  }
  try {
    log_events();    // the driver's last ones (its stop)
    publish_sent();  // the shutdown's stop
  } catch (const std::exception& e) {
    ROS_ERROR("publishing failed: %s", e.what());
  }
}

void RangerNode::publish_sent() {
  std::vector<SentTwist> sent;
  {
    std::lock_guard<std::mutex> lock(sent_mutex_);
    sent.swap(sent_queue_);
  }
  for (const SentTwist& t : sent)
    publish_shared(cmd_vel_out_pub_, to_twist_stamped(t.twist, t.stamp, params_.base_frame));
}

bool RangerNode::publish_motion(const ranger::DriverSnapshot& s) {
  // Publish only what is known: nothing while the chassis is not heard (never, or link lost),
  // and each estimate once, stamped with the time of the frames that produced it.
  // A message is built only for a topic with a subscriber (in this process or another).
  if (!s.motion_known) return true;  // nothing to wait for
  bool published = false;
  if (s.odometry.stamp > last_odom_stamp_) {
    last_odom_stamp_ = s.odometry.stamp;
    const bool odom_heard = odom_pub_.getNumSubscribers() > 0;
    const bool tf_heard = tf_pub_ && tf_pub_.getNumSubscribers() > 0;
    if (odom_heard || tf_heard) {
      auto odom = boost::make_shared<nav_msgs::Odometry>(to_odometry(s.odometry, params_));
      if (tf_heard) {
        auto tf = boost::make_shared<tf2_msgs::TFMessage>();
        tf->transforms.push_back(to_transform(*odom));
        tf_pub_.publish(tf);
      }
      if (odom_heard) odom_pub_.publish(odom);
    }
    published = true;
  }
  const ranger::Timestamp joints = joints_stamp(s.feedback);
  if ((s.joints.has_steering || s.joints.has_wheels) && joints > last_joints_stamp_) {
    last_joints_stamp_ = joints;
    publish_if_heard(joint_state_pub_,
                     [&] { return to_joint_state(s.joints, to_ros_time(joints)); });
    published = true;
  }
  return published;
}

bool RangerNode::motion_has_subscribers() const {
  return odom_pub_.getNumSubscribers() > 0 || joint_state_pub_.getNumSubscribers() > 0 ||
         (tf_pub_ && tf_pub_.getNumSubscribers() > 0) ||
         (ground_truth_pub_ && ground_truth_pub_.getNumSubscribers() > 0);
}

void RangerNode::publish_ground_truth() {
  const auto truth = sim_->snapshot();
  publish_shared(ground_truth_pub_, to_ground_truth(truth, params_, to_ros_time(truth.time)));
}

void RangerNode::publish_states() {
  const auto s = driver_->snapshot();
  const ros::Time stamp = ros::Time::now();
  publish_if_heard(system_state_pub_, [&] { return to_system_state(*s, stamp); });
  publish_if_heard(actuator_state_pub_, [&] { return to_actuator_state(s->feedback, stamp); });
  publish_if_heard(bms_state_pub_, [&] { return to_bms_state(s->feedback, s->now, stamp); });
  publish_if_heard(battery_state_pub_,
                   [&] { return to_battery_state(s->feedback, s->now, stamp); });
  publish_if_heard(ultrasonic_state_pub_, [&] { return to_ultrasonic_state(*s, stamp); });
  if (s->remote && s->remote->received > last_remote_received_) {
    last_remote_received_ = s->remote->received;
    publish_if_heard(remote_state_pub_, [&] {
      return to_remote_state(*s->remote, to_ros_time(s->feedback.remote_control_state->stamp));
    });
  }
  if (s->motion_known) {
    for (std::size_t g = 0; g < s->feedback.ultrasonic.size(); ++g) {
      const auto& group = s->feedback.ultrasonic[g];
      if (!group || group->stamp <= last_ultrasonic_stamp_[g]) continue;  // no new reading
      last_ultrasonic_stamp_[g] = group->stamp;
      for (int k = 0; k < 4; ++k) {
        const int sensor = group->value.first_sensor + k;
        if (sensor < 1 || sensor > static_cast<int>(range_pubs_.size())) continue;
        publish_if_heard(range_pubs_[static_cast<std::size_t>(sensor - 1)], [&] {
          return to_range(sensor, group->value.raw[static_cast<std::size_t>(k)], params_,
                          to_ros_time(group->stamp));
        });
      }
    }
  }
}

void RangerNode::log_events() {
  events_.clear();
  const std::uint64_t missed = driver_->events_since(logged_event_, events_);
  if (missed > 0)
    ROS_WARN("%" PRIu64 " driver events were not logged (the log fell behind)", missed);
  for (const ranger::DriverEvent& e : events_) {
    logged_event_ = e.sequence;
    log_event(e);
  }
}

void RangerNode::publish_diagnostics() {
  diagnostics_->refresh();
  updater_.update();
}

}  // namespace ranger_base
