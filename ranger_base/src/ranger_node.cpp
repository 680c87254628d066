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
#include <string>

#include <ranger_can/frontend/answers.hpp>
#include <ranger_can/frontend/publication.hpp>
#include <ranger_can/sim/chassis_commands.hpp>
#include <ranger_can/text.hpp>
#include <ranger_can/transport/bus_source.hpp>

#include "ranger_base/conversions.hpp"

namespace ranger_base {
namespace {

using std::chrono::nanoseconds;
using Kind = ranger::RequestOutcome::Kind;

const ranger::Clock& driver_clock() {
  static const ranger::SteadyClock clock;
  return clock;
}
const ranger::Clock& bus_clock() {
  static const ranger::SystemClock clock;
  return clock;
}

// A service answer from the library's words onto a ROS response.
template <class Response>
bool respond(const ranger::ServiceAnswer& answer, Response& res) {
  res.success = answer.success;
  res.message = answer.message;
  return true;
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

// A line in the log at its severity: the one mapping from the library's severities (the driver's
// events, the library's start-up and injection lines).
void log_at(ranger::Severity severity, const std::string& text) {
  using Level = ros::console::levels::Level;
  static constexpr Level kLevel[] = {Level::Debug, Level::Info, Level::Warn, Level::Error};
  ROS_LOG(kLevel[static_cast<int>(severity)], ROSCONSOLE_DEFAULT_NAME, "%s", text.c_str());
}
void log_event(const ranger::DriverEvent& event) {
  log_at(event.severity, ranger::describe(event));
}

// A service's answer onto its response, and its one log line (the library's words; the driver's
// events that are the same answer are not logged besides: log_events).
template <class Response>
bool answer(std::string_view service, const ranger::ServiceAnswer& said, Response& res) {
  const auto line = ranger::answer_line(service, said);
  log_at(line.severity, line.text);
  return respond(said, res);
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

  subscribe_cmd_vel();
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
  set_drive_mode_srv_ =
      service_nh_.advertiseService("set_drive_mode", &RangerNode::on_set_drive_mode, this);

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
  for (const auto& line : ranger::describe_protocol_setup(params_))
    log_at(line.severity, line.text);
}

void RangerNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  // Commands stop first: no cmd_vel may restart the chassis after the stop.
  cmd_vel_type_timer_.stop();
  {
    std::lock_guard<std::mutex> lock(cmd_vel_sub_mutex_);
    cmd_vel_closed_ = true;
    cmd_vel_sub_.shutdown();
  }
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

namespace {

// The master's type of `topic` (its latest publisher's), as the rule takes the publishers' types:
// none when nobody publishes it (or the master does not answer).
std::vector<std::string> published_types(const std::string& topic) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return {};
  for (const auto& t : topics) {
    if (t.name == topic) return {t.datatype};
  }
  return {};
}

}  // namespace

void RangerNode::subscribe_cmd_vel() {
  // Latest command wins: a queue of one drops stale twists under a flood instead of replaying
  // them late; TCP_NODELAY keeps the latency down.
  const auto hints = ros::TransportHints().tcpNoDelay();
  ranger::CmdVelTypeRule rule(params_.cmd_vel_stamped, ranger::TypeSpelling::kRos1);
  const auto start =
      rule.start(rule.follows_publishers() ? published_types(cmd_nh_.resolveName("cmd_vel"))
                                           : std::vector<std::string>{});
  {
    std::lock_guard<std::mutex> lock(cmd_vel_type_mutex_);
    cmd_vel_type_ = rule;
  }
  if (!rule.follows_publishers()) {
    cmd_vel_sub_ =
        start.taken == ranger::CmdVelType::kTwistStamped
            ? cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel_stamped, this, hints)
            : cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel, this, hints);
  } else {
    // Any type: each message is read as the type its publisher declares, Twist or TwistStamped.
    cmd_vel_sub_ = cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel_any, this, hints);
    cmd_vel_type_timer_ = service_nh_.createTimer(
        ros::Duration(0.25), [this](const ros::TimerEvent&) { recheck_cmd_vel_type(); });
  }
  ROS_INFO("%s", start.line.c_str());
}

void RangerNode::recheck_cmd_vel_type() {
  // The master gives one type for the topic: the rule wants to know whether the type taken still
  // comes (a subscription of any type keeps a link to a publisher of the other type, refused, so
  // its publisher count says nothing).
  const auto since_last =
      std::chrono::steady_clock::now().time_since_epoch() - nanoseconds(last_cmd_vel_ns_.load());
  {
    std::lock_guard<std::mutex> lock(cmd_vel_type_mutex_);
    if (!cmd_vel_type_.publishers_matter(since_last)) return;
  }
  const auto types = published_types(cmd_nh_.resolveName("cmd_vel"));
  ranger::CmdVelTypeDecision d;
  {
    std::lock_guard<std::mutex> lock(cmd_vel_type_mutex_);
    d = cmd_vel_type_.on_publishers(types, since_last);
  }
  if (d.change == ranger::CmdVelTypeChange::kSwitched) {
    std::lock_guard<std::mutex> lock(cmd_vel_sub_mutex_);
    if (cmd_vel_closed_) return;
    // roscpp's subscription of any type keeps its first publisher's type: a subscription of any
    // type again. The old one ends first: a second subscription of the topic would join its
    // (typed) connection.
    cmd_vel_sub_.shutdown();
    cmd_vel_sub_ = cmd_nh_.subscribe("cmd_vel", 1, &RangerNode::on_cmd_vel_any, this,
                                     ros::TransportHints().tcpNoDelay());
  }
  if (!d.line.empty()) ROS_INFO("%s", d.line.c_str());
}

void RangerNode::on_cmd_vel(const geometry_msgs::Twist::ConstPtr& msg) {
  drive(*msg, std::nullopt);
}

void RangerNode::on_cmd_vel_stamped(const geometry_msgs::TwistStamped::ConstPtr& msg) {
  drive(msg->twist, msg->header.stamp);
}

void RangerNode::on_cmd_vel_any(const topic_tools::ShapeShifter::ConstPtr& msg) {
  const std::string& type = msg->getDataType();
  const auto kind = ranger::parse_cmd_vel_type(type);
  if (!kind) {
    ROS_WARN_THROTTLE(5.0, "%s",
                      ranger::cmd_vel_type_refused_line(type, ranger::TypeSpelling::kRos1).c_str());
    return;
  }
  last_cmd_vel_ns_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::steady_clock::now().time_since_epoch())
                         .count();
  ranger::CmdVelTypeDecision d;
  {
    std::lock_guard<std::mutex> lock(cmd_vel_type_mutex_);
    d = cmd_vel_type_.on_message(*kind);
  }
  if (!d.line.empty()) ROS_INFO("%s", d.line.c_str());
  if (*kind == ranger::CmdVelType::kTwist) {
    drive(*msg->instantiate<geometry_msgs::Twist>(), std::nullopt);
  } else {
    const auto stamped = msg->instantiate<geometry_msgs::TwistStamped>();
    drive(stamped->twist, stamped->header.stamp);
  }
}

void RangerNode::drive(const geometry_msgs::Twist& twist, std::optional<ros::Time> stamp) {
  // All six fields go to the driver: the library refuses a NaN or an infinity in any of them. A
  // refusal (NaN, not connected, a stale stamp) is the driver's event, logged with the others.
  ranger::MotionRequest request = to_motion_request(twist);
  if (stamp && !stamp->isZero()) {  // a zero stamp means now
    request.age = std::chrono::nanoseconds((ros::Time::now() - *stamp).toNSec());
  }
  const ranger::Status st = driver_->command(request);
  if (st && has_non_planar_components(twist)) {
    ROS_WARN_THROTTLE(5.0, "cmd_vel: linear.z, angular.x and angular.y are ignored (planar base)");
  }
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
  const auto said = sim_->with_chassis([&](ranger::sim::VirtualChassis& c) {
    return ranger::sim::apply_chassis_command(msg->data, c);
  });
  const auto line = ranger::describe_injection(msg->data, said);
  log_at(line.severity, line.text);
}

bool RangerNode::on_resume(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  auto refused = ranger::resume_refused_offline(*driver_->snapshot(), params_.port_name);
  return answer(
      "resume",
      refused ? *refused : ranger::request_answer(wait_for(driver_->resume(), Kind::kResume)), res);
}

bool RangerNode::on_clear_errors(ranger_msgs::ClearErrors::Request& req,
                                 ranger_msgs::ClearErrors::Response& res) {
  const auto posted = driver_->clear_errors(req.code);
  res.error_word = driver_->snapshot()->controller.error_bits;
  if (!posted) return answer("clear_errors", {false, posted.error().message}, res);
  const auto outcome = wait_for(*posted, Kind::kClearErrors);
  const auto answered =
      ranger::clear_errors_answer(req.code, outcome, driver_->snapshot()->profile.error_word);
  res.error_word =
      answered.success ? *outcome.error_word : driver_->snapshot()->controller.error_bits;
  return answer("clear_errors", answered, res);
}

bool RangerNode::on_set_ultrasonic(ranger_msgs::SetUltrasonic::Request& req,
                                   ranger_msgs::SetUltrasonic::Response& res) {
  const auto refused = ranger::ultrasonic_request_refused(req.enable, req.disable);
  const auto answered = refused ? *refused
                                : ranger::request_answer(wait_for(
                                      driver_->set_ultrasonic(req.enable), Kind::kUltrasonic));
  res.enabled = driver_->snapshot()->controller.ultrasonic_enabled.value_or(false);
  return answer("set_ultrasonic", answered, res);
}

bool RangerNode::on_set_motion_mode(ranger_msgs::SetMotionMode::Request& req,
                                    ranger_msgs::SetMotionMode::Response& res) {
  const auto& numbers = ranger::motion_mode_numbers();
  const auto known = std::find_if(numbers.begin(), numbers.end(),
                                  [&](const auto& n) { return n.first == req.mode; });
  ranger::ServiceAnswer answered{false, ""};
  if (known == numbers.end()) {
    answered.message = ranger::unknown_motion_mode_number(req.mode, driver_->snapshot()->profile);
  } else if (const ranger::Status st = driver_->set_motion_mode(known->second); !st) {
    answered.message = st.error().message;
  } else {
    answered = {true, ranger::motion_mode_pinned(known->second)};
  }
  return answer("set_motion_mode", answered, res);
}

bool RangerNode::on_set_lights(ranger_msgs::SetLights::Request& req,
                               ranger_msgs::SetLights::Response& res) {
  ranger::ServiceAnswer answered{false, ""};
  const auto wanted = ranger::lights_request(req.front_mode, req.front_brightness, req.rear_mode,
                                             req.rear_brightness);
  if (!wanted) {
    answered.message = wanted.error().message;
  } else if (const auto posted = driver_->set_lights(*wanted); !posted) {
    answered.message = posted.error().message;
  } else {
    answered = ranger::request_answer(wait_for(*posted, Kind::kLights));
  }
  fill_lights_response(driver_->snapshot()->lights, res);
  return answer("set_lights", answered, res);
}

bool RangerNode::on_park(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  return answer("park", ranger::request_answer(wait_for(driver_->set_park(req.data), Kind::kPark)),
                res);
}

bool RangerNode::on_set_drive_mode(ranger_msgs::SetDriveMode::Request& req,
                                   ranger_msgs::SetDriveMode::Response& res) {
  const auto mode = ranger::drive_mode_request(req.mode);
  const auto answered =
      !mode ? ranger::ServiceAnswer{false, mode.error().message}
            : ranger::request_answer(wait_for(driver_->set_drive_mode(*mode), Kind::kDriveMode));
  const auto reported = driver_->snapshot()->drive_mode;
  res.drive_mode = ranger_msgs::SystemState::DRIVE_MODE_NONE;
  if (reported) res.drive_mode = static_cast<std::uint8_t>(*reported);
  return answer("set_drive_mode", answered, res);
}

// ---- publishing
// ----------------------------------------------------------------------------------

void RangerNode::publication_loop() {
  ::pthread_setname_np(::pthread_self(), "ranger_publish");
  using Clock = std::chrono::steady_clock;
  // The library's schedules (frontend/publication.hpp), as the ROS 2 node paces its own.
  ranger::MotionPacer motion(params_.publish_rate);
  ranger::PublicationSchedule states(params_.state_publish_rate);
  ranger::PublicationSchedule diagnostics(1.0);
  const auto start = Clock::now();
  motion.start(start);
  states.start(start);
  diagnostics.start(start);
  bool waiting_for_snapshot = false;  // motion is due, the latest snapshot had nothing new
  while (!publication_stop_) {
    try {
      log_events();
      publish_sent();
      const auto now = Clock::now();
      if (motion.due(now) && !motion_has_subscribers()) {
        // Nobody listens: nothing is built, and the thread sleeps until the states are due
        // (which see a new subscriber within one state period).
        waiting_for_snapshot = false;
        motion.skip(now);
      } else if (motion.due(now)) {
        // Wanted before the snapshot is read: an iteration that ends meanwhile wakes us.
        snapshot_wanted_ = true;
        const auto snapshot = driver_->snapshot();
        const auto decision = motion.decide(*snapshot, now);
        waiting_for_snapshot = decision.wait_for_estimate;
        if (!waiting_for_snapshot) snapshot_wanted_ = false;
        if (decision.publish()) publish_motion(*snapshot, decision);
        // The virtual chassis's truth at the motion rate, heard or not (as long as nothing is
        // awaited): it moves on while the chassis is silent.
        if (!waiting_for_snapshot && sim_ && ground_truth_pub_.getNumSubscribers() > 0) {
          publish_ground_truth();
        }
      }
      if (states.due(now)) {
        publish_states();
        states.advance(now);
      }
      if (diagnostics.due(now)) {
        publish_diagnostics();
        diagnostics.advance(now);
      }
    } catch (const std::exception& e) {  // nothing may escape the thread
      ROS_ERROR_THROTTLE(5.0, "publishing failed: %s", e.what());
    }
    // Until the next publication is due, a frame was sent, or (motion due) the driver's next
    // iteration.
    auto until = std::min(states.wake_at(), diagnostics.wake_at());
    if (!waiting_for_snapshot && motion_has_subscribers())
      until = std::min(until, motion.wake_at());
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

void RangerNode::publish_motion(const ranger::DriverSnapshot& s,
                                const ranger::MotionDecision& decision) {
  // Each estimate once (the library's MotionPacer decides), stamped with the time of the frames
  // that produced it; a message is built only for a topic with a subscriber (in this process or
  // another).
  if (decision.odometry) {
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
  }
  if (decision.joints) {
    publish_if_heard(joint_state_pub_, [&] {
      return to_joint_state(s.joints, to_ros_time(ranger::joints_stamp(s.feedback)));
    });
  }
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
    // A service's answer is logged once, as the answer (answer()), not as the driver's event too.
    if (!ranger::is_answer_event(e.kind)) log_event(e);
  }
}

void RangerNode::publish_diagnostics() {
  diagnostics_->refresh();
  updater_.update();
}

}  // namespace ranger_base
