// ranger_base_node end to end against its in-process virtual chassis (port_name:=sim), through
// ROS only: cmd_vel and sim/inject (faults for the virtual chassis) in; system_state, odom,
// sim/ground_truth, cmd_vel_out (every motion command the node sent, stamped with its send time),
// /rosout, /diagnostics, services out. Launched by node_sim.test (NodeSim, Safety), and filtered
// to one suite by node_sim_faults.test (Faults), node_sim_identify*.test (Identification:
// protocol auto, the default, on sim, sim:agx_v2 and sim:undecidable) and
// node_sim_implausible*.test (Implausible: a wrong forced setting on a sim variant),
// node_sim_vendor.test (Vendor: remote_state, set_lights, park, the firmware version on
// sim:agx_v2) and node_sim_mini_v1.test (MiniV1: side slip, park refused).
//
// With protocol auto (the default) the node drives nothing until the identification has decided
// (about 3.6 s after the chassis is first heard): SetUp waits for that, a condition like every
// other wait here.
//
// Nothing sleeps to synchronise: every wait is on an observable condition (a message, a state),
// bounded only to fail a broken build instead of hanging; timing is asserted on the node's own
// stamps and on message order, never on how long the test took.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ranger_msgs/ClearErrors.h>
#include <ranger_msgs/RemoteState.h>
#include <ranger_msgs/SetDriveMode.h>
#include <ranger_msgs/SetLights.h>
#include <ranger_msgs/SetMotionMode.h>
#include <ranger_msgs/SetUltrasonic.h>
#include <ranger_msgs/SystemState.h>
#include <ranger_msgs/UltrasonicState.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/String.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2/utils.h>

#include <ranger_base/conversions.hpp>
#include <ranger_base/diagnostics.hpp>
#include <ranger_can/wire/protocol.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace {

using ranger_msgs::SystemState;

// The node's parameters in node_sim.test.
constexpr double kCmdVelTimeout = 0.3;         // s
constexpr double kPublishPeriod = 0.02;        // s (publish_rate 50)
constexpr double kMaxLinearSpeed = 1.0;        // m/s
constexpr double kMinCommandInterval = 0.005;  // s, ControllerConfig default
constexpr double kKeepAlivePeriod = 0.02;      // s

template <typename M>
class Latest {
 public:
  void set(const M& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    value_ = m;
  }
  std::optional<M> get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return value_;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<M> value_;
};

// roscpp's subscribe() overloads are ambiguous for a lambda: name the callback type.
template <typename M, typename F>
ros::Subscriber subscribe(ros::NodeHandle& nh, const std::string& topic, int queue, F f) {
  return nh.subscribe<M>(topic, queue, boost::function<void(const typename M::ConstPtr&)>(f));
}

class NodeSim : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = std::make_unique<ros::NodeHandle>();
    auto& nh = *nh_;
    subs_.push_back(
        subscribe<SystemState>(nh, "system_state", 10, [](const SystemState::ConstPtr& m) {
          state_.set(*m);
          std::lock_guard<std::mutex> lock(commands_mutex_);
          states_.push_back(*m);  // every one: the suite runs for minutes at 10 Hz
        }));
    subs_.push_back(
        subscribe<nav_msgs::Odometry>(nh, "odom", 10, [](const nav_msgs::Odometry::ConstPtr& m) {
          // Each estimate once, stamped with its frames' time: stamps only ever increase.
          const auto previous = odom_.get();
          if (previous && m->header.stamp <= previous->header.stamp) ++odom_stamp_regressions_;
          odom_.set(*m);
          ++odom_count_;
        }));
    subs_.push_back(subscribe<sensor_msgs::JointState>(
        nh, "joint_states", 10, [](const sensor_msgs::JointState::ConstPtr&) { ++joints_count_; }));
    subs_.push_back(subscribe<sensor_msgs::Range>(
        nh, "ultrasonic/range_1", 10,
        [](const sensor_msgs::Range::ConstPtr& m) { range_.set(*m); }));
    subs_.push_back(subscribe<nav_msgs::Odometry>(
        nh, "sim/ground_truth", 10, [](const nav_msgs::Odometry::ConstPtr& m) { truth_.set(*m); }));
    subs_.push_back(subscribe<ranger_msgs::UltrasonicState>(
        nh, "ultrasonic_state", 10,
        [](const ranger_msgs::UltrasonicState::ConstPtr& m) { ultrasonic_.set(*m); }));
    subs_.push_back(subscribe<ranger_msgs::RemoteState>(
        nh, "remote_state", 10, [](const ranger_msgs::RemoteState::ConstPtr& m) {
          remote_.set(*m);
          ++remote_count_;
        }));
    subs_.push_back(subscribe<geometry_msgs::TwistStamped>(
        nh, "cmd_vel_out", 1000, [](const geometry_msgs::TwistStamped::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(commands_mutex_);
          commands_.push_back(*m);
          if (commands_.size() > 20000) commands_.pop_front();
        }));
    subs_.push_back(subscribe<rosgraph_msgs::Log>(
        nh, "/rosout", 1000, [](const rosgraph_msgs::Log::ConstPtr& m) {
          if (m->name.find("ranger_base_node") == std::string::npos) return;
          std::lock_guard<std::mutex> lock(commands_mutex_);
          logs_.push_back(*m);
        }));
    subs_.push_back(subscribe<diagnostic_msgs::DiagnosticArray>(
        nh, "/diagnostics", 100, [](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(commands_mutex_);
          for (const auto& status : m->status)
            diagnostics_[status.name] = status;
        }));
    cmd_pub_ = nh.advertise<geometry_msgs::Twist>("cmd_vel", 100);
    inject_pub_ = nh.advertise<std_msgs::String>("sim/inject", 10);
    spinner_ = std::make_unique<ros::AsyncSpinner>(2);
    spinner_->start();
  }

  static void TearDownTestSuite() {
    spinner_->stop();
    // Destroyed here, not at exit: a static spinner outliving roscpp's own statics is a
    // heap-use-after-free in ~AsyncSpinner (found by the ASan build of the ROS tests).
    spinner_.reset();
    subs_.clear();
    cmd_pub_.shutdown();
    inject_pub_.shutdown();
    nh_.reset();
  }

  void SetUp() override {
    // On a system_state published a while (ten chassis frames) after this test began: what the
    // test before left (a latch its last injection caused) is in it.
    const ros::Time begun = ros::Time::now() + ros::Duration(0.2);
    ASSERT_TRUE(wait_for([begun] {
      const auto s = state_.get();
      return s && s->header.stamp >= begun && s->link_up &&
             s->control_mode == SystemState::CONTROL_MODE_CAN && settings_decided(*s) &&
             cmd_pub_.getNumSubscribers() > 0 && inject_pub_.getNumSubscribers() > 0 &&
             truth_.get() && odom_.get();
    })) << "the node never reached CAN command mode with its protocol settings decided";
    // A test that ended latched (link loss, an e-stop) is re-armed: only resume does that.
    if (state_.get()->rearm_required) {
      const auto resumed = call_resume();
      ASSERT_TRUE(resumed.success) << resumed.message;
    }
    stop_and_settle();
  }

  // The protocol settings are decided: forced (no identification), or identified.
  static bool settings_decided(const SystemState& s) {
    return s.identification.empty() || s.identification == "decided";
  }

  // The node's latest report of one of its diagnostics statuses ("Protocol", ...).
  static std::optional<diagnostic_msgs::DiagnosticStatus> diagnostic(const std::string& status) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& [name, d] : diagnostics_) {
      if (name.size() >= status.size() &&
          name.compare(name.size() - status.size(), status.size(), status) == 0 &&
          name.find("ranger_base_node: ") != std::string::npos) {
        return d;
      }
    }
    return std::nullopt;
  }

  static std::string value_of(const diagnostic_msgs::DiagnosticStatus& d, const std::string& key) {
    for (const auto& kv : d.values) {
      if (kv.key == key) return kv.value;
    }
    return "<missing>";
  }

  // Publishes `cmd` every 50 ms (a teleop at 20 Hz) until the node has published `n` more
  // system_states: a teleop kept alive while the node may send no motion command at all. The
  // stream stays fresh however the states are paced (cmd_vel_timeout is 0.3 s in these
  // fixtures; one twist per state let it lapse when a state came late). False when a state
  // takes over 5 s.
  static bool drive_for_states(const geometry_msgs::Twist& cmd, int n) {
    std::size_t seen = 0;
    {
      std::lock_guard<std::mutex> lock(commands_mutex_);
      seen = states_.size();
    }
    for (std::size_t want = seen + 1; want <= seen + static_cast<std::size_t>(n); ++want) {
      const auto end = ros::WallTime::now() + ros::WallDuration(5.0);
      bool arrived = false;
      while (!arrived && ros::ok() && ros::WallTime::now() < end) {
        cmd_pub_.publish(cmd);
        arrived = wait_for(
            [&] {
              std::lock_guard<std::mutex> lock(commands_mutex_);
              return states_.size() >= want;
            },
            0.05);
      }
      if (!arrived) return false;
    }
    return true;
  }

  // The stamp of the node's log line containing `text` at `level` or above (zero: none).
  static ros::Time log_stamp(const std::string& text, std::uint8_t level) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& l : logs_) {
      if (l.level >= level && l.msg.find(text) != std::string::npos) return l.header.stamp;
    }
    return ros::Time();
  }

  static bool wait_for(const std::function<bool()>& condition, double limit_s = 20.0) {
    const auto end = ros::WallTime::now() + ros::WallDuration(limit_s);
    while (ros::ok() && ros::WallTime::now() < end) {
      if (condition()) return true;
      ros::WallDuration(0.005).sleep();
    }
    return condition();
  }

  static geometry_msgs::Twist twist(double vx, double vy, double wz) {
    geometry_msgs::Twist t;
    t.linear.x = vx;
    t.linear.y = vy;
    t.angular.z = wz;
    return t;
  }

  // Publishes `cmd` at 20 Hz (a teleop's rate, well inside cmd_vel_timeout) until `condition`.
  static bool drive_until(const geometry_msgs::Twist& cmd, const std::function<bool()>& condition,
                          double limit_s = 20.0) {
    const auto end = ros::WallTime::now() + ros::WallDuration(limit_s);
    while (ros::ok() && ros::WallTime::now() < end) {
      cmd_pub_.publish(cmd);
      if (wait_for(condition, 0.05)) return true;
    }
    return false;
  }

  // The newest cmd_vel_out stamp (zero before the first).
  static ros::Time newest_command() {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    return commands_.empty() ? ros::Time() : commands_.back().header.stamp;
  }

  // Publishes `cmd` `n` times, each time waiting until the node has sent a motion command after
  // it: a teleop kept alive at the node's own pace, observed on cmd_vel_out.
  static bool drive_for(const geometry_msgs::Twist& cmd, int n) {
    for (int i = 0; i < n; ++i) {
      const ros::Time before = newest_command();
      cmd_pub_.publish(cmd);
      if (!wait_for([&] { return newest_command() > before; }, 5.0)) return false;
    }
    return true;
  }

  // Waits until the node logged `text` (at `level` or above) on /rosout after `since`.
  static bool logged(const std::string& text, const ros::Time& since,
                     std::uint8_t level = rosgraph_msgs::Log::DEBUG, double limit_s = 20.0) {
    return wait_for(
        [&] {
          std::lock_guard<std::mutex> lock(commands_mutex_);
          for (const auto& l : logs_) {
            if (l.header.stamp >= since && l.level >= level &&
                l.msg.find(text) != std::string::npos) {
              return true;
            }
          }
          return false;
        },
        limit_s);
  }

  static void inject(const std::string& line) {
    std_msgs::String msg;
    msg.data = line;
    inject_pub_.publish(msg);
  }

  static std_srvs::Trigger::Response call_resume() {
    ros::ServiceClient client = nh_->serviceClient<std_srvs::Trigger>("resume");
    EXPECT_TRUE(client.waitForExistence(ros::Duration(10.0)));
    std_srvs::Trigger srv;
    EXPECT_TRUE(client.call(srv));
    return srv.response;
  }

  static bool contains(const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
  }

  static double speed(const nav_msgs::Odometry& o) {
    return std::hypot(o.twist.twist.linear.x, o.twist.twist.linear.y) +
           std::abs(o.twist.twist.angular.z);
  }

  // Stops publishing and waits until the virtual chassis is at rest.
  static void stop_and_settle() {
    cmd_pub_.publish(twist(0, 0, 0));
    ASSERT_TRUE(wait_for([] { return speed(*truth_.get()) < 1e-3; })) << "chassis did not stop";
  }

  static std::vector<geometry_msgs::TwistStamped> commands_since(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    std::vector<geometry_msgs::TwistStamped> out;
    for (const auto& c : commands_) {
      if (c.header.stamp >= t) out.push_back(c);
    }
    return out;
  }

  static bool is_zero(const geometry_msgs::TwistStamped& c) {
    return c.twist.linear.x == 0.0 && c.twist.linear.y == 0.0 && c.twist.angular.z == 0.0;
  }

  // Odometry against the virtual chassis's ground truth, both from the same node cycle.
  static void expect_odom_matches_truth(double distance_travelled) {
    const auto odom = odom_.get();
    const auto truth = truth_.get();
    ASSERT_TRUE(odom && truth);
    const double tolerance = 0.02 + 0.02 * distance_travelled;
    EXPECT_NEAR(odom->pose.pose.position.x, truth->pose.pose.position.x, tolerance);
    EXPECT_NEAR(odom->pose.pose.position.y, truth->pose.pose.position.y, tolerance);
    const double dyaw = std::remainder(
        tf2::getYaw(odom->pose.pose.orientation) - tf2::getYaw(truth->pose.pose.orientation),
        2 * M_PI);
    EXPECT_LT(std::abs(dyaw), 2.0 * M_PI / 180.0);
    EXPECT_GT(odom->pose.covariance[0], 0.0);
    EXPECT_GT(odom->twist.covariance[35], 0.0);
  }

  static std::unique_ptr<ros::NodeHandle> nh_;
  static std::vector<ros::Subscriber> subs_;
  static ros::Publisher cmd_pub_, inject_pub_;
  static std::unique_ptr<ros::AsyncSpinner> spinner_;
  static Latest<SystemState> state_;
  static Latest<nav_msgs::Odometry> odom_, truth_;
  static Latest<ranger_msgs::UltrasonicState> ultrasonic_;
  static Latest<sensor_msgs::Range> range_;
  static Latest<ranger_msgs::RemoteState> remote_;
  static std::atomic<int> odom_count_, joints_count_, odom_stamp_regressions_, remote_count_;
  static std::mutex commands_mutex_;
  static std::deque<geometry_msgs::TwistStamped> commands_;
  static std::deque<SystemState> states_;
  static std::vector<rosgraph_msgs::Log> logs_;
  static std::map<std::string, diagnostic_msgs::DiagnosticStatus> diagnostics_;
};

std::unique_ptr<ros::NodeHandle> NodeSim::nh_;
std::vector<ros::Subscriber> NodeSim::subs_;
ros::Publisher NodeSim::cmd_pub_, NodeSim::inject_pub_;
std::unique_ptr<ros::AsyncSpinner> NodeSim::spinner_;
Latest<SystemState> NodeSim::state_;
Latest<nav_msgs::Odometry> NodeSim::odom_, NodeSim::truth_;
Latest<ranger_msgs::UltrasonicState> NodeSim::ultrasonic_;
Latest<sensor_msgs::Range> NodeSim::range_;
Latest<ranger_msgs::RemoteState> NodeSim::remote_;
std::atomic<int> NodeSim::odom_count_{0}, NodeSim::joints_count_{0},
    NodeSim::odom_stamp_regressions_{0}, NodeSim::remote_count_{0};
std::mutex NodeSim::commands_mutex_;
std::deque<geometry_msgs::TwistStamped> NodeSim::commands_;
std::deque<SystemState> NodeSim::states_;
std::vector<rosgraph_msgs::Log> NodeSim::logs_;
std::map<std::string, diagnostic_msgs::DiagnosticStatus> NodeSim::diagnostics_;

double yaw_of(const nav_msgs::Odometry& o) {
  return tf2::getYaw(o.pose.pose.orientation);
}

TEST_F(NodeSim, HandshakeReachesCanCommandMode) {
  const auto s = state_.get();
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->link_up);
  EXPECT_EQ(s->control_mode, SystemState::CONTROL_MODE_CAN);
  EXPECT_EQ(s->vehicle_status, SystemState::VEHICLE_STATUS_NORMAL);
  EXPECT_EQ(s->error_word, 0u);
}

TEST_F(NodeSim, AckermannArcMovesForwardAndTurnsLeft) {
  const auto start = *truth_.get();
  ASSERT_TRUE(drive_until(twist(0.5, 0.0, 0.4), [&] {
    const auto t = truth_.get();
    return std::hypot(t->pose.pose.position.x - start.pose.pose.position.x,
                      t->pose.pose.position.y - start.pose.pose.position.y) > 0.8;
  }));
  EXPECT_EQ(state_.get()->motion_mode, SystemState::MOTION_MODE_ACKERMANN);
  const auto end = *truth_.get();
  EXPECT_GT(std::remainder(yaw_of(end) - yaw_of(start), 2 * M_PI), 0.1);  // CCW = left (REP-103)
  stop_and_settle();
  expect_odom_matches_truth(1.0);
}

TEST_F(NodeSim, LateralVelocityCrabsInObliqueMode) {
  const auto start = *truth_.get();
  const double yaw0 = yaw_of(start);
  ASSERT_TRUE(drive_until(twist(0.0, 0.4, 0.0), [&] {
    const auto t = truth_.get();
    // Displacement expressed in the body frame at the start: to the left (+y).
    const double dx = t->pose.pose.position.x - start.pose.pose.position.x;
    const double dy = t->pose.pose.position.y - start.pose.pose.position.y;
    return -std::sin(yaw0) * dx + std::cos(yaw0) * dy > 0.5;
  }));
  EXPECT_EQ(state_.get()->motion_mode, SystemState::MOTION_MODE_OBLIQUE);
  EXPECT_LT(std::abs(std::remainder(yaw_of(*truth_.get()) - yaw0, 2 * M_PI)), 0.02);
  stop_and_settle();
  expect_odom_matches_truth(1.0);
}

TEST_F(NodeSim, PureRotationSpinsInPlace) {
  const auto start = *truth_.get();
  double turned = 0.0, last = yaw_of(start);
  ASSERT_TRUE(drive_until(twist(0.0, 0.0, 0.6), [&] {
    const double y = yaw_of(*truth_.get());
    turned += std::remainder(y - last, 2 * M_PI);
    last = y;
    return turned > 1.5;
  }));
  EXPECT_EQ(state_.get()->motion_mode, SystemState::MOTION_MODE_SPIN);
  const auto end = *truth_.get();
  EXPECT_LT(std::hypot(end.pose.pose.position.x - start.pose.pose.position.x,
                       end.pose.pose.position.y - start.pose.pose.position.y),
            0.05);
  stop_and_settle();
  expect_odom_matches_truth(0.0);
}

TEST_F(NodeSim, CmdVelStoppingGivesAZeroCommandWithinTheTimeout) {
  ASSERT_TRUE(
      drive_until(twist(0.4, 0.0, 0.0), [] { return truth_.get()->twist.twist.linear.x > 0.3; }));
  ASSERT_TRUE(drive_for(twist(0.4, 0.0, 0.0), 5));  // keep driving a little: the command is fresh
  const ros::Time last_publish = ros::Time::now();
  cmd_pub_.publish(twist(0.4, 0.0, 0.0));
  // Then silence. The first zero 0x111 after the last cmd_vel must be stamped (by the node, when
  // it sent it) no earlier than the timeout after that cmd_vel was published, and no later than
  // the timeout + one publish period + a generous allowance for ROS transport and scheduling.
  std::optional<geometry_msgs::TwistStamped> first_zero;
  ASSERT_TRUE(wait_for([&] {
    for (const auto& c : commands_since(last_publish)) {
      if (is_zero(c)) {
        first_zero = c;
        return true;
      }
    }
    return false;
  }));
  const double delay = (first_zero->header.stamp - last_publish).toSec();
  EXPECT_GE(delay, kCmdVelTimeout - 0.001);
  EXPECT_LE(delay, kCmdVelTimeout + kPublishPeriod + 0.25);
  // Until then the chassis kept being commanded (keep-alive), in order.
  for (const auto& c : commands_since(last_publish)) {
    if (c.header.stamp >= first_zero->header.stamp) break;
    EXPECT_GT(c.twist.linear.x, 0.0);
  }
  EXPECT_TRUE(wait_for([] { return state_.get()->motion_inhibited_reason == "cmd_timeout"; }));
  ASSERT_TRUE(wait_for([] { return speed(*truth_.get()) < 1e-3; }));
}

TEST_F(NodeSim, NonFiniteCommandsAreRefusedStopTheChassisAndAreLoggedThrottled) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& bad : {twist(nan, 0, 0), twist(0, inf, 0), twist(0.3, 0, -inf)}) {
    ASSERT_TRUE(
        drive_until(twist(0.4, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.3; }));
    const ros::Time sent = ros::Time::now();
    cmd_pub_.publish(bad);
    // A zero command follows at once (not after the timeout), and nothing non-finite is sent.
    ASSERT_TRUE(wait_for([&] {
      for (const auto& c : commands_since(sent)) {
        if (is_zero(c)) return true;
      }
      return false;
    }));
    for (const auto& c : commands_since(sent)) {
      EXPECT_TRUE(std::isfinite(c.twist.linear.x) && std::isfinite(c.twist.linear.y) &&
                  std::isfinite(c.twist.angular.z));
    }
    ASSERT_TRUE(wait_for([] { return speed(*truth_.get()) < 1e-3; }));
  }
  // A flood of NaN over more than a second: the refusal is logged at most once per second. Each
  // NaN is published once the node has sent a motion command since the previous one.
  const ros::Time flood_start = ros::Time::now();
  while ((ros::Time::now() - flood_start).toSec() < 1.5) {
    const ros::Time before = newest_command();
    cmd_pub_.publish(twist(nan, 0, 0));
    ASSERT_TRUE(wait_for([&] { return newest_command() > before; }, 5.0));
  }
  const double flood_s = (ros::Time::now() - flood_start).toSec();
  // A log line the node writes after the flood: once it is here, so is every earlier one (one
  // publisher, one ordered connection).
  const ros::Time marker = ros::Time::now();
  ros::ServiceClient modes = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ranger_msgs::SetMotionMode automatic;
  automatic.request.mode = ranger_msgs::SetMotionMode::Request::AUTOMATIC;
  ASSERT_TRUE(modes.call(automatic));
  ASSERT_TRUE(logged("set_motion_mode", marker));
  std::lock_guard<std::mutex> lock(commands_mutex_);
  int refusals = 0;
  for (const auto& l : logs_) {
    if (l.header.stamp >= flood_start && l.header.stamp < marker &&
        l.msg.find("cmd_vel refused") != std::string::npos) {
      ++refusals;
    }
  }
  EXPECT_GE(refusals, 1);
  EXPECT_LE(refusals, static_cast<int>(std::ceil(flood_s)) + 1);
}

TEST_F(NodeSim, HugeCommandsAreClampedToTheLimits) {
  ASSERT_TRUE(
      drive_until(twist(1e9, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.9; }));
  const ros::Time t = ros::Time::now();
  ASSERT_TRUE(drive_for(twist(1e9, 0, 0), 20));
  const auto commands = commands_since(t);
  ASSERT_FALSE(commands.empty());
  for (const auto& c : commands)
    EXPECT_LE(c.twist.linear.x, kMaxLinearSpeed + 1e-3);
  EXPECT_LE(truth_.get()->twist.twist.linear.x, kMaxLinearSpeed + 1e-3);
  stop_and_settle();
}

TEST_F(NodeSim, AFloodOfCommandsIsRateBoundedAndTheNodeStaysResponsive) {
  const ros::Time start = ros::Time::now();
  for (int i = 0; i < 3000; ++i)
    cmd_pub_.publish(twist(0.1 + 0.0001 * (i % 100), 0, 0));
  const ros::Time end = ros::Time::now();
  // Commands arrive in order: once one stamped after the flood is here, the flood's all are.
  ASSERT_TRUE(wait_for([&] { return newest_command() > end; }));
  const auto commands = commands_since(start);
  // Whatever arrives, changed commands go out at most every min_command_interval, plus the
  // 20 ms keep-alive: the bus load stays bounded.
  int in_window = 0;
  for (const auto& c : commands) {
    if (c.header.stamp <= end) ++in_window;
  }
  const double window = (end - start).toSec();
  EXPECT_LE(in_window,
            static_cast<int>(window / kMinCommandInterval + window / kKeepAlivePeriod) + 2);
  // Still alive and obeying: the latest command drives the chassis.
  ASSERT_TRUE(drive_until(
      twist(0.3, 0, 0), [] { return std::abs(truth_.get()->twist.twist.linear.x - 0.3) < 0.02; }));
  stop_and_settle();
}

TEST_F(NodeSim, UltrasonicServiceReachesTheChassis) {
  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::SetUltrasonic>("set_ultrasonic");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  for (const bool enable : {true, false}) {
    ranger_msgs::SetUltrasonic srv;
    srv.request.enable = enable;
    srv.request.disable = !enable;
    ASSERT_TRUE(client.call(srv));
    EXPECT_TRUE(srv.response.success) << srv.response.message;
    EXPECT_EQ(srv.response.enabled, enable);
    EXPECT_TRUE(wait_for([&] {
      const auto u = ultrasonic_.get();
      return u && u->avoidance_known && u->avoidance_enabled == enable;
    }));
  }
  const auto u = ultrasonic_.get();
  ASSERT_EQ(u->sensors.size(), 8u);
  EXPECT_EQ(u->sensors[0].status, "ok");
  ASSERT_TRUE(wait_for([] { return range_.get().has_value(); }));
  EXPECT_EQ(range_.get()->header.frame_id, "ultrasonic_1_link");  // no frame_prefix here
  EXPECT_NEAR(range_.get()->range, 3.0, 1e-3);                    // sim/ultrasonic_range
}

TEST_F(NodeSim, UltrasonicServiceRefusesEmptyAndContradictoryRequests) {
  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::SetUltrasonic>("set_ultrasonic");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  for (const bool both : {false, true}) {
    ranger_msgs::SetUltrasonic srv;
    srv.request.enable = both;
    srv.request.disable = both;
    ASSERT_TRUE(client.call(srv));
    EXPECT_FALSE(srv.response.success);
    EXPECT_NE(srv.response.message.find(both ? "contradictory" : "empty"), std::string::npos)
        << srv.response.message;
    EXPECT_NE(srv.response.message.find("nothing sent"), std::string::npos);
  }
}

TEST_F(NodeSim, ClearErrorsRefusesAnUnknownCodeAndAnswersWithTheChassisErrorWord) {
  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::ClearErrors>("clear_errors");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::ClearErrors srv;
  srv.request.code = 0x11;
  ASSERT_TRUE(client.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("17"), std::string::npos) << srv.response.message;
  srv.request.code = ranger_msgs::ClearErrors::Request::ALL_NON_CRITICAL;
  ASSERT_TRUE(client.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.error_word, 0u);
  EXPECT_NE(srv.response.message.find("the chassis answered with error word 0x00000000"),
            std::string::npos)
      << srv.response.message;
}

TEST_F(NodeSim, MotionModeCanBePinnedAndReleased) {
  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::SetMotionMode srv;
  srv.request.mode = ranger_msgs::SetMotionMode::Request::OBLIQUE;
  ASSERT_TRUE(client.call(srv));
  EXPECT_TRUE(srv.response.success);
  // Straight ahead would be Ackermann automatically; pinned, it is driven in oblique mode.
  ASSERT_TRUE(drive_until(twist(0.2, 0, 0), [] {
    return state_.get()->motion_mode == SystemState::MOTION_MODE_OBLIQUE &&
           truth_.get()->twist.twist.linear.x > 0.1;
  }));
  stop_and_settle();
  srv.request.mode = ranger_msgs::SetMotionMode::Request::AUTOMATIC;
  ASSERT_TRUE(client.call(srv));
  EXPECT_TRUE(srv.response.success);
  ASSERT_TRUE(drive_until(twist(0.3, 0, 0.3), [] {
    return state_.get()->motion_mode == SystemState::MOTION_MODE_ACKERMANN &&
           truth_.get()->twist.twist.linear.x > 0.1;
  }));
  srv.request.mode = 7;
  ASSERT_TRUE(client.call(srv));
  EXPECT_FALSE(srv.response.success);
  stop_and_settle();
}

TEST_F(NodeSim, LightsAndParkAreRefusedByNameOnTheManualsChassis) {
  ros::ServiceClient lights = nh_->serviceClient<ranger_msgs::SetLights>("set_lights");
  ros::ServiceClient park = nh_->serviceClient<std_srvs::SetBool>("park");
  ASSERT_TRUE(lights.waitForExistence(ros::Duration(10.0)));
  ASSERT_TRUE(park.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::SetLights l;
  l.request.front_mode = ranger_msgs::SetLights::Request::BREATHING;
  ASSERT_TRUE(lights.call(l));
  EXPECT_FALSE(l.response.success);
  EXPECT_NE(l.response.message.find("lights: unsupported by protocol manual"), std::string::npos)
      << l.response.message;
  std_srvs::SetBool p;
  p.request.data = true;
  ASSERT_TRUE(park.call(p));
  EXPECT_FALSE(p.response.success);
  EXPECT_NE(p.response.message.find("park: unsupported by protocol manual"), std::string::npos)
      << p.response.message;
  EXPECT_FALSE(state_.get()->park_requested);
  // Side slip is not in the manual's numbering either.
  ros::ServiceClient modes = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ranger_msgs::SetMotionMode m;
  m.request.mode = ranger_msgs::SetMotionMode::Request::SIDE_SLIP;
  ASSERT_TRUE(modes.call(m));
  EXPECT_FALSE(m.response.success);
  EXPECT_NE(m.response.message.find("side_slip: unsupported by protocol manual"), std::string::npos)
      << m.response.message;
  // No remote state from a chassis that sends no 0x241; the version is known unsupported.
  EXPECT_EQ(remote_count_.load(), 0);
  EXPECT_EQ(state_.get()->firmware_version_state, "unsupported");
  // And cmd_vel still drives.
  ASSERT_TRUE(
      drive_until(twist(0.3, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  stop_and_settle();
}

// ---- the vendor's additions on sim:agx_v2 (node_sim_vendor.test) ------------------------------

class Vendor : public NodeSim {};

TEST_F(Vendor, RemoteStateIsPublishedWithSwitchesByName) {
  ASSERT_TRUE(wait_for([] { return remote_count_ > 5; }));
  const auto r = remote_.get();
  EXPECT_EQ(r->swb, "up") << "SWB up: CAN command mode";
  EXPECT_EQ(r->swa, "up");
  EXPECT_GE(r->left_vertical, -1.0f);
  EXPECT_LE(r->left_vertical, 1.0f);
  EXPECT_GT(r->header.stamp.toSec(), 0.0);
}

TEST_F(Vendor, SetLightsIsAnsweredWithTheStateTheChassisReports) {
  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::SetLights>("set_lights");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  using Req = ranger_msgs::SetLights::Request;
  ranger_msgs::SetLights srv;
  srv.request.front_mode = Req::BREATHING;
  srv.request.rear_mode = Req::CUSTOM;
  srv.request.rear_brightness = 40;
  ASSERT_TRUE(client.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.message, "the chassis reports front breathing, rear custom 40");
  EXPECT_TRUE(srv.response.can_control);
  EXPECT_EQ(srv.response.front_mode, Req::BREATHING);
  EXPECT_EQ(srv.response.rear_mode, Req::CUSTOM);
  EXPECT_EQ(srv.response.rear_brightness, 40);
  // A brightness above 100 is refused before anything is sent.
  srv.request.rear_brightness = 101;
  ASSERT_TRUE(client.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("rear_brightness 101"), std::string::npos)
      << srv.response.message;
  EXPECT_EQ(srv.response.rear_brightness, 40) << "the state the chassis still reports";
  // Off again.
  srv.request.front_mode = srv.request.rear_mode = Req::OFF;
  srv.request.rear_brightness = 0;
  ASSERT_TRUE(client.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.front_mode, Req::OFF);
}

TEST_F(Vendor, ParkRefusesMotionByNameUntilReleased) {
  ros::ServiceClient park = nh_->serviceClient<std_srvs::SetBool>("park");
  ASSERT_TRUE(park.waitForExistence(ros::Duration(10.0)));
  std_srvs::SetBool srv;
  srv.request.data = true;
  ASSERT_TRUE(park.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  ASSERT_TRUE(wait_for([] {
    const auto s = state_.get();
    return s->parked && s->park_requested && s->motion_mode_name == "park";
  }));
  // Every twist is refused by name; the chassis does not move.
  const double x0 = truth_.get()->pose.pose.position.x;
  ASSERT_TRUE(drive_for_states(twist(0.4, 0, 0), 10));
  EXPECT_EQ(state_.get()->motion_inhibited_reason, "parked");
  EXPECT_NE(state_.get()->motion_inhibited_detail.find("call park with data = false"),
            std::string::npos);
  EXPECT_NEAR(truth_.get()->pose.pose.position.x, x0, 1e-6);
  // Released: the twist drives again.
  srv.request.data = false;
  ASSERT_TRUE(park.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  ASSERT_TRUE(
      drive_until(twist(0.4, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  EXPECT_FALSE(state_.get()->park_requested);
  EXPECT_EQ(state_.get()->motion_inhibited_reason, "");
  stop_and_settle();
}

TEST_F(Vendor, TheFirmwareVersionIsInSystemStateAndDiagnostics) {
  std::string want;
  ASSERT_TRUE(ros::param::get("~expected_firmware", want));
  ASSERT_TRUE(wait_for([&] { return state_.get()->firmware_version == want; }))
      << state_.get()->firmware_version;
  EXPECT_EQ(state_.get()->firmware_version_state, "answered");
  ASSERT_TRUE(wait_for([&] {
    const auto d = diagnostic("CAN link");
    return d && value_of(*d, "Firmware version") == want;
  }));
}

// ---- the RANGER MINI V1 (node_sim_mini_v1.test) -----------------------------------------------

class MiniV1 : public NodeSim {};

TEST_F(MiniV1, SideSlipThroughSetMotionModeMovesSidewaysWithOdometry) {
  ros::ServiceClient modes = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ASSERT_TRUE(modes.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::SetMotionMode srv;
  srv.request.mode = ranger_msgs::SetMotionMode::Request::SIDE_SLIP;
  ASSERT_TRUE(modes.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  const auto y0 = truth_.get()->pose.pose.position.y;
  const auto oy0 = odom_.get()->pose.pose.position.y;
  ASSERT_TRUE(drive_until(twist(0, 0.3, 0), [&] {
    return state_.get()->motion_mode_name == "side_slip" &&
           truth_.get()->pose.pose.position.y > y0 + 0.5;
  }));
  EXPECT_EQ(state_.get()->motion_mode, 3) << "the MINI V1's side slip is its mode 3";
  EXPECT_NEAR(truth_.get()->twist.twist.linear.y, 0.3, 0.02);
  EXPECT_NEAR(odom_.get()->pose.pose.position.y - oy0, truth_.get()->pose.pose.position.y - y0,
              0.05);
  stop_and_settle();
  srv.request.mode = ranger_msgs::SetMotionMode::Request::AUTOMATIC;
  ASSERT_TRUE(modes.call(srv));
  // Park is not the MINI V1's.
  ros::ServiceClient park = nh_->serviceClient<std_srvs::SetBool>("park");
  std_srvs::SetBool p;
  p.request.data = true;
  ASSERT_TRUE(park.call(p));
  EXPECT_FALSE(p.response.success);
  EXPECT_NE(p.response.message.find("park: unsupported by protocol"), std::string::npos)
      << p.response.message;
}

// ---- the RANGER MINI 3.0 (node_sim_mini_v3.test) ----------------------------------------------

class MiniV3 : public NodeSim {
 protected:
  // The odometry against the ground truth since `start`: within 1 % of the distance + 2 cm.
  static void expect_odometry_within_budget(const nav_msgs::Odometry& odom0,
                                            const nav_msgs::Odometry& truth0, double distance) {
    const auto odom = *odom_.get();
    const auto truth = *truth_.get();
    const double tolerance = 0.02 + 0.01 * distance;
    const double dx_odom = odom.pose.pose.position.x - odom0.pose.pose.position.x;
    const double dy_odom = odom.pose.pose.position.y - odom0.pose.pose.position.y;
    const double dx_truth = truth.pose.pose.position.x - truth0.pose.pose.position.x;
    const double dy_truth = truth.pose.pose.position.y - truth0.pose.pose.position.y;
    EXPECT_LE(std::hypot(dx_odom - dx_truth, dy_odom - dy_truth), tolerance)
        << "odometry off by more than 1 % of " << distance << " m + 2 cm";
    const double turned_odom = std::remainder(yaw_of(odom) - yaw_of(odom0), 2 * M_PI);
    const double turned_truth = std::remainder(yaw_of(truth) - yaw_of(truth0), 2 * M_PI);
    EXPECT_LT(std::abs(std::remainder(turned_odom - turned_truth, 2 * M_PI)), M_PI / 180.0);
  }
  static std::string drive_mode_diagnostic() {
    const auto d = diagnostic(std::string(ranger::kDiagControl));
    return d ? value_of(*d, "Drive mode") : "<no diagnostics>";
  }
};

TEST_F(MiniV3, TheDriveModeIsSetThroughItsServiceAndReported) {
  ASSERT_TRUE(wait_for([] { return state_.get()->drive_mode_name == "current"; }));
  EXPECT_EQ(state_.get()->drive_mode, SystemState::DRIVE_MODE_CURRENT);
  ros::ServiceClient drive = nh_->serviceClient<ranger_msgs::SetDriveMode>("set_drive_mode");
  ASSERT_TRUE(drive.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::SetDriveMode srv;
  srv.request.mode = ranger_msgs::SetDriveMode::Request::VOLTAGE;
  ASSERT_TRUE(drive.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.message, "the chassis reports drive mode voltage");
  EXPECT_EQ(srv.response.drive_mode, SystemState::DRIVE_MODE_VOLTAGE);
  ASSERT_TRUE(wait_for([] { return state_.get()->drive_mode_name == "voltage"; }));
  EXPECT_EQ(state_.get()->drive_mode, SystemState::DRIVE_MODE_VOLTAGE);
  EXPECT_TRUE(wait_for([] { return drive_mode_diagnostic() == "voltage"; }))
      << drive_mode_diagnostic();
  srv.request.mode = 7;
  ASSERT_TRUE(drive.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("nothing sent"), std::string::npos);
  srv.request.mode = ranger_msgs::SetDriveMode::Request::CURRENT;
  ASSERT_TRUE(drive.call(srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
}

TEST_F(MiniV3, DrivesEveryModeWithinTheOdometryBudgetAndReportsRearOdometry) {
  EXPECT_EQ(state_.get()->protocol_profile, "mini_v3");
  struct Mode {
    geometry_msgs::Twist twist;
    std::uint8_t mode;
    double distance;  // m the truth should cover (or rad turned, for the spin)
  } modes[] = {{twist(0.6, 0.0, 0.4), SystemState::MOTION_MODE_ACKERMANN, 1.5},
               {twist(0.0, 0.4, 0.0), SystemState::MOTION_MODE_OBLIQUE, 1.0},
               {twist(0.0, 0.0, 0.8), SystemState::MOTION_MODE_SPIN, 2.0}};
  for (const Mode& m : modes) {
    const auto odom0 = *odom_.get();
    const auto truth0 = *truth_.get();
    double travelled = 0.0, turned = 0.0, last_yaw = yaw_of(truth0);
    auto last = truth0.pose.pose.position;
    ASSERT_TRUE(drive_until(
        m.twist,
        [&] {
          const auto t = *truth_.get();
          travelled += std::hypot(t.pose.pose.position.x - last.x, t.pose.pose.position.y - last.y);
          turned += std::abs(std::remainder(yaw_of(t) - last_yaw, 2 * M_PI));
          last = t.pose.pose.position;
          last_yaw = yaw_of(t);
          return (m.mode == SystemState::MOTION_MODE_SPIN ? turned : travelled) > m.distance;
        }))
        << "mode " << int(m.mode);
    EXPECT_EQ(state_.get()->motion_mode, m.mode);
    stop_and_settle();
    expect_odometry_within_budget(odom0, truth0, travelled);
  }
  // The chassis's own odometers, front and rear, in metres.
  const auto s = *state_.get();
  for (double d : {s.front_left_distance, s.front_right_distance, s.rear_left_distance,
                   s.rear_right_distance}) {
    EXPECT_TRUE(std::isfinite(d));
    EXPECT_NE(d, 0.0);
  }
}

TEST_F(MiniV3, WhatItLacksIsRefusedByName) {
  ros::ServiceClient lights = nh_->serviceClient<ranger_msgs::SetLights>("set_lights");
  ranger_msgs::SetLights l;
  l.request.front_mode = ranger_msgs::SetLights::Request::ON;
  l.request.rear_mode = ranger_msgs::SetLights::Request::ON;
  ASSERT_TRUE(lights.call(l));
  EXPECT_FALSE(l.response.success);
  EXPECT_NE(l.response.message.find("a rear light: unsupported by protocol mini_v3"),
            std::string::npos)
      << l.response.message;
  l.request.rear_mode = ranger_msgs::SetLights::Request::OFF;
  l.request.front_mode = ranger_msgs::SetLights::Request::BREATHING;
  ASSERT_TRUE(lights.call(l));
  EXPECT_NE(l.response.message.find("breathing lights: unsupported by protocol mini_v3"),
            std::string::npos)
      << l.response.message;
  l.request.front_mode = ranger_msgs::SetLights::Request::OFF;
  ASSERT_TRUE(lights.call(l));
  EXPECT_TRUE(l.response.success) << l.response.message;
  ros::ServiceClient modes = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ranger_msgs::SetMotionMode m;
  m.request.mode = ranger_msgs::SetMotionMode::Request::SIDE_SLIP;
  ASSERT_TRUE(modes.call(m));
  EXPECT_FALSE(m.response.success);
  EXPECT_NE(m.response.message.find("side_slip: unsupported by protocol mini_v3"),
            std::string::npos)
      << m.response.message;
}

TEST_F(MiniV3, TheBmsAlarmsReachSystemStateAndDiagnostics) {
  inject("battery 8");  // below the 10 % cut-off: the pack's under-voltage alarm
  ASSERT_TRUE(wait_for([] {
    const auto s = state_.get();  // held: the state may be replaced meanwhile
    return std::find(s->bms_alarms.begin(), s->bms_alarms.end(), "under_voltage") !=
           s->bms_alarms.end();
  }));
  // The diagnostics come once a second.
  EXPECT_TRUE(wait_for([] {
    const auto d = diagnostic(std::string(ranger::kDiagBattery));
    return d && value_of(*d, "BMS alarms").find("under_voltage") != std::string::npos;
  }));
  EXPECT_TRUE(wait_for([] { return state_.get()->errors.battery_under_voltage; }));
  inject("battery 90");
}

// ---- safety through ROS: the re-arm latch, resume, sim/inject ------------------------

class Safety : public NodeSim {
 protected:
  // Undoes a fault injection however the test ends, so the next test starts from a normal
  // chassis: it returns once the node has applied the last line (its log says so), so that no
  // injection lands in the next test, however slowly the topic delivers it on a busy host.
  struct Injected {
    std::vector<std::string> undo;
    ~Injected() {
      const ros::Time t = ros::Time::now();
      for (const auto& line : undo)
        inject(line);
      if (!undo.empty()) {
        EXPECT_TRUE(logged("sim/inject \"" + undo.back() + "\" applied", t))
            << "the undo '" << undo.back() << "' was never applied";
      }
    }
  };
};

TEST_F(Safety, EmergencyStopLatchesUntilResume) {
  ASSERT_TRUE(
      drive_until(twist(0.4, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.3; }));
  const Injected undo{{"estop off"}};
  const ros::Time pressed = ros::Time::now();
  inject("estop on");
  // Still commanding: the chassis stops, and the node says why.
  ASSERT_TRUE(drive_until(twist(0.4, 0, 0), [] {
    const auto s = state_.get();
    return s->motion_inhibited_reason == "estop" && speed(*truth_.get()) < 1e-3;
  }));
  EXPECT_TRUE(logged("sim/inject \"estop on\" applied", pressed));

  // resume while the e-stop is pressed: refused, naming it; nothing changes.
  const auto refused = call_resume();
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.message.find("emergency_stop"), std::string::npos) << refused.message;
  EXPECT_EQ(state_.get()->motion_inhibited_reason, "estop");

  // Released: the e-stop is gone, but cmd_vel alone never restarts the chassis.
  inject("estop off");
  ASSERT_TRUE(drive_until(twist(0.4, 0, 0), [] {
    const auto s = state_.get();
    return s->vehicle_status == SystemState::VEHICLE_STATUS_NORMAL && s->rearm_required &&
           s->motion_inhibited_reason == "rearm_required";
  }));
  const ros::Time released = ros::Time::now();
  ASSERT_TRUE(drive_for(twist(0.4, 0, 0), 25));
  for (const auto& c : commands_since(released))
    EXPECT_TRUE(is_zero(c)) << "a motion command went out before resume";
  EXPECT_LT(speed(*truth_.get()), 1e-3);
  const auto held = *state_.get();
  EXPECT_TRUE(held.rearm_required);
  EXPECT_TRUE(contains(held.latched_causes, "emergency_stop"));
  EXPECT_TRUE(held.active_causes.empty());
  EXPECT_NE(held.motion_inhibited_detail.find("after emergency_stop"), std::string::npos)
      << held.motion_inhibited_detail;
  EXPECT_TRUE(logged("rearm_required after emergency_stop", pressed, rosgraph_msgs::Log::WARN));

  // resume: the chassis drives again on the same cmd_vel.
  const auto resumed = call_resume();
  EXPECT_TRUE(resumed.success) << resumed.message;
  EXPECT_TRUE(
      drive_until(twist(0.4, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.3; }));
  EXPECT_FALSE(state_.get()->rearm_required);
  stop_and_settle();
}

TEST_F(Safety, RemoteControlIsFinalUntilResume) {
  ASSERT_TRUE(
      drive_until(twist(0.3, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  // However it ends: the remote takes over and hands back to CAN command mode.
  const Injected undo{{"remote on", "remote can"}};
  inject("remote on");
  ASSERT_TRUE(drive_until(twist(0.3, 0, 0), [] {
    const auto s = state_.get();
    return s->control_mode == SystemState::CONTROL_MODE_REMOTE && speed(*truth_.get()) < 1e-3;
  }));
  // The remote is switched off: the chassis falls back to standby, and the node does not take
  // CAN control back by itself, however long cmd_vel keeps coming.
  inject("remote off");
  ASSERT_TRUE(drive_until(twist(0.3, 0, 0), [] {
    const auto s = state_.get();
    return s->control_mode == SystemState::CONTROL_MODE_STANDBY && s->reclaim_blocked;
  }));
  ASSERT_TRUE(drive_for_states(twist(0.3, 0, 0), 15));
  EXPECT_EQ(state_.get()->control_mode, SystemState::CONTROL_MODE_STANDBY);
  EXPECT_LT(speed(*truth_.get()), 1e-3);
  // A zero cmd_vel changes nothing: neither the re-arm nor CAN control; resume does both.
  ASSERT_TRUE(drive_for_states(twist(0, 0, 0), 5));
  {
    const auto s = state_.get();
    EXPECT_TRUE(s->rearm_required);
    EXPECT_TRUE(s->reclaim_blocked);
    EXPECT_EQ(s->control_mode, SystemState::CONTROL_MODE_STANDBY);
    EXPECT_EQ(s->motion_inhibited_detail,
              "rearm_required after remote: call resume to drive again");
  }
  const auto resumed = call_resume();
  EXPECT_TRUE(resumed.success) << resumed.message;
  ASSERT_TRUE(wait_for([] {
    const auto s = state_.get();
    return s->control_mode == SystemState::CONTROL_MODE_CAN && !s->reclaim_blocked;
  }));
  EXPECT_TRUE(
      drive_until(twist(0.3, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  stop_and_settle();
}

TEST_F(Safety, SimInjectRefusesUnknownAndMalformedCommandsByName) {
  const ros::Time t = ros::Time::now();
  inject("warp 9");
  ASSERT_TRUE(logged("sim/inject \"warp 9\" not applied", t, rosgraph_msgs::Log::WARN));
  inject("estop maybe");
  ASSERT_TRUE(logged("sim/inject \"estop maybe\" not applied", t, rosgraph_msgs::Log::WARN));
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& l : logs_) {
      if (l.header.stamp >= t && l.msg.find("not applied") != std::string::npos) {
        // The valid commands are named.
        EXPECT_NE(l.msg.find("estop"), std::string::npos) << l.msg;
        EXPECT_NE(l.msg.find("remote"), std::string::npos) << l.msg;
      }
    }
  }
  // Nothing was injected: a valid command after them is the first one applied, and the chassis
  // still drives.
  inject("ultrasonic all 2500");
  ASSERT_TRUE(logged("sim/inject \"ultrasonic all 2500\" applied", t));
  const Injected undo{{"ultrasonic all 3000"}};
  EXPECT_EQ(state_.get()->vehicle_status, SystemState::VEHICLE_STATUS_NORMAL);
  EXPECT_TRUE(wait_for([] { return range_.get() && std::abs(range_.get()->range - 2.5) < 1e-3; }));
  EXPECT_TRUE(
      drive_until(twist(0.3, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  stop_and_settle();
}

TEST_F(Safety, OdometryOnlyWhileTheChassisIsHeardAndItResumesFromTheLastPose) {
  ASSERT_TRUE(drive_until(twist(0.4, 0, 0), [] { return speed(*odom_.get()) > 0.3; }));
  stop_and_settle();
  ASSERT_TRUE(wait_for([] { return speed(*odom_.get()) < 1e-3; }));
  const auto before = *odom_.get();
  const ros::Time t = ros::Time::now();
  inject("silent 1.5");
  ASSERT_TRUE(wait_for([] {
    const auto s = state_.get();
    return !s->link_up && !s->motion_known;
  }));
  EXPECT_TRUE(logged("went silent", t, rosgraph_msgs::Log::WARN));
  // While the chassis is not heard, nothing is estimated, so nothing is published: count over
  // the next system_state messages (10 Hz) that still say so.
  const int odoms = odom_count_, joints = joints_count_;
  std::size_t seen = 0;
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    seen = states_.size();
  }
  ASSERT_TRUE(wait_for([&] {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    return states_.size() >= seen + 4;
  }));
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (std::size_t i = seen; i < seen + 4; ++i)
      ASSERT_FALSE(states_[i].motion_known);  // the silence lasted
  }
  EXPECT_EQ(odom_count_, odoms);
  EXPECT_EQ(joints_count_, joints);
  // Heard again: odometry comes back where it was (the chassis did not move), not from zero.
  ASSERT_TRUE(wait_for([] { return state_.get()->link_up && state_.get()->motion_known; }));
  ASSERT_TRUE(wait_for([&] { return odom_count_ > odoms; }));
  const auto after = *odom_.get();
  EXPECT_NEAR(after.pose.pose.position.x, before.pose.pose.position.x, 0.01);
  EXPECT_NEAR(after.pose.pose.position.y, before.pose.pose.position.y, 0.01);
  EXPECT_GT(std::abs(after.pose.pose.position.x), 0.1);  // really the old pose
  EXPECT_GT(after.header.stamp, before.header.stamp);
  EXPECT_TRUE(logged("chassis heard again", t));
  EXPECT_EQ(odom_stamp_regressions_, 0);
  // The link loss latched: resume re-arms (the next test's SetUp calls it).
  EXPECT_TRUE(wait_for([] { return state_.get()->rearm_required; }));
  EXPECT_TRUE(contains(state_.get()->latched_causes, "link_lost"));
}

// ---- the adversarial trial through ROS (node_sim.test on sim, node_sim_adversarial_agx.test on
// sim:agx_v2): what only the ROS edge can get wrong, judged by the virtual chassis's ground truth
// (sim/ground_truth) and what the node says (system_state, /diagnostics, /rosout). The rest of
// the trial runs in lock-step in libranger_can/test/test_adversarial.cpp.

class Adversarial : public Safety {
 protected:
  static geometry_msgs::Point position() { return truth_.get()->pose.pose.position; }
  static double moved_since(const geometry_msgs::Point& p) {
    const auto q = position();
    return std::hypot(q.x - p.x, q.y - p.y);
  }
  // The system_state messages received since index `from`.
  static std::vector<SystemState> states_since(std::size_t from) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    return std::vector<SystemState>(states_.begin() + static_cast<std::ptrdiff_t>(from),
                                    states_.end());
  }
  static std::size_t states_seen() {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    return states_.size();
  }
  // The node's log lines at `level` or above after `since` that contain `text`.
  static int log_lines(const std::string& text, const ros::Time& since, std::uint8_t level) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    return static_cast<int>(std::count_if(logs_.begin(), logs_.end(), [&](const auto& l) {
      return l.header.stamp >= since && l.level >= level && l.msg.find(text) != std::string::npos;
    }));
  }
};

// e-stop, a remote takeover handed back with SWB, link loss: each followed by a zero cmd_vel and
// then 0.5 m/s for 4 s (40 of the node's 10 Hz states) moves nothing; resume drives.
TEST_F(Adversarial, AfterAStopAZeroCmdVelAndFourSecondsOfMotionMoveNothingUntilResume) {
  struct Stop {
    const char* cause;
    const char* begin;
    const char* end;
  };
  for (const Stop& stop :
       {Stop{"emergency_stop", "estop on", "estop off"}, Stop{"remote", "remote on", "remote can"},
        Stop{"link_lost", "silent on", "silent off"}}) {
    SCOPED_TRACE(stop.cause);
    ASSERT_TRUE(
        drive_until(twist(0.5, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.4; }));
    const Injected undo{{stop.end}};
    inject(stop.begin);
    ASSERT_TRUE(drive_until(twist(0.5, 0, 0), [] {
      return speed(*truth_.get()) < 1e-3 && state_.get()->rearm_required;
    }));
    inject(stop.end);
    ASSERT_TRUE(drive_until(twist(0.5, 0, 0), [&] {
      const auto s = state_.get();
      return s->link_up && s->control_mode == SystemState::CONTROL_MODE_CAN &&
             s->active_causes.empty() && s->motion_inhibited_reason == "rearm_required" &&
             contains(s->latched_causes, stop.cause);
    }));
    ASSERT_TRUE(drive_for_states(twist(0, 0, 0), 3));  // what a planner at its goal publishes
    const auto at = position();
    const std::size_t from = states_seen();
    ASSERT_TRUE(drive_for_states(twist(0.5, 0, 0), 40));
    EXPECT_EQ(moved_since(at), 0.0) << "moved without resume";
    EXPECT_LT(speed(*truth_.get()), 1e-3);
    for (const auto& s : states_since(from)) {
      EXPECT_EQ(s.motion_inhibited_reason, "rearm_required");
      EXPECT_NE(s.motion_inhibited_detail.find("call resume"), std::string::npos)
          << s.motion_inhibited_detail;
      EXPECT_EQ(s.motion_inhibited_detail.find("zero"), std::string::npos)
          << "a zero cmd_vel is no re-arm: " << s.motion_inhibited_detail;
    }
    const auto resumed = call_resume();
    EXPECT_TRUE(resumed.success) << resumed.message;
    EXPECT_TRUE(
        drive_until(twist(0.5, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.4; }));
    stop_and_settle();
  }
}

// A NaN or an infinity in any of the six fields ({linear: {x: 0.3, z: .nan}} and the like):
// nothing moves, and system_state (and /diagnostics) name the refusal for as long as it lasts.
TEST_F(Adversarial, ANonFiniteFieldMovesNothingAndIsNamedWhileItLasts) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Field {
    const char* name;
    double geometry_msgs::Vector3::*axis;
    bool angular;
  };
  const Field fields[] = {{"linear.x", &geometry_msgs::Vector3::x, false},
                          {"linear.y", &geometry_msgs::Vector3::y, false},
                          {"linear.z", &geometry_msgs::Vector3::z, false},
                          {"angular.x", &geometry_msgs::Vector3::x, true},
                          {"angular.y", &geometry_msgs::Vector3::y, true},
                          {"angular.z", &geometry_msgs::Vector3::z, true}};
  int i = 0;
  for (const Field& f : fields) {
    const double bad = i++ % 2 ? inf : nan;
    const std::string named = std::string(f.name) + (std::isnan(bad) ? " is NaN" : " is infinite");
    SCOPED_TRACE(named);
    geometry_msgs::Twist t = twist(0.3, 0, 0);
    geometry_msgs::Vector3& vector = f.angular ? t.angular : t.linear;
    vector.*(f.axis) = bad;
    const auto at = position();
    ASSERT_TRUE(drive_for_states(t, 2));
    // A state that says cmd_timeout means the stream itself lapsed (this process or the node
    // not run for cmd_vel_timeout, 0.3 s: a busy host), and the driver is right to say so: the
    // window is then repeated, and said, up to 3 times in all. Any other reason fails.
    std::vector<SystemState> window;
    for (int attempt = 1;; ++attempt) {
      const std::size_t from = states_seen();
      ASSERT_TRUE(drive_for_states(t, 8));
      window = states_since(from);
      const bool lapsed = std::any_of(window.begin(), window.end(), [](const SystemState& s) {
        return s.motion_inhibited_reason == "cmd_timeout";
      });
      if (!lapsed || attempt == 3) break;
      std::printf(
          "[retry] %s: attempt %d saw cmd_timeout (the stream lapsed: a busy host?); "
          "the window again\n",
          named.c_str(), attempt);
      std::fflush(stdout);
    }
    for (const auto& s : window) {
      EXPECT_EQ(s.motion_inhibited_reason, "invalid_command");
      EXPECT_NE(s.motion_inhibited_detail.find(named), std::string::npos)
          << s.motion_inhibited_detail;
    }
    if (std::string(f.name) == "linear.z") {  // the issue's {x: 0.3, z: .nan}: diagnostics too
      ASSERT_TRUE(drive_until(t, [&] {
        const auto d = diagnostic("Control mode");
        return d && d->message.find(named) != std::string::npos;
      }));
    }
    EXPECT_EQ(moved_since(at), 0.0);
    ASSERT_TRUE(drive_for_states(twist(0, 0, 0), 3));  // a valid twist ends it
    EXPECT_EQ(state_.get()->motion_inhibited_reason, "");
  }
}

// Service requests the chassis cannot honour are refused, listing only what is valid here; a
// request repeated at a high rate has one log line per answer, never two.
TEST_F(Adversarial, BadServiceArgumentsAreRefusedAndEachAnswerIsLoggedOnce) {
  const bool manual = state_.get()->protocol_profile.rfind("manual", 0) == 0;
  ros::ServiceClient modes = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ranger_msgs::SetMotionMode m;
  m.request.mode = 7;
  ASSERT_TRUE(modes.call(m));
  EXPECT_FALSE(m.response.success);
  EXPECT_NE(m.response.message.find("0 (ackermann), 1 (oblique), 2 (spin)"), std::string::npos)
      << m.response.message;
  EXPECT_EQ(m.response.message.find("side_slip") != std::string::npos, !manual)
      << "side slip is valid only where the chassis has it: " << m.response.message;
  ros::ServiceClient park = nh_->serviceClient<std_srvs::SetBool>("park");
  std_srvs::SetBool p;
  p.request.data = false;
  ASSERT_TRUE(park.call(p));
  if (manual) {
    EXPECT_FALSE(p.response.success) << "no park to release: " << p.response.message;
    EXPECT_NE(p.response.message.find("park: unsupported by protocol manual"), std::string::npos)
        << p.response.message;
  } else {
    EXPECT_TRUE(p.response.success) << p.response.message;
  }

  // clear_errors as fast as it answers, for 2 s of the node's states: each answer is logged once,
  // in the library's words (the service's line, not the driver's request event besides).
  ros::ServiceClient clear = nh_->serviceClient<ranger_msgs::ClearErrors>("clear_errors");
  const ros::Time start = ros::Time::now();
  const std::size_t from = states_seen();
  int calls = 0;
  while (states_seen() < from + 20) {
    ranger_msgs::ClearErrors c;
    c.request.code = ranger_msgs::ClearErrors::Request::ALL_NON_CRITICAL;
    ASSERT_TRUE(clear.call(c));
    ASSERT_TRUE(c.response.success) << c.response.message;
    ++calls;
  }
  ASSERT_GT(calls, 10);
  // Another request of the kind ends the run of identical answers; its line counts them.
  ranger_msgs::ClearErrors other;
  other.request.code = ranger_msgs::ClearErrors::Request::MOTOR1_COMMUNICATION;
  ASSERT_TRUE(clear.call(other));
  EXPECT_TRUE(other.response.success) << other.response.message;
  const ros::Time marker = ros::Time::now();
  ros::ServiceClient modes2 = nh_->serviceClient<ranger_msgs::SetMotionMode>("set_motion_mode");
  ranger_msgs::SetMotionMode automatic;
  automatic.request.mode = ranger_msgs::SetMotionMode::Request::AUTOMATIC;
  ASSERT_TRUE(modes2.call(automatic));
  ASSERT_TRUE(logged("set_motion_mode: automatic", marker));  // everything before it is here
  EXPECT_EQ(log_lines("clear_errors code 0 (", start, rosgraph_msgs::Log::INFO), calls)
      << "one line per answer";
  EXPECT_EQ(log_lines("clear_errors 0x00", start, rosgraph_msgs::Log::DEBUG), 0)
      << "the driver's request event is not logged besides the answer";
  stop_and_settle();
}

// 1e6 rad/s at standstill is a saturated rotation (spin at its limit): the warning says so, and
// never that a translation or a rotation was dropped.
TEST_F(Adversarial, AHugeRotationAtStandstillIsWarnedAsASaturatedRotation) {
  const ros::Time start = ros::Time::now();
  ASSERT_TRUE(drive_until(twist(0, 0, 1e6), [] {
    return state_.get()->motion_mode == SystemState::MOTION_MODE_SPIN &&
           std::abs(truth_.get()->twist.twist.angular.z) > 0.5;
  }));
  ASSERT_TRUE(drive_for_states(twist(0, 0, 1e6), 10));
  EXPECT_TRUE(
      logged("cmd_vel adjusted to what the chassis can do: spin_saturated: asked (vx, vy, "
             "wz) = (0 m/s, 0 m/s, 1e+06 rad/s)",
             start, rosgraph_msgs::Log::WARN));
  EXPECT_EQ(log_lines("dropped", start, rosgraph_msgs::Log::WARN), 0);
  stop_and_settle();
}

// Silent for 2 s while driving: system_state and /diagnostics say how long the gap was, and the
// odometry's covariance grew by what the chassis could have moved in it (its speed limit, 1 m/s
// in node_sim.test, times the gap).
TEST_F(Adversarial, OdometryAcrossASilenceSaysTheGapAndGrowsTheCovariance) {
  ASSERT_TRUE(
      drive_until(twist(0.5, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.4; }));
  const auto gaps = state_.get()->odometry_gaps;
  const double variance = odom_.get()->pose.covariance[0];
  inject("silent 2");
  ASSERT_TRUE(drive_until(twist(0.5, 0, 0), [] { return !state_.get()->link_up; }));
  ASSERT_TRUE(drive_until(twist(0.5, 0, 0), [&] {
    const auto s = state_.get();
    return s->link_up && s->motion_known && s->odometry_gaps > gaps;
  }));
  const auto s = *state_.get();
  EXPECT_EQ(s.odometry_gaps, gaps + 1);
  EXPECT_GE(s.odometry_gap, 1.95);
  EXPECT_GT(s.odometry_gap_end, ros::Time());
  ASSERT_TRUE(wait_for([&] {
    const auto o = odom_.get();
    return o->header.stamp >= s.odometry_gap_end;
  }));
  const double reach = kMaxLinearSpeed * s.odometry_gap;
  EXPECT_GE(odom_.get()->pose.covariance[0], variance + reach * reach - 1e-6);
  EXPECT_GE(odom_.get()->pose.covariance[7], reach * reach - 1e-6);
  ASSERT_TRUE(wait_for([&] {
    const auto d = diagnostic("CAN link");
    const std::string gap = d ? value_of(*d, "Last odometry gap (s)") : "";
    return !gap.empty() && gap != "<missing>" &&
           std::abs(std::atof(gap.c_str()) - s.odometry_gap) < 1e-3;
  }));
  stop_and_settle();
}

// ---- node_sim_faults.test: the virtual chassis boots with motor driver 1's communication fault.

class Faults : public NodeSim {
 protected:
  void SetUp() override {
    // On a system_state published a while (ten chassis frames) after this test began: what the
    // test before left (a latch its last injection caused) is in it.
    const ros::Time begun = ros::Time::now() + ros::Duration(0.2);
    ASSERT_TRUE(wait_for([begun] {
      const auto s = state_.get();
      return s && s->header.stamp >= begun && s->link_up &&
             s->control_mode == SystemState::CONTROL_MODE_CAN && cmd_pub_.getNumSubscribers() > 0 &&
             truth_.get();
    }));
  }
};

TEST_F(Faults, ClearErrorsAnswersThenTheLatchHoldsUntilResume) {
  ASSERT_TRUE(wait_for([] { return state_.get()->errors.motor_driver_1_communication_fault; }));
  EXPECT_EQ(state_.get()->motion_inhibited_reason, "critical_error");
  // The fault stops the chassis: commands do not move it.
  ASSERT_TRUE(drive_for(twist(0.4, 0, 0), 10));
  EXPECT_LT(speed(*truth_.get()), 1e-3);

  ros::ServiceClient client = nh_->serviceClient<ranger_msgs::ClearErrors>("clear_errors");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(10.0)));
  ranger_msgs::ClearErrors srv;
  srv.request.code = ranger_msgs::ClearErrors::Request::MOTOR1_COMMUNICATION;
  ASSERT_TRUE(client.call(srv));
  // The answer is the chassis's error word after it received the request: cleared.
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.error_word, 0u) << srv.response.message;
  ASSERT_TRUE(wait_for([] { return state_.get()->error_word == 0; }));
  // The error is gone, but the stop it caused latched: cmd_vel alone does not move the chassis.
  ASSERT_TRUE(wait_for([] {
    const auto s = state_.get();
    return s->rearm_required && s->motion_inhibited_reason == "rearm_required";
  }));
  EXPECT_TRUE(contains(state_.get()->latched_causes, "critical_error"));
  ASSERT_TRUE(drive_for(twist(0.4, 0, 0), 10));
  EXPECT_LT(speed(*truth_.get()), 1e-3);
  EXPECT_TRUE(state_.get()->rearm_required);
  // resume re-arms.
  const auto resumed = call_resume();
  EXPECT_TRUE(resumed.success) << resumed.message;
  EXPECT_TRUE(
      drive_until(twist(0.4, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.3; }));
  EXPECT_FALSE(state_.get()->rearm_required);
  stop_and_settle();
}

// ---- node_sim_fault_bits*.test: every error bit of the chassis's layout, by meaning ------------

class FaultBits : public Faults {
 protected:
  // The error-word layout of the chassis (the test's private parameter): "manual", "agx_v2" or
  // "mini_v3".
  static ranger::ErrorWordLayout layout() {
    std::string name = "manual";
    ros::param::get("~layout", name);
    if (name == "agx_v2") return ranger::ErrorWordLayout::kAgxV2_16;
    return name == "mini_v3" ? ranger::ErrorWordLayout::kMini32
                             : ranger::ErrorWordLayout::kManual32;
  }

  // The value /diagnostics' error status gives `key` (empty when absent).
  static std::string diagnostic_value(const std::string& key) {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& [name, status] : diagnostics_) {
      const std::string errors(ranger::kDiagErrors);
      if (name.size() < errors.size() ||
          name.compare(name.size() - errors.size(), std::string::npos, errors) != 0) {
        continue;
      }
      for (const auto& kv : status.values) {
        if (kv.key == key) return kv.value;
      }
    }
    return "";
  }
};

// Each bit the layout defines, raised on the virtual chassis through sim/inject, shows the
// SystemErrors field of its meaning (and no other) true in system_state, and its name active in
// /diagnostics; dropped, it clears.
TEST_F(FaultBits, EveryBitOfTheLayoutShowsTheFieldOfItsMeaning) {
  const auto& fields = ranger_base::system_error_fields();
  const auto& bits = ranger::protocol::system_error_bits(layout());
  ASSERT_FALSE(bits.empty());
  for (const auto& bit : bits) {
    const std::string name(bit.name);
    const auto field = fields.at(bit.name);
    // The chassis's own watchdog: the node's next 0x111 clears it at once (the conversion test
    // covers its field).
    if (name == "host_communication_lost") continue;
    inject("error " + std::to_string(bit.index));
    ASSERT_TRUE(wait_for([&] { return state_.get()->errors.*field != 0; })) << name;
    const auto s = *state_.get();
    EXPECT_EQ(s.error_word, 1u << bit.index) << name;
    for (const auto& [other, other_field] : fields) {
      EXPECT_EQ(s.errors.*other_field != 0, other == bit.name) << name << ": field " << other;
    }
    EXPECT_TRUE(contains(s.active_errors, name)) << name;
    EXPECT_TRUE(wait_for([&] { return diagnostic_value(name) == "active"; })) << name;
    inject("error " + std::to_string(bit.index) + " off");
    ASSERT_TRUE(wait_for([] { return state_.get()->error_word == 0; })) << name;
    EXPECT_FALSE(state_.get()->errors.*field) << name;
  }
}

// ---- node_sim_identify*.test: protocol auto (the default) -------------------------------------

class Identification : public NodeSim {
 protected:
  void SetUp() override {}  // each test watches the start-up itself

  // The profile the identification must reach (the test's private parameter).
  static std::string expected_profile() {
    std::string profile = "manual";
    ros::param::get("~expected_profile", profile);
    return profile;
  }

  static bool ready_for_commands() {
    const auto s = state_.get();
    return s && truth_.get() && cmd_pub_.getNumSubscribers() > 0;
  }
};

// cmd_vel keeps coming from the first system_state on: nothing is driven while the node says
// "identifying"; once the identification decided, the same cmd_vel drives and odometry moves.
TEST_F(Identification, NothingIsDrivenBeforeTheDecisionThenCmdVelDrives) {
  ASSERT_TRUE(wait_for(ready_for_commands, 30.0)) << "no system_state from the node";
  const auto first = *state_.get();
  EXPECT_EQ(first.protocol, "auto");
  EXPECT_NE(first.identification, "decided")
      << "the node decided before the test saw it identify: start-up too slow to observe";
  const auto arc = twist(0.4, 0.0, 0.2);
  ASSERT_TRUE(drive_until(
      arc, [] { return state_.get()->identification == "decided"; }, 30.0))
      << "identification: " << state_.get()->identification << ", "
      << state_.get()->motion_inhibited_detail;

  // What system_state said until then: identifying, never driven (cmd_vel_out: every motion
  // command the node sent, stamped when sent; the probe steers at zero speed).
  ros::Time last_identifying;
  bool saw_identifying = false;
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& st : states_) {
      if (st.identification == "decided") break;
      // identifying (listening, probing), or the handshake's own states on the way (standby).
      EXPECT_FALSE(st.motion_inhibited_reason.empty()) << st.identification;
      saw_identifying = saw_identifying || st.motion_inhibited_reason == "identifying";
      last_identifying = st.header.stamp;
    }
    for (const auto& c : commands_) {
      if (c.header.stamp <= last_identifying) EXPECT_TRUE(is_zero(c)) << "driven while identifying";
    }
  }
  EXPECT_TRUE(saw_identifying);

  // Then the same cmd_vel drives, and the odometry follows.
  const auto start = *truth_.get();
  ASSERT_TRUE(drive_until(arc, [&] {
    const auto t = truth_.get();
    return std::hypot(t->pose.pose.position.x - start.pose.pose.position.x,
                      t->pose.pose.position.y - start.pose.pose.position.y) > 0.6;
  }));
  stop_and_settle();
  ASSERT_TRUE(wait_for([] { return speed(*odom_.get()) < 1e-3; }));
  const auto odom = *odom_.get();
  EXPECT_GT(std::hypot(odom.pose.pose.position.x, odom.pose.pose.position.y), 0.5);
  expect_odom_matches_truth(1.0);

  const auto s = *state_.get();
  EXPECT_EQ(s.protocol, "auto");
  EXPECT_EQ(s.protocol_profile, expected_profile());
  // Logged once, with its evidence; in diagnostics with the decision.
  EXPECT_TRUE(logged("chassis identified in", ros::Time(), rosgraph_msgs::Log::INFO));
  EXPECT_TRUE(logged("Evidence: ", ros::Time(), rosgraph_msgs::Log::INFO));
  ASSERT_TRUE(wait_for([] {
    const auto d = diagnostic("Protocol");
    return d && value_of(*d, "Identification") == "decided";
  }));
  const auto d = *diagnostic("Protocol");
  EXPECT_EQ(d.level, diagnostic_msgs::DiagnosticStatus::OK) << d.message;
  EXPECT_EQ(d.message, "identified: " + expected_profile());
  EXPECT_NE(value_of(d, "Evidence 1"), "<missing>");
  EXPECT_NE(value_of(d, "Undecided (the preset's value, checked while driving)"), "<missing>");
}

// sim:undecidable: no reading explains it. The node stays at rest and says what to set.
TEST_F(Identification, AChassisThatCannotBeIdentifiedStaysAtRestAndSaysWhatToSet) {
  ASSERT_TRUE(wait_for(ready_for_commands, 30.0)) << "no system_state from the node";
  ASSERT_TRUE(drive_until(
      twist(0.4, 0, 0), [] { return state_.get()->identification == "failed"; }, 30.0))
      << state_.get()->identification;
  ASSERT_TRUE(drive_for_states(twist(0.4, 0, 0), 10));
  EXPECT_LT(speed(*truth_.get()), 1e-3);
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    for (const auto& c : commands_)
      EXPECT_TRUE(is_zero(c)) << "driven although not identified";
  }
  const auto s = *state_.get();
  EXPECT_EQ(s.motion_inhibited_reason, "identifying");
  EXPECT_NE(s.motion_inhibited_detail.find("could not be identified"), std::string::npos)
      << s.motion_inhibited_detail;
  ASSERT_TRUE(wait_for([] {
    const auto d = diagnostic("Protocol");
    return d && d->level == diagnostic_msgs::DiagnosticStatus::ERROR;
  }));
  const auto d = *diagnostic("Protocol");
  for (const char* expected :
       {"could not be identified", "protocol: manual", "identify_timeout",
        "ranger_can commission IFACE --wheels-lifted", "commissioning_file"}) {
    EXPECT_NE(d.message.find(expected), std::string::npos) << expected << " in " << d.message;
  }
  EXPECT_EQ(value_of(d, "Identification"), "failed");
  EXPECT_TRUE(logged("could not be identified", ros::Time(), rosgraph_msgs::Log::ERROR));
}

// ---- node_sim_implausible*.test: a sim variant driven with the wrong forced settings ----------

class Implausible : public NodeSim {};

// sim:spin_cw with protocol manual: the spin turns the other way; the yaw check stops it.
TEST_F(Implausible, AWrongSpinSignIsStoppedAndSaid) {
  EXPECT_EQ(state_.get()->protocol, "forced");
  const ros::Time t0 = ros::Time::now();
  const auto spin = twist(0, 0, 0.5);
  ASSERT_TRUE(drive_until(
      spin, [] { return state_.get()->motion_inhibited_reason == "implausible_feedback"; }, 30.0))
      << state_.get()->motion_inhibited_reason;
  const auto stopped = *state_.get();
  EXPECT_NE(stopped.motion_inhibited_detail.find("spin_sign: try cw"), std::string::npos)
      << stopped.motion_inhibited_detail;
  // At rest, and it stays there however long cmd_vel keeps coming.
  ASSERT_TRUE(drive_until(spin, [] { return speed(*truth_.get()) < 1e-3; }));
  ASSERT_TRUE(drive_for_states(spin, 10));
  EXPECT_LT(speed(*truth_.get()), 1e-3);
  EXPECT_EQ(state_.get()->motion_inhibited_reason, "implausible_feedback");
  EXPECT_TRUE(state_.get()->rearm_required);
  // Said: the warning (WARN, the value to try), the stop (ERROR), the Protocol diagnostics.
  EXPECT_TRUE(logged("plausibility: spin_sign: try cw", t0, rosgraph_msgs::Log::WARN));
  EXPECT_TRUE(logged("plausibility stop: spin_sign: try cw", t0, rosgraph_msgs::Log::ERROR));
  ASSERT_TRUE(wait_for([] {
    const auto d = diagnostic("Protocol");
    return d && d->level == diagnostic_msgs::DiagnosticStatus::ERROR;
  }));
  const auto d = *diagnostic("Protocol");
  EXPECT_NE(d.message.find("spin_sign: try cw"), std::string::npos) << d.message;
  EXPECT_NE(value_of(d, "Plausibility stop").find("spin_sign: try cw"), std::string::npos);
  // resume: the operator takes the stop on; the monitors start over.
  cmd_pub_.publish(twist(0, 0, 0));
  const auto resumed = call_resume();
  EXPECT_TRUE(resumed.success) << resumed.message;
  EXPECT_TRUE(
      wait_for([] { return state_.get()->motion_inhibited_reason != "implausible_feedback"; }));
}

// sim:inner_angle with protocol manual: the arc is steered on the wrong reference; a subtle
// mismatch warns first (WARN, the value to try), then stops.
TEST_F(Implausible, AWrongSteeringReferenceIsWarnedThenStopped) {
  const ros::Time t0 = ros::Time::now();
  const auto arc = twist(0.4, 0, 0.4);
  ASSERT_TRUE(drive_until(
      arc, [] { return state_.get()->motion_inhibited_reason == "implausible_feedback"; }, 40.0))
      << state_.get()->motion_inhibited_reason;
  EXPECT_NE(state_.get()->motion_inhibited_detail.find("steering_reference: try inner_front"),
            std::string::npos)
      << state_.get()->motion_inhibited_detail;
  ASSERT_TRUE(drive_until(arc, [] { return speed(*truth_.get()) < 1e-3; }));
  ASSERT_TRUE(
      logged("plausibility: steering_reference: try inner_front", t0, rosgraph_msgs::Log::WARN));
  ASSERT_TRUE(logged("plausibility stop: steering_reference: try inner_front", t0,
                     rosgraph_msgs::Log::ERROR));
  // The warning came first, once.
  EXPECT_LE(log_stamp("plausibility: steering_reference", rosgraph_msgs::Log::WARN),
            log_stamp("plausibility stop: steering_reference", rosgraph_msgs::Log::ERROR));
  {
    std::lock_guard<std::mutex> lock(commands_mutex_);
    int warnings = 0;
    for (const auto& l : logs_)
      warnings += l.msg.find("plausibility: steering_reference") != std::string::npos;
    EXPECT_EQ(warnings, 1);
  }
  ASSERT_TRUE(wait_for([] {
    const auto d = diagnostic("Protocol");
    return d && d->level == diagnostic_msgs::DiagnosticStatus::ERROR;
  }));
  EXPECT_NE(diagnostic("Protocol")->message.find("steering_reference: try inner_front"),
            std::string::npos)
      << diagnostic("Protocol")->message;
  cmd_pub_.publish(twist(0, 0, 0));
}

}  // namespace

// ---- driving by the remote control (node_sim_remote.test) -------------------------------------
// The virtual chassis boots under its remote (sim/boot_in_remote_mode) with protocol auto: the
// node listens, learns the wheels' reading from the remote's driving, and its odometry follows the
// chassis in every mode the remote drives (sim/inject's remote lines), the modes in system_state
// being the chassis's own; handed back (SWB up) and re-armed, the identification decides.

class Remote : public NodeSim {
 protected:
  void SetUp() override {
    ASSERT_TRUE(wait_for([] {
      const auto s = state_.get();
      return s && s->link_up && s->control_mode == SystemState::CONTROL_MODE_REMOTE &&
             inject_pub_.getNumSubscribers() > 0 && truth_.get();
    })) << "the node never heard the chassis under its remote control";
  }

  struct Pose {
    double x, y, yaw;
  };
  static Pose pose_of(const nav_msgs::Odometry& o) {
    return {o.pose.pose.position.x, o.pose.pose.position.y, tf2::getYaw(o.pose.pose.orientation)};
  }
  // `to` in the frame of `from`.
  static Pose relative(const Pose& from, const Pose& to) {
    const double dx = to.x - from.x, dy = to.y - from.y;
    const double c = std::cos(from.yaw), s = std::sin(from.yaw);
    return {c * dx + s * dy, -s * dx + c * dy, std::remainder(to.yaw - from.yaw, 2 * M_PI)};
  }
  static bool still() {
    const auto t = truth_.get();
    const auto o = odom_.get();
    return t && o && speed(*t) < 1e-3 && speed(*o) < 1e-3;
  }

  // The remote drives one segment from rest to rest; the odometry's displacement against the
  // ground truth's, each in its own frame at the start (the e2e budget plus 1 cm for the topics'
  // timing).
  static void drive(const std::string& swd, const std::string& sticks, std::uint8_t mode,
                    double seconds) {
    SCOPED_TRACE(swd + " " + sticks);
    ASSERT_TRUE(wait_for(still));
    const Pose truth0 = pose_of(*truth_.get()), odom0 = pose_of(*odom_.get());
    inject("remote swd " + swd);
    inject("remote sticks " + sticks);
    ASSERT_TRUE(wait_for([&] {
      const auto s = state_.get();
      return s->motion_mode == mode && !s->motion_mode_switching && speed(*truth_.get()) > 0.05;
    })) << "the chassis's motion mode is reported, not one the node asked for";
    wait_for([] { return false; }, seconds);
    inject("remote sticks 0 0");
    ASSERT_TRUE(wait_for(still));
    wait_for([] { return false; }, 0.5);
    const Pose truth = relative(truth0, pose_of(*truth_.get()));
    const Pose odom = relative(odom0, pose_of(*odom_.get()));
    const double distance = std::hypot(truth.x, truth.y);
    EXPECT_NEAR(odom.x, truth.x, 0.01 + 0.01 * distance);
    EXPECT_NEAR(odom.y, truth.y, 0.01 + 0.01 * distance);
    EXPECT_NEAR(odom.yaw, truth.yaw, 1.0 * M_PI / 180.0);
    EXPECT_GT(distance + std::abs(truth.yaw), 0.2) << "the segment must move";
  }
};

TEST_F(Remote, OdometryFollowsTheRemoteInEveryModeThenTheIdentificationDecides) {
  EXPECT_EQ(state_.get()->identification, "awaiting_control");
  // Nothing published before the wheels' reading is known; the remote drives, and it is.
  inject("remote sticks 0.2 -0.3");
  ASSERT_TRUE(wait_for([] { return static_cast<bool>(odom_.get()) && joints_count_ > 0; }))
      << "no odometry from the remote's driving";
  EXPECT_EQ(state_.get()->identification, "awaiting_control");
  inject("remote sticks 0 0");
  drive("top", "0.2 -0.3", SystemState::MOTION_MODE_ACKERMANN, 4.0);
  drive("top", "0 0.5", SystemState::MOTION_MODE_SPIN, 3.0);
  drive("bottom", "0.2 0.5", SystemState::MOTION_MODE_OBLIQUE, 3.0);
  drive("top", "0.2 0.3", SystemState::MOTION_MODE_ACKERMANN, 3.0);
  EXPECT_EQ(state_.get()->identification, "awaiting_control");
  EXPECT_EQ(odom_stamp_regressions_, 0);
  // SWB up, the re-arm: the probe at standstill, decided; cmd_vel drives.
  inject("remote can");
  ASSERT_TRUE(wait_for([] { return state_.get()->control_mode == SystemState::CONTROL_MODE_CAN; }));
  const auto resumed = call_resume();
  EXPECT_TRUE(resumed.success) << resumed.message;
  ASSERT_TRUE(wait_for([] { return state_.get()->identification == "decided"; }, 30.0))
      << state_.get()->motion_inhibited_detail;
  EXPECT_TRUE(
      drive_until(twist(0.3, 0, 0), [] { return truth_.get()->twist.twist.linear.x > 0.2; }));
  stop_and_settle();
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_node_sim");
  return RUN_ALL_TESTS();
}
