// The virtual chassis's `mini_v3` variant (sim:mini_v3): the RANGER MINI 3.0 as its manual has it
// (shared/reference/PROTOCOL_MINI_V3.md) — the frames it sends and their lengths, the 32-bit fault
// word without counter, drive modes (0x423, 0x291 byte 2), the front and rear odometers in mm,
// park, lights on/off, its limits; over the test-support FakeBus with injected time.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "ranger_can/control/model.hpp"
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
using protocol::DriveMode;
using protocol::MotionMode;

struct Mini {
  Mini() : config(*apply_variant("mini_v3", {})), chassis(bus, config, Timestamp{0}) {
    chassis.step(t);
  }
  VirtualChassisConfig config;
  Timestamp t{0};
  test::FakeBus bus;
  VirtualChassis chassis;

  const ProtocolProfile& profile() const { return config.profile; }
  void send(const Message& m) {
    auto f = encode(m, profile());
    ASSERT_TRUE(f.ok()) << f.error().message;
    chassis.on_frame(*f, t);
  }
  void advance(std::chrono::nanoseconds d) {
    const Timestamp end = t + d;
    while (t < end) {
      t += 1ms;
      chassis.step(t);
    }
  }
  void drive(const MotionCommand& cmd, std::chrono::nanoseconds d) {
    const Timestamp end = t + d;
    while (t < end) {
      send(cmd);
      advance(20ms);
    }
  }
  void handshake() {
    send(ControlModeCommand{ControlMode::kCan});
    advance(20ms);
  }
  void switch_mode(MotionMode m) {
    send(MotionModeCommand{m});
    advance(1500ms);
    ASSERT_EQ(chassis.snapshot().motion_mode, m);
  }
  std::vector<CanFrame> frames(std::uint32_t id) const {
    std::vector<CanFrame> out;
    for (const auto& f : bus.sent)
      if (f.id == id) out.push_back(f);
    return out;
  }
  template <typename T>
  T last(std::uint32_t id) const {
    const auto all = frames(id);
    EXPECT_FALSE(all.empty()) << "no frame 0x" << std::hex << id;
    if (all.empty()) return T{};
    auto m = decode(all.back(), profile());
    EXPECT_TRUE(m.ok()) << (m ? "" : m.error().message);
    return m ? std::get<T>(*m) : T{};
  }
};

TEST(VirtualChassisMiniV3, IsTheModelsChassisSpeakingItsManual) {
  const Mini m;
  const ModelPreset model = *model_preset("ranger_mini_v3");
  EXPECT_EQ(m.config.profile, *protocol_preset("mini_v3"));
  EXPECT_EQ(m.config.geometry.wheelbase, model.geometry.wheelbase);
  EXPECT_EQ(m.config.limits.max_linear_speed, 2.0);
  EXPECT_EQ(m.config.limits.max_speed_at_large_steering, 0.7);
  EXPECT_TRUE(m.config.vendor_frames);
  EXPECT_TRUE(m.config.odometer_frames);
}

TEST(VirtualChassisMiniV3, SendsItsManualsFramesWithTheirLengthsOnly) {
  Mini m;
  m.advance(1s);
  const auto own = protocol::ids_of(FrameLayout::kMiniV3);
  std::set<std::uint32_t> seen;
  for (const auto& f : m.bus.sent) {
    seen.insert(f.id);
    EXPECT_NE(std::find(own.begin(), own.end(), f.id), own.end())
        << "not a MINI 3.0 frame: 0x" << std::hex << f.id;
    EXPECT_EQ(f.dlc, protocol::layout_dlc(f.id, FrameLayout::kMiniV3)) << std::hex << f.id;
  }
  for (std::uint32_t id : {0x211u, 0x221u, 0x231u, 0x241u, 0x251u, 0x261u, 0x271u, 0x281u, 0x291u,
                           0x311u, 0x312u, 0x361u, 0x362u})
    EXPECT_EQ(seen.count(id), 1u) << std::hex << id;
  EXPECT_EQ(m.frames(0x291).back().dlc, 3);
  EXPECT_EQ(m.frames(0x362).back().dlc, 4);
  // 0x211 byte 7 is the fault word's lowest byte, not a counter: constant at rest.
  const auto status = m.frames(protocol::kSystemStatusId);
  EXPECT_EQ(status.front().data[7], status.back().data[7]);
  EXPECT_FALSE(m.last<SystemStatus>(protocol::kSystemStatusId).counter.has_value());
}

TEST(VirtualChassisMiniV3, FaultsByMeaningInItsFaultWord) {
  Mini m;
  m.handshake();
  EXPECT_TRUE(m.chassis.set_fault(protocol::Fault::kOverCurrent, true));
  EXPECT_TRUE(m.chassis.set_fault(protocol::Fault::kBatteryOverVoltage, true));
  EXPECT_FALSE(m.chassis.set_fault(protocol::Fault::kSafetyEdge, true)) << "not a MINI 3.0 fault";
  m.chassis.set_emergency_stop(true);
  m.advance(40ms);
  const auto s = m.last<SystemStatus>(protocol::kSystemStatusId);
  EXPECT_EQ(s.vehicle_status, protocol::VehicleStatus::kEmergencyStop);
  EXPECT_EQ(protocol::error_bit_names(s.error_bits, ErrorWordLayout::kMini32),
            (std::vector<std::string>{"battery_over_voltage", "emergency_stop", "over_current"}));
  // 0x441 0x0F clears the over-current, 0x00 the rest once the e-stop is released.
  m.chassis.set_emergency_stop(false);
  m.send(ErrorClearCommand{0x0F});
  m.send(ErrorClearCommand{0x00});
  m.advance(40ms);
  EXPECT_EQ(m.last<SystemStatus>(protocol::kSystemStatusId).error_bits, 0u);
}

TEST(VirtualChassisMiniV3, DriveModesSetBy0x423AndReportedIn0x291) {
  Mini m;
  m.advance(40ms);
  auto mode = m.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId);
  ASSERT_TRUE(mode.drive_mode.has_value());
  EXPECT_EQ(*mode.drive_mode, static_cast<std::uint8_t>(DriveMode::kCurrent));
  m.send(DriveModeCommand{DriveMode::kVoltage});  // in standby: ignored
  m.advance(40ms);
  EXPECT_EQ(m.chassis.snapshot().drive_mode, DriveMode::kCurrent);
  m.handshake();
  m.send(DriveModeCommand{DriveMode::kVoltage});
  m.advance(40ms);
  EXPECT_EQ(m.chassis.snapshot().drive_mode, DriveMode::kVoltage);
  mode = m.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId);
  EXPECT_EQ(*mode.drive_mode, static_cast<std::uint8_t>(DriveMode::kVoltage));
}

TEST(VirtualChassisMiniV3, FrontAndRearOdometersFollowTheWheels) {
  Mini m;
  m.handshake();
  MotionCommand forward;
  forward.linear_speed = 0.5;
  m.drive(forward, 3s);
  forward.linear_speed = 0.0;
  m.drive(forward, 1s);
  const auto s = m.chassis.snapshot();
  const auto front = m.last<OdometerFeedback>(protocol::kOdometerId);
  const auto rear = m.last<OdometerFeedback>(protocol::kRearOdometerId);
  ASSERT_TRUE(front.left_distance && rear.right_distance);
  EXPECT_FALSE(front.rear);
  EXPECT_TRUE(rear.rear);
  // Straight ahead: every wheel rolled the body's distance (to the wire's millimetre).
  EXPECT_NEAR(*front.left_distance, s.distance_travelled, 0.002);
  EXPECT_NEAR(*front.right_distance, s.distance_travelled, 0.002);
  EXPECT_NEAR(*rear.left_distance, s.distance_travelled, 0.002);
  EXPECT_NEAR(*rear.right_distance, s.distance_travelled, 0.002);
  EXPECT_NEAR(s.wheel_distance[kLeftRear], s.distance_travelled, 1e-6);
  // A spin turns the left wheels back and the right ones forward (counter-clockwise).
  m.switch_mode(MotionMode::kSpin);
  MotionCommand spin;
  spin.yaw_rate = 0.5;
  m.drive(spin, 2s);
  const auto after = m.last<OdometerFeedback>(protocol::kRearOdometerId);
  EXPECT_LT(*after.left_distance, *rear.left_distance - 0.1);
  EXPECT_GT(*after.right_distance, *rear.right_distance + 0.1);
}

TEST(VirtualChassisMiniV3, ParksAsMode3AndHasNoSideSlip) {
  Mini m;
  m.handshake();
  m.switch_mode(MotionMode::kPark);
  EXPECT_EQ(m.last<MotionModeFeedback>(protocol::kMotionModeFeedbackId).mode_raw, 3);
  MotionCommand c;
  c.linear_speed = 0.5;
  m.drive(c, 500ms);
  EXPECT_EQ(m.chassis.snapshot().twist.vx, 0.0) << "parked";
  // Mode 4 is side slip elsewhere; here it is no mode: ignored.
  CanFrame four;
  four.id = protocol::kMotionModeCommandId;
  four.dlc = 1;
  four.data[0] = 4;
  m.chassis.on_frame(four, m.t);
  m.advance(1500ms);
  EXPECT_EQ(m.chassis.snapshot().motion_mode, MotionMode::kPark);
}

TEST(VirtualChassisMiniV3, ItsLimitsBound0x111) {
  Mini m;
  m.handshake();
  MotionCommand fast;
  fast.linear_speed = 2.5;  // beyond the MINI 3.0's 2.0 m/s
  m.drive(fast, 4s);
  EXPECT_NEAR(m.chassis.snapshot().twist.vx, 2.0, 1e-9);
  // Beyond 20 deg of steering: 0.7 m/s.
  MotionCommand turning;
  turning.linear_speed = 1.5;
  turning.steering_angle = interpretation::manual_from_rep103_command_steering(0.5);  // inner
  m.drive(turning, 4s);
  EXPECT_NEAR(m.chassis.snapshot().target.speed, 0.7, 1e-9);
  // Spin: 3.259 rad/s at most.
  m.switch_mode(MotionMode::kSpin);
  MotionCommand spin;
  spin.yaw_rate = 5.0;
  m.drive(spin, 4s);
  EXPECT_NEAR(m.chassis.snapshot().twist.wz, 3.259, 0.001);
}

TEST(VirtualChassisMiniV3, LightsOnOrOffOnlyAndNoUltrasonicAnswer) {
  Mini m;
  m.handshake();
  LightCommand off;
  off.enable = true;
  off.front_mode = protocol::LightMode::kOff;
  m.send(off);
  m.advance(40ms);
  const auto state = m.last<LightState>(protocol::kLightStateId);
  EXPECT_TRUE(state.enable);
  EXPECT_EQ(state.front_mode, protocol::LightMode::kOff);
  EXPECT_EQ(m.frames(protocol::kLightStateId).back().data[3], 0) << "no rear light";
  // 0x451 is not a MINI 3.0 frame: rejected, never answered.
  const auto rejected = m.chassis.counters().frames_rejected;
  m.chassis.on_frame(*encode(UltrasonicSettingCommand{true}), m.t);
  m.advance(40ms);
  EXPECT_EQ(m.chassis.counters().frames_rejected, rejected + 1);
  EXPECT_TRUE(m.frames(protocol::kUltrasonicSettingFeedbackId).empty());
}

}  // namespace
}  // namespace ranger::sim
