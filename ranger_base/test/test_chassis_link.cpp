// The CAN thread against the in-process virtual chassis (real threads, real time). Timeouts below
// only bound how long a failing test waits; nothing asserts on how long anything took.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <thread>

#include <ranger_can/clock.hpp>
#include <ranger_can/wire/protocol.hpp>

#include "ranger_base/chassis_link.hpp"

namespace ranger_base {
namespace {

using namespace std::chrono_literals;
namespace protocol = ranger::protocol;

bool wait_until(const std::function<bool()>& condition, std::chrono::seconds limit = 15s) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return condition();
}

ChassisLinkOptions sim_options() {
  ChassisLinkOptions o;
  o.port_name = "sim";
  o.sim = ranger::sim::VirtualChassisConfig{};
  return o;
}

bool in_command_mode(const LinkSnapshot& s) {
  return s.controller.link == ranger::LinkState::kConnected &&
         s.controller.control_mode == protocol::ControlMode::kCan && s.controller.motion_mode;
}

class ChassisLinkSim : public ::testing::Test {
 protected:
  void SetUp() override {
    link_ = std::make_unique<ChassisLink>(sim_options(), clock_);
    link_->start([this](const MotionCommandEvent& e) {
      ++commands_;
      if (e.command.linear_speed == 0.0 && e.command.spin_speed == 0.0) ++zero_commands_;
    });
    ASSERT_TRUE(wait_until([&] { return in_command_mode(link_->snapshot()); }))
        << "no handshake to CAN command mode";
  }

  // Keeps commanding `twist` (as a teleop would) until `condition` holds.
  bool drive_until(const ranger::BodyTwist& twist, const std::function<bool()>& condition) {
    return wait_until([&] {
      EXPECT_TRUE(link_->set_command({twist, std::nullopt}).ok());
      return condition();
    });
  }

  ranger::SteadyClock clock_;
  std::unique_ptr<ChassisLink> link_;
  std::atomic<int> commands_{0};
  std::atomic<int> zero_commands_{0};
};

TEST_F(ChassisLinkSim, HandshakeAndFeedbackReachTheSnapshot) {
  const auto s = link_->snapshot();
  EXPECT_TRUE(s.bus_open);
  EXPECT_GT(s.frames_received, 0u);
  EXPECT_TRUE(s.frames_by_id.count(protocol::kSystemStatusId));
  ASSERT_TRUE(s.sim);
  EXPECT_EQ(s.sim->control_mode, protocol::ControlMode::kCan);
}

TEST_F(ChassisLinkSim, CommandMovesTheChassisAndOdometryFollows) {
  ASSERT_TRUE(drive_until({0.5, 0.0, 0.0}, [&] { return link_->snapshot().sim->pose.x > 0.5; }));
  EXPECT_GT(commands_.load(), 0);
  const auto s = link_->snapshot();
  EXPECT_NEAR(s.odometry.pose.x, s.sim->pose.x, 0.05);
  EXPECT_NEAR(s.odometry.pose.y, s.sim->pose.y, 0.02);
  EXPECT_TRUE(s.joints.has_wheels);
  EXPECT_GT(s.joints.wheel_position[0], 0.0);
}

TEST_F(ChassisLinkSim, NonFiniteCommandIsRefusedAndStopsTheChassis) {
  ASSERT_TRUE(drive_until({0.5, 0.0, 0.0}, [&] { return link_->snapshot().sim->twist.vx > 0.3; }));
  const auto st = link_->set_command({{std::nan(""), 0.0, 0.0}, std::nullopt});
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().code, ranger::Errc::kNotFinite);
  EXPECT_TRUE(wait_until([&] { return link_->snapshot().sim->target.speed == 0.0; }));
  EXPECT_TRUE(wait_until([&] { return std::abs(link_->snapshot().sim->twist.vx) < 1e-6; }));
}

TEST_F(ChassisLinkSim, StopSendsAZeroCommandBeforeTheThreadEnds) {
  ASSERT_TRUE(drive_until({0.5, 0.0, 0.0}, [&] { return link_->snapshot().sim->twist.vx > 0.3; }));
  const int zeros_before = zero_commands_.load();
  link_->stop();
  const auto s = link_->snapshot();
  ASSERT_TRUE(s.controller.last_motion_command);
  EXPECT_EQ(s.controller.last_motion_command->linear_speed, 0.0);
  EXPECT_TRUE(s.controller.shut_down);
  // The virtual chassis received the zero: its target is a standstill.
  EXPECT_TRUE(wait_until([&] { return link_->snapshot().sim->target.speed == 0.0; }));
  EXPECT_GE(zero_commands_.load(), zeros_before);
  // After stop nothing is accepted.
  link_->set_command({{0.5, 0.0, 0.0}, std::nullopt});
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(link_->snapshot().sim->target.speed, 0.0);
}

TEST_F(ChassisLinkSim, UltrasonicSettingIsConfirmedByTheChassis) {
  ASSERT_TRUE(link_->set_ultrasonic(true).ok());
  EXPECT_TRUE(wait_until([&] {
    const auto s = link_->snapshot();
    return s.controller.ultrasonic_enabled.value_or(false) && s.sim->ultrasonic_enabled;
  }));
}

TEST_F(ChassisLinkSim, PinnedMotionModeIsReachedAtStandstill) {
  link_->request_motion_mode(protocol::MotionMode::kOblique);
  ASSERT_TRUE(drive_until({0.2, 0.0, 0.0}, [&] {
    return link_->snapshot().sim->motion_mode == protocol::MotionMode::kOblique;
  }));
}

TEST_F(ChassisLinkSim, InterfaceGoingDownIsReportedAndRecovered) {
  link_->sim_network()->set_link_up(false);  // `ip link set sim down`: the adapter is unplugged
  ASSERT_TRUE(wait_until([&] {
    const auto s = link_->snapshot();
    return s.bus.state == ranger::BusState::kDown && s.controller.link == ranger::LinkState::kStale;
  }));
  EXPECT_EQ(link_->snapshot().controller.refusal, ranger::MotionRefusal::kLinkLost);
  link_->sim_network()->set_link_up(true);
  EXPECT_TRUE(wait_until([&] {
    const auto s = link_->snapshot();
    return s.bus.state == ranger::BusState::kActive && in_command_mode(s) &&
           s.bus.stats.reopens > 0;
  }));
  EXPECT_TRUE(drive_until({0.3, 0.0, 0.0}, [&] { return link_->snapshot().sim->twist.vx > 0.2; }));
}

TEST(ChassisLink, MissingInterfaceIsReportedAndRetriedWithoutCrashing) {
  ranger::SteadyClock clock;
  ChassisLinkOptions o;
  o.port_name = "nosuchcan7";
  o.reconnect_interval = 50ms;
  ChassisLink link(o, clock);
  link.start();
  ASSERT_TRUE(wait_until([&] { return !link.snapshot().bus_error.empty(); }));
  const auto s = link.snapshot();
  EXPECT_FALSE(s.bus_open);
  EXPECT_NE(s.bus_error.find("nosuchcan7"), std::string::npos) << s.bus_error;
  const auto st = link.set_command({{0.5, 0.0, 0.0}, std::nullopt});
  EXPECT_FALSE(st.ok());
  EXPECT_FALSE(link.clear_errors(0).ok());
  // Still alive and still retrying.
  const auto iterations = s.loop_iterations;
  EXPECT_TRUE(wait_until([&] { return link.snapshot().loop_iterations > iterations; }));
  link.stop();
}

TEST(ChassisLink, InjectedErrorIsVisibleAndClearedThroughTheLink) {
  ranger::SteadyClock clock;
  auto o = sim_options();
  const auto& bits = protocol::system_error_bits();
  const auto it = std::find_if(bits.begin(), bits.end(), [](const auto& b) {
    return b.name == "motor_driver_1_communication_fault";
  });
  ASSERT_NE(it, bits.end());
  o.sim_error_bits = 1u << it->index;
  ChassisLink link(o, clock);
  link.start();
  ASSERT_TRUE(
      wait_until([&] { return link.snapshot().controller.error_bits == o.sim_error_bits; }));
  ASSERT_TRUE(link.clear_errors(0x01).ok());  // motor driver 1 communication
  EXPECT_TRUE(wait_until([&] { return link.snapshot().controller.error_bits == 0; }));
  link.stop();
}

}  // namespace
}  // namespace ranger_base
