// The virtual chassis's side of the vendor's additions: park (agx_v2 mode 3, at standstill only,
// motion ignored while parked), side slip on the MINI V1 (its mode 3, the negated field of bytes
// 4-5), the lights (0x121, the remote's SWA) and the configurable firmware version (0x4A1).
#include <gtest/gtest.h>

#include <string>

#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "support/fake_bus.hpp"

namespace ranger::sim {
namespace {

using namespace std::chrono_literals;
using protocol::LightMode;
using protocol::MotionMode;

class Chassis {
 public:
  explicit Chassis(const std::string& variant) {
    config_ = *apply_variant(variant, VirtualChassisConfig{});
    chassis_ = std::make_unique<VirtualChassis>(bus_, config_, now_);
    send(ControlModeCommand{protocol::ControlMode::kCan});
  }
  void send(const Message& m) {
    auto frame = encode(m, config_.profile);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    chassis_->on_frame(*frame, now_);
  }
  // Keeps sending `command` every 20 ms for `d`.
  void hold(const MotionCommand& command, std::chrono::nanoseconds d) {
    const Timestamp end = now_ + d;
    while (now_ < end) {
      send(command);
      now_ += 20ms;
      chassis_->step(now_);
    }
  }
  void advance(std::chrono::nanoseconds d) { hold(MotionCommand{}, d); }
  VirtualChassis& operator*() { return *chassis_; }
  VirtualChassis* operator->() { return chassis_.get(); }
  test::FakeBus& bus() { return bus_; }
  const ProtocolProfile& profile() const { return config_.profile; }

 private:
  test::FakeBus bus_;
  VirtualChassisConfig config_;
  Timestamp now_{std::chrono::seconds(10)};
  std::unique_ptr<VirtualChassis> chassis_;
};

TEST(VirtualChassisPark, OnlyAtStandstillAndNothingMovesWhileParked) {
  Chassis c("agx_v2");
  MotionCommand forward;
  forward.linear_speed = 0.5;
  c.hold(forward, 1s);
  ASSERT_GT(c->snapshot().speed, 0.3);
  c.send(MotionModeCommand{MotionMode::kPark});  // moving: ignored
  c.hold(forward, 100ms);
  EXPECT_EQ(c->snapshot().motion_mode, MotionMode::kAckermann);
  EXPECT_FALSE(c->snapshot().switching);
  c.advance(1s);  // to rest
  c.send(MotionModeCommand{MotionMode::kPark});
  c.advance(1s);
  const ChassisSnapshot parked = c->snapshot();
  ASSERT_EQ(parked.motion_mode, MotionMode::kPark);
  EXPECT_EQ(parked.motion_refused_reason, "parked");
  c.hold(forward, 1s);
  EXPECT_NEAR(c->snapshot().pose.x, parked.pose.x, 1e-9);
  EXPECT_EQ(c->snapshot().speed, 0.0);
  // 0x291 reports park in the vendor's numbering (3).
  const auto modes = c.bus().sent_with_id(protocol::kMotionModeFeedbackId);
  ASSERT_FALSE(modes.empty());
  EXPECT_EQ(modes.back().data[0], 3);
  // Leaving park: an ordinary switch.
  c.send(MotionModeCommand{MotionMode::kAckermann});
  c.advance(1s);
  c.hold(forward, 1s);
  EXPECT_GT(c->snapshot().pose.x, parked.pose.x + 0.2);
}

TEST(VirtualChassisSideSlip, TheMiniV1SlipsSidewaysOnItsNegatedField) {
  Chassis c("mini_v1");
  c.send(MotionModeCommand{MotionMode::kSideSlip});
  c.advance(1s);
  ASSERT_EQ(c->snapshot().motion_mode, MotionMode::kSideSlip);
  const auto modes = c.bus().sent_with_id(protocol::kMotionModeFeedbackId);
  EXPECT_EQ(modes.back().data[0], 3) << "side slip is the MINI V1's mode 3";
  MotionCommand left;
  left.spin_speed = -0.3;  // the MINI V1's field is negated: -0.3 on the wire = 0.3 m/s left
  c.hold(left, 2s);
  const ChassisSnapshot s = c->snapshot();
  EXPECT_NEAR(s.twist.vy, 0.3, 1e-6);
  EXPECT_NEAR(s.twist.vx, 0.0, 1e-9);
  EXPECT_NEAR(s.twist.wz, 0.0, 1e-9);
  EXPECT_GT(s.pose.y, 0.3);
  EXPECT_NEAR(s.pose.x, 0.0, 1e-6);
  for (const auto& w : s.wheels)
    EXPECT_NEAR(std::abs(w.angle), M_PI / 2, 1e-6);
  // 0x221: the lateral speed, left positive, in bytes 0-1.
  auto fb = decode(c.bus().sent_with_id(protocol::kMotionFeedbackId).back(), c.profile());
  ASSERT_TRUE(fb.ok());
  EXPECT_NEAR(std::get<MotionFeedback>(*fb).speed, 0.3, 0.002);
}

TEST(VirtualChassisLights, CanCommandsAndTheRemotesSwa) {
  Chassis c("agx_v2");
  EXPECT_EQ(c->snapshot().lights.front_mode, LightMode::kOn) << "on at power-on";
  EXPECT_FALSE(c->snapshot().lights.enable);
  LightCommand cmd;
  cmd.enable = true;
  cmd.front_mode = LightMode::kCustom;
  cmd.front_custom = 70;
  cmd.rear_mode = LightMode::kOff;
  c.send(cmd);
  c.advance(40ms);
  auto st = decode(c.bus().sent_with_id(protocol::kLightStateId).back(), c.profile());
  ASSERT_TRUE(st.ok());
  const LightState& l = std::get<LightState>(*st);
  EXPECT_TRUE(l.enable);
  EXPECT_EQ(l.front_mode, LightMode::kCustom);
  EXPECT_EQ(l.front_custom, 70);
  EXPECT_EQ(l.rear_mode, LightMode::kOff);
  // The remote takes over: SWA (up) decides, both on; handed back, CAN's setting returns.
  c->remote_takeover();
  EXPECT_EQ(c->snapshot().lights.front_mode, LightMode::kOn);
  EXPECT_EQ(c->snapshot().lights.rear_mode, LightMode::kOn);
  c->remote_hand_back();
  EXPECT_EQ(c->snapshot().lights.front_mode, LightMode::kCustom);
  // The model itself: SWA down under the remote switches both off.
  ChassisLights lights;
  lights.set_remote(true, protocol::RemoteSwitch::kDown);
  EXPECT_EQ(lights.report().front_mode, LightMode::kOff);
  EXPECT_EQ(lights.report().rear_mode, LightMode::kOff);
  EXPECT_TRUE(lights.take_changed());
  EXPECT_FALSE(lights.take_changed());
  lights.set_remote(false, protocol::RemoteSwitch::kDown);
  EXPECT_EQ(lights.report().front_mode, LightMode::kOn);
}

TEST(VirtualChassisVersion, TheControlLanguageSetsTheAnswer) {
  Chassis c("agx_v2");
  auto out = apply_chassis_command("version RANGER 5.7.3 test build", *c);
  ASSERT_TRUE(out.ok()) << out.error().message;
  c.bus().clear_sent();
  c.send(VersionRequest{});
  std::string text;
  for (const CanFrame& f : c.bus().sent_with_id(protocol::kVersionId)) {
    auto v = decode(f, c.profile());
    ASSERT_TRUE(v.ok());
    text += std::string(std::get<VersionResponse>(*v).view());
  }
  EXPECT_EQ(text, "RANGER 5.7.3 test build");
  EXPECT_FALSE(parse_chassis_command("version").ok());
  EXPECT_FALSE(parse_chassis_command("version " + std::string(65, 'x')).ok());
}

}  // namespace
}  // namespace ranger::sim
