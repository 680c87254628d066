// The virtual chassis's remote control (user manual section 2.3): SWD and the sticks drive it in
// each motion mode through the same model as 0x111, it reports that in 0x291/0x271/0x281 (and
// 0x241 on agx_v2), SWA switches the lights and SWC the avoidance, and the control language
// refuses bad input by name. Lock-step over the test-support FakeBus, no sleeping.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/fake_bus.hpp"

namespace ranger::sim {
namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;
using protocol::RemoteSwitch;

constexpr double kDeg = M_PI / 180.0;

struct Harness {
  explicit Harness(VirtualChassisConfig config = remote_config())
      : profile(config.profile), chassis(bus, config, Timestamp{0}) {
    chassis.step(Timestamp{0});
  }
  static VirtualChassisConfig remote_config() {
    VirtualChassisConfig c;
    c.boot_in_remote_mode = true;
    return c;
  }

  Timestamp t{0};
  ProtocolProfile profile;
  test::FakeBus bus;
  VirtualChassis chassis;

  void advance(std::chrono::nanoseconds d) {
    const Timestamp end = t + d;
    while (t < end) {
      t += 1ms;
      chassis.step(t);
    }
  }
  void apply(const std::string& line) {
    auto r = apply_chassis_command(line, chassis);
    ASSERT_TRUE(r.ok()) << line << ": " << (r ? "" : r.error().message);
  }
  template <typename T>
  std::optional<T> last(std::uint32_t id) const {
    for (auto it = bus.sent.rbegin(); it != bus.sent.rend(); ++it) {
      if (it->id != id) continue;
      auto m = decode(*it, profile);
      if (!m) return std::nullopt;
      if (auto* v = std::get_if<T>(&*m)) return *v;
    }
    return std::nullopt;
  }
  ChassisSnapshot snap() const { return chassis.snapshot(); }
};

TEST(RemoteControl, LeftStickDrivesAckermannAtItsScaleRightStickSteers) {
  Harness h;
  const MotionLimits limits;
  h.apply("remote sticks 0.25 0");
  h.advance(3s);
  auto s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kAckermann);
  EXPECT_NEAR(s.twist.vx, 0.25 * limits.max_linear_speed, 1e-9);
  EXPECT_NEAR(s.twist.wz, 0.0, 1e-12);
  // Pushed right: the mean front angle turns right (REP-103 negative), the body turns clockwise.
  h.apply("remote sticks 0.25 0.5");
  h.advance(2s);
  s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kAckermann);
  EXPECT_NEAR(s.steering, -0.5 * limits.max_ackermann_angle, 1e-9);
  EXPECT_LT(s.twist.wz, 0.0);
  // 0x291 says Ackermann, 0x281 the wheels rolling forward.
  EXPECT_EQ(h.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId)->mode,
            MotionMode::kAckermann);
  const auto speeds = h.last<WheelSpeedsFeedback>(protocol::kWheelSpeedsId);
  ASSERT_TRUE(speeds);
  for (double v : speeds->speeds)
    EXPECT_GT(v, 0.3);
  // Backwards.
  h.apply("remote sticks -0.2 0");
  h.advance(3s);
  EXPECT_NEAR(h.snap().twist.vx, -0.2 * limits.max_linear_speed, 1e-9);
}

TEST(RemoteControl, RightStickAloneSpinsAndTheLeftStickBringsAckermannBack) {
  Harness h;
  const MotionLimits limits;
  h.apply("remote sticks 0 0.5");  // pushed right: clockwise
  h.advance(3s);
  auto s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kSpin);
  EXPECT_FALSE(s.switching);
  EXPECT_NEAR(s.speed, -0.5 * limits.max_spin_speed, 1e-9);
  EXPECT_LT(s.twist.wz, 0.0);
  EXPECT_EQ(h.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId)->mode, MotionMode::kSpin);
  // The wheels stand at the spin position: 0x271 reports +-atan(wheelbase/track).
  const auto angles = h.last<SteeringAnglesFeedback>(protocol::kSteeringAnglesId);
  ASSERT_TRUE(angles);
  const VehicleGeometry g;
  for (double a : angles->angles)
    EXPECT_NEAR(std::abs(a), std::atan(g.wheelbase / g.track), 0.01 * kDeg);
  // Sticks centred: the spin stops, the mode stays.
  h.apply("remote sticks 0 0");
  h.advance(2s);
  EXPECT_EQ(h.snap().motion_mode, MotionMode::kSpin);
  EXPECT_EQ(h.snap().speed, 0.0);
  // The left stick: back to Ackermann (a switch, then driving).
  h.apply("remote sticks 0.2 0");
  h.advance(3s);
  s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kAckermann);
  EXPECT_GT(s.twist.vx, 0.1);
}

TEST(RemoteControl, SwdBottomIsObliqueUpToLateral) {
  Harness h;
  h.apply("remote swd bottom");
  h.apply("remote sticks 0.2 1");  // full right: 90 deg, lateral to the right
  h.advance(4s);
  auto s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kOblique);
  EXPECT_NEAR(s.steering, -90.0 * kDeg, 1e-9);
  EXPECT_NEAR(s.twist.vx, 0.0, 1e-9);
  EXPECT_LT(s.twist.vy, -0.4);
  EXPECT_EQ(s.twist.wz, 0.0);
  EXPECT_EQ(h.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId)->mode,
            MotionMode::kOblique);
  h.apply("remote sticks 0.2 -0.5");  // 45 deg to the left
  h.advance(2s);
  s = h.snap();
  EXPECT_NEAR(s.steering, 45.0 * kDeg, 1e-9);
  EXPECT_NEAR(s.twist.vx, s.twist.vy, 1e-9);
  // SWD back up: Ackermann.
  h.apply("remote sticks 0 0");
  h.apply("remote swd top");
  h.advance(3s);
  EXPECT_EQ(h.snap().motion_mode, MotionMode::kAckermann);
}

TEST(RemoteControl, StickScaleFollowsTheModelsLimits) {
  auto model = model_preset("ranger_mini_v1");
  ASSERT_TRUE(model.ok());
  VirtualChassisConfig c = chassis_for_model(*model, Harness::remote_config());
  c.boot_in_remote_mode = true;
  Harness h(c);
  h.apply("remote swd bottom");
  h.apply("remote sticks 0.5 1");
  h.advance(4s);
  const auto s = h.snap();
  EXPECT_EQ(s.motion_mode, MotionMode::kOblique);
  EXPECT_NEAR(s.steering, -c.limits.max_oblique_angle, 1e-9);  // the MINI V1's 40 deg
  EXPECT_NEAR(s.speed, 0.5 * c.limits.max_linear_speed, 1e-9);
}

TEST(RemoteControl, SticksDoNothingOutsideRemoteModeAndTheDeadBandReadsCentred) {
  VirtualChassisConfig c;
  Harness h(c);  // standby
  h.apply("remote sticks 0.5 0");
  h.advance(2s);
  EXPECT_EQ(h.snap().speed, 0.0);
  h.apply("remote on");
  h.advance(2s);  // now the held stick drives
  EXPECT_GT(h.snap().speed, 0.5);
  h.apply("remote sticks 0.04 -0.04");  // within the dead band
  h.advance(2s);
  EXPECT_EQ(h.snap().speed, 0.0);
  EXPECT_EQ(h.snap().motion_mode, MotionMode::kAckermann);  // not a spin either
}

TEST(RemoteControl, SafetyStopsTheRemoteToo) {
  Harness h;
  h.apply("remote sticks 0.3 0");
  h.advance(2s);
  ASSERT_GT(h.snap().speed, 0.5);
  h.apply("estop on");
  h.advance(1s);
  EXPECT_EQ(h.snap().speed, 0.0);
  h.apply("estop off");
  h.advance(2s);
  EXPECT_GT(h.snap().speed, 0.5);  // the operator still holds the stick
  h.apply("remote can");           // SWB up: the host's, which has not asked for anything
  h.advance(2s);
  EXPECT_EQ(h.snap().speed, 0.0);
}

TEST(RemoteControl, ReportsSwitchesAndSticksIn0x241AndSwaSwitchesTheLights) {
  VirtualChassisConfig c = Harness::remote_config();
  auto agx = apply_variant("agx_v2", c);
  ASSERT_TRUE(agx.ok());
  Harness h(*agx);
  h.apply("remote swd bottom");
  h.apply("remote swc middle");
  h.apply("remote sticks 0.5 -0.25");
  h.advance(100ms);
  auto rc = h.last<RemoteControlState>(protocol::kRemoteControlStateId);
  ASSERT_TRUE(rc);
  EXPECT_EQ(rc->swa, RemoteSwitch::kUp);
  EXPECT_EQ(rc->swb, RemoteSwitch::kMiddle);  // remote mode
  EXPECT_EQ(rc->swc, RemoteSwitch::kMiddle);
  EXPECT_EQ(rc->swd, RemoteSwitch::kDown);
  EXPECT_EQ(rc->stick_left_v, 50);
  EXPECT_EQ(rc->stick_right_h, -25);
  EXPECT_TRUE(h.snap().ultrasonic_enabled);  // SWC middle
  // The lights (chassis_lights.hpp): under the remote SWA decides, bottom = both off, top = both
  // on; what the host set over CAN comes back when the remote hands back.
  LightCommand custom;
  custom.enable = true;
  custom.front_mode = protocol::LightMode::kCustom;
  custom.front_custom = 40;
  custom.rear_mode = protocol::LightMode::kOff;
  h.apply("remote can");
  auto f = encode(custom, h.profile);
  ASSERT_TRUE(f.ok());
  h.chassis.on_frame(*f, h.t);
  h.advance(50ms);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_mode, protocol::LightMode::kCustom);
  h.apply("remote on");
  h.advance(50ms);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_mode, protocol::LightMode::kOn);
  h.apply("remote swa bottom");
  h.advance(50ms);
  EXPECT_EQ(h.snap().lights.front_mode, protocol::LightMode::kOff);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_mode, protocol::LightMode::kOff);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->rear_mode, protocol::LightMode::kOff);
  EXPECT_EQ(h.last<RemoteControlState>(protocol::kRemoteControlStateId)->swa, RemoteSwitch::kDown);
  h.apply("remote swa top");
  h.advance(50ms);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_mode, protocol::LightMode::kOn);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->rear_mode, protocol::LightMode::kOn);
  h.apply("remote swa bottom");
  h.apply("remote can");
  h.advance(50ms);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_mode, protocol::LightMode::kCustom);
  EXPECT_EQ(h.last<LightState>(protocol::kLightStateId)->front_custom, 40);
  h.apply("remote swc top");
  EXPECT_FALSE(h.snap().ultrasonic_enabled);
}

TEST(RemoteControl, BadInputIsRefusedByName) {
  Harness h;
  const struct {
    const char* line;
    const char* says;
  } cases[] = {
      {"remote sticks nan 0", "LEFT"},
      {"remote sticks 0 inf", "RIGHT"},
      {"remote sticks 1.5 0", "outside"},
      {"remote sticks 0 -1.01", "outside"},
      {"remote sticks 0.5", "usage"},
      {"remote sticks x y", "not a number"},
      {"remote swd middle", "top|bottom"},
      {"remote swd left", "unknown position 'left'"},
      {"remote swc sideways", "top|middle|bottom"},
      {"remote swa", "usage"},
      {"remote fly", "expected on|can|off|lost|swa|swc|swd|sticks"},
  };
  for (const auto& c : cases) {
    auto r = apply_chassis_command(c.line, h.chassis);
    ASSERT_FALSE(r.ok()) << c.line;
    EXPECT_NE(r.error().message.find(c.says), std::string::npos)
        << c.line << ": " << r.error().message;
  }
  const auto s = h.snap();
  EXPECT_EQ(s.remote.left, 0.0);
  EXPECT_EQ(s.remote.right, 0.0);
  EXPECT_EQ(s.remote.swd, RemoteSwitch::kUp);
}

TEST(RemoteControl, StatusShowsTheRemote) {
  Harness h;
  h.apply("remote swd bottom");
  h.apply("remote sticks 0.5 -0.25");
  auto r = apply_chassis_command("status", h.chassis);
  ASSERT_TRUE(r.ok());
  EXPECT_NE(r->find("remote SWA top SWC top SWD bottom sticks (0.50, -0.25)"), std::string::npos)
      << *r;
}

}  // namespace
}  // namespace ranger::sim
