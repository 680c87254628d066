// The virtual chassis under every protocol profile and variant (sim_bus_source.hpp): what each one
// sends and how it obeys (mini_v3, the RANGER MINI 3.0, at the end), over the test-support
// FakeBus with injected time (no sleeping). The driver against each variant, end to end, is
// tests/variants/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
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

constexpr double kDeg = M_PI / 180.0;

VirtualChassisConfig variant(const std::string& name) {
  auto c = apply_variant(name, VirtualChassisConfig{});
  EXPECT_TRUE(c.ok()) << (c ? "" : c.error().message);
  return c ? *c : VirtualChassisConfig{};
}

// A chassis of one variant and a host speaking the same profile.
struct Host {
  explicit Host(VirtualChassisConfig c)
      : config(c), profile(c.profile), chassis(bus, config, Timestamp{0}) {
    chassis.step(t);
  }

  VirtualChassisConfig config;
  ProtocolProfile profile;  // the host's: the chassis's unless a test changes it
  Timestamp t{0};
  test::FakeBus bus;
  VirtualChassis chassis;

  void send(const Message& m) {
    auto f = encode(m, profile);
    ASSERT_TRUE(f.ok()) << f.error().message;
    chassis.on_frame(*f, t);
  }
  void send_frame(const CanFrame& f) { chassis.on_frame(f, t); }
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
    auto m = decode(all.back(), profile);
    EXPECT_TRUE(m.ok()) << (m ? "" : m.error().message);
    return m ? std::get<T>(*m) : T{};
  }
};

MotionCommand ackermann(double v, double rep103_steering) {
  MotionCommand c;
  c.linear_speed = v;
  c.steering_angle = interpretation::manual_from_rep103_command_steering(rep103_steering);
  return c;
}

// ---- the table --------------------------------------------------------------------------------

TEST(ChassisVariants, TableNamesEveryVariantWithADescriptionAndTheDriverOptions) {
  const std::vector<std::string> expected = {
      "manual",        "agx_v2",      "padded",     "spin_cw", "steer_left_positive",
      "speed221_body", "inner_angle", "mini_v1",    "mini_v3", "mini_v3_manual",
      "field_switch",  "mode_left",   "undecidable"};
  EXPECT_EQ(variant_names(), expected);
  for (const VariantInfo& v : variants()) {
    SCOPED_TRACE(v.name);
    EXPECT_FALSE(v.description.empty());
    EXPECT_NE(variants_help().find("  " + v.name + " "), std::string::npos);
    EXPECT_TRUE(variant(v.name).profile.validate().ok());
  }
}

TEST(ChassisVariants, UnknownVariantListsTheValidOnes) {
  auto c = apply_variant("ranger_xl", {});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().code, Errc::kInvalidArgument);
  EXPECT_EQ(c.error().message,
            "unknown virtual chassis variant 'ranger_xl' (valid: manual, agx_v2, padded, spin_cw, "
            "steer_left_positive, speed221_body, inner_angle, mini_v1, mini_v3, mini_v3_manual, "
            "field_switch, mode_left, undecidable)");
}

TEST(ChassisVariants, EachSettingVariantChangesOneReadingOfTheManual) {
  const ProtocolProfile manual = manual_profile();
  EXPECT_EQ(variant("manual").profile, manual);
  EXPECT_EQ(describe(variant("padded").profile), "manual with tx_dlc=8");
  EXPECT_EQ(describe(variant("spin_cw").profile), "manual with spin_sign=cw");
  EXPECT_EQ(describe(variant("steer_left_positive").profile),
            "manual with steering_sign_111=left_positive,steering_sign_221=left_positive,"
            "steering_sign_271=left_positive");
  EXPECT_EQ(describe(variant("speed221_body").profile), "manual with feedback_speed=body_centre");
  EXPECT_EQ(describe(variant("inner_angle").profile), "manual with steering_reference=inner_front");
  EXPECT_EQ(variant("agx_v2").profile, *protocol_preset("agx_v2"));
  EXPECT_TRUE(variant("agx_v2").vendor_frames);
  const auto v1 = *model_preset("ranger_mini_v1");
  EXPECT_EQ(variant("mini_v1").profile, v1.profile);
  EXPECT_DOUBLE_EQ(variant("mini_v1").geometry.wheelbase, 0.36);
  EXPECT_DOUBLE_EQ(variant("mini_v1").limits.max_oblique_angle, v1.limits.max_oblique_steering);
  EXPECT_EQ(describe(variant("undecidable").profile), "agx_v2 with mode_numbering=manual,tx_dlc=0");
}

TEST(ChassisVariants, AVariantAppliesOverAModel) {
  auto c = apply_variant("padded", chassis_for_model(*model_preset("ranger_mini_v2")));
  ASSERT_TRUE(c.ok());
  EXPECT_DOUBLE_EQ(c->geometry.track, 0.364);
  EXPECT_EQ(describe(c->profile), "agx_v2 with spin_field=wheel_speed,bms_voltage_scale=0.01");
}

// ---- the wire ---------------------------------------------------------------------------------

TEST(ChassisVariants, PaddedAndAgxChassisSendEveryFrameWithEightBytes) {
  for (const char* name : {"padded", "agx_v2"}) {
    SCOPED_TRACE(name);
    Host h(variant(name));
    h.handshake();
    h.advance(1s);
    std::set<std::uint32_t> ids;
    for (const auto& f : h.bus.sent) {
      EXPECT_EQ(f.dlc, 8) << std::hex << f.id;
      ids.insert(f.id);
      EXPECT_TRUE(decode(f, h.profile).ok()) << std::hex << f.id;
      // A manual driver reads the padded manual chassis as it is.
      if (std::string(name) == "padded") EXPECT_TRUE(decode(f, manual_profile()).ok());
    }
    EXPECT_TRUE(ids.count(protocol::kMotionModeFeedbackId));
    EXPECT_TRUE(ids.count(protocol::kBmsBaseId + 1));  // the 4-byte alarm frame, padded
  }
  Host manual(variant("manual"));
  manual.advance(100ms);
  EXPECT_EQ(manual.frames(protocol::kMotionModeFeedbackId).back().dlc, 2);
}

TEST(ChassisVariants, AgxChassisSendsTheVendorFramesAndACounter) {
  Host h(variant("agx_v2"));
  h.advance(200ms);
  // 0x211 byte 7 counts up by one per frame; the error word is bytes 4-5.
  const auto status = h.frames(protocol::kSystemStatusId);
  ASSERT_GE(status.size(), 10u);
  for (std::size_t i = 1; i < status.size(); ++i)
    EXPECT_EQ(static_cast<std::uint8_t>(status[i].data[7] - status[i - 1].data[7]), 1);
  EXPECT_EQ(h.frames(protocol::kLightStateId).size(), status.size());
  EXPECT_EQ(h.frames(protocol::kRemoteControlStateId).size(), status.size());
  const auto rc = h.last<RemoteControlState>(protocol::kRemoteControlStateId);
  EXPECT_EQ(rc.swb, protocol::RemoteSwitch::kUp);
  // 0x121 sets what 0x231 reports.
  h.handshake();
  LightCommand light;
  light.enable = true;
  light.front_mode = protocol::LightMode::kBreathing;
  h.send(light);
  h.advance(40ms);
  const auto state = h.last<LightState>(protocol::kLightStateId);
  EXPECT_TRUE(state.enable);
  EXPECT_EQ(state.front_mode, protocol::LightMode::kBreathing);
  // BMS voltage in 0.1 V: a 48 V pack is about 480 on the wire.
  const auto bms = h.frames(protocol::kBmsBaseId);
  ASSERT_FALSE(bms.empty());
  const int raw = bms.back().data[2] << 8 | bms.back().data[3];
  EXPECT_GT(raw, 450);
  EXPECT_LT(raw, 510);
  // A manual chassis sends none of these.
  Host manual(variant("manual"));
  manual.advance(200ms);
  for (std::uint32_t id : {protocol::kLightStateId, protocol::kRemoteControlStateId})
    EXPECT_TRUE(manual.frames(id).empty());
}

TEST(ChassisVariants, AgxChassisAnswersAVersionRequestInAnyControlMode) {
  VirtualChassisConfig c = variant("agx_v2");
  c.version = "RANGER sim 5.7.3";
  Host h(c);
  h.send(VersionRequest{});  // standby
  const auto answers = h.frames(protocol::kVersionId);
  ASSERT_EQ(answers.size(), 2u);
  std::string text;
  for (const auto& f : answers) {
    auto m = decode(f, h.profile);
    ASSERT_TRUE(m.ok());
    text += std::string(std::get<VersionResponse>(*m).view());
  }
  EXPECT_EQ(text, "RANGER sim 5.7.3");
  // The manual's chassis does not know the request.
  Host manual(variant("manual"));
  manual.send_frame(*encode(VersionRequest{}, manual.profile));
  EXPECT_TRUE(manual.frames(protocol::kVersionId).empty());
  EXPECT_EQ(manual.chassis.counters().frames_rejected, 1u);
}

TEST(ChassisVariants, ErrorBitsFollowTheLayout) {
  Host h(variant("agx_v2"));
  h.handshake();
  h.drive(ackermann(0.3, 0.0), 200ms);
  h.advance(600ms);  // no 0x111: host communication lost
  const auto st = h.last<SystemStatus>(protocol::kSystemStatusId);
  EXPECT_EQ(st.error_bits, protocol::fault_bit(protocol::Fault::kHostCommunicationLost,
                                               ErrorWordLayout::kAgxV2_16));
  EXPECT_EQ(st.error_bits, 0x0200u);
  // A fault the layout has (steering encoder) stops the chassis; one it lacks cannot be set.
  EXPECT_TRUE(h.chassis.set_fault(protocol::Fault::kSteeringEncoder, true));
  EXPECT_FALSE(h.chassis.set_fault(protocol::Fault::kOverCurrent, true));
  h.send(ackermann(0.3, 0.0));  // the link is back; the fault remains
  EXPECT_NE(h.chassis.snapshot().motion_refused_reason.find("steering_encoder"), std::string::npos);
  EXPECT_TRUE(h.chassis.clear_errors(0x00));  // not critical enough
  EXPECT_TRUE(h.chassis.snapshot().error_bits & 0x0080u);
}

TEST(ChassisVariants, ModeNumberingOfTheProfile) {
  Host h(variant("mini_v1"));
  h.handshake();
  h.send(MotionModeCommand{MotionMode::kSideSlip});  // wire 3 on a MINI V1
  EXPECT_EQ(h.frames(protocol::kMotionModeFeedbackId).back().data[0], 0);
  h.advance(1500ms);
  EXPECT_EQ(h.chassis.snapshot().motion_mode, MotionMode::kSideSlip);
  EXPECT_EQ(h.frames(protocol::kMotionModeFeedbackId).back().data[0], 3);
  h.switch_mode(MotionMode::kSpin);
  h.advance(40ms);
  EXPECT_EQ(h.frames(protocol::kMotionModeFeedbackId).back().data[0], 2);
  // A value the numbering lacks is ignored and counted.
  Host m(variant("manual"));
  m.handshake();
  const auto ignored = m.chassis.counters().frames_ignored;
  CanFrame f;
  f.id = protocol::kMotionModeCommandId;
  f.dlc = 1;
  f.data[0] = 4;
  m.send_frame(f);
  EXPECT_EQ(m.chassis.counters().frames_ignored, ignored + 1);
}

// ---- the physics of the readings --------------------------------------------------------------

TEST(ChassisVariants, SpinFieldDecidesWhichBytesTurnTheChassis) {
  for (const char* name : {"manual", "agx_v2"}) {
    SCOPED_TRACE(name);
    const bool yaw_field = std::string(name) == "agx_v2";
    Host h(variant(name));
    h.handshake();
    h.switch_mode(MotionMode::kSpin);
    MotionCommand other;  // the field this chassis does not read
    if (yaw_field) {
      other.spin_speed = 0.5;
    } else {
      other.yaw_rate = 0.8;
    }
    h.drive(other, 2s);
    const auto idle = h.chassis.snapshot();
    EXPECT_EQ(idle.twist.wz, 0.0) << "the wheels stand in the spin position, nothing moves";
    EXPECT_EQ(idle.yaw_travelled, 0.0);
    MotionCommand right;
    if (yaw_field) {
      right.yaw_rate = 0.8;
    } else {
      right.spin_speed = 0.8 * std::hypot(0.445, 0.28);
    }
    h.drive(right, 3s);
    EXPECT_NEAR(h.chassis.snapshot().twist.wz, 0.8, 2e-3);  // 1 mm/s or 1 mrad/s on the wire
    // 0x221 carries it back in the same field.
    const auto fb = h.last<MotionFeedback>(protocol::kMotionFeedbackId);
    if (yaw_field) {
      EXPECT_NEAR(fb.yaw_rate, 0.8, 1e-3);
      EXPECT_EQ(fb.speed, 0.0);
    } else {
      EXPECT_NEAR(fb.speed, 0.8 * std::hypot(0.445, 0.28), 1e-3);
      EXPECT_EQ(fb.yaw_rate, 0.0);
    }
  }
}

TEST(ChassisVariants, SpinSignReversesTheTurnAndTheReport) {
  Host h(variant("spin_cw"));
  h.handshake();
  h.switch_mode(MotionMode::kSpin);
  MotionCommand cmd;
  cmd.spin_speed = 0.3;  // positive on the wire: clockwise on this chassis
  h.drive(cmd, 2s);
  EXPECT_LT(h.chassis.snapshot().twist.wz, 0.0);
  EXPECT_NEAR(h.last<MotionFeedback>(protocol::kMotionFeedbackId).speed, 0.3, 1e-3);
}

TEST(ChassisVariants, SteeringSignOfTheWire) {
  Host h(variant("steer_left_positive"));
  h.profile = manual_profile();  // a host that does not know: its "right" turns left
  h.handshake();
  h.drive(ackermann(0.5, -10 * kDeg), 3s);  // REP-103 -10 deg = right for the manual
  EXPECT_GT(h.chassis.snapshot().twist.wz, 0.0) << "the chassis turned left";
  // Its 0x221 and 0x271 carry left as positive.
  const auto raw221 = h.frames(protocol::kMotionFeedbackId).back();
  EXPECT_GT(static_cast<std::int16_t>(raw221.data[6] << 8 | raw221.data[7]), 0);
}

TEST(ChassisVariants, InnerAngleChassisSteersItsInnerWheelToTheCommand) {
  for (const char* name : {"manual", "inner_angle"}) {
    SCOPED_TRACE(name);
    Host h(variant(name));
    h.handshake();
    h.drive(ackermann(0.5, 20 * kDeg), 3s);  // left turn: the inner wheel is the left one
    const auto s = h.chassis.snapshot();
    const double inner = s.wheels[kLeftFront].angle;
    const double outer = s.wheels[kRightFront].angle;
    if (std::string(name) == "inner_angle") {
      EXPECT_NEAR(inner, 20 * kDeg, 1e-9);
    } else {
      EXPECT_NEAR((inner + outer) / 2, 20 * kDeg, 1e-9);
    }
    // 0x221 reports the same reading back.
    const auto fb = h.last<MotionFeedback>(protocol::kMotionFeedbackId);
    EXPECT_NEAR(interpretation::rep103_from_manual_steering(fb.steering_angle), 20 * kDeg, 1e-3);
  }
}

// The manual's 0x221 speed is the wheels' mean; the vendor's revision (and the variant that
// reads the manual's frames so) reports the body centre's, as it reads 0x111's.
TEST(ChassisVariants, Speed221BodyAndAgxV2ReportTheBodyCentre) {
  for (const char* name : {"manual", "speed221_body", "agx_v2"}) {
    SCOPED_TRACE(name);
    Host h(variant(name));
    h.handshake();
    h.drive(ackermann(0.5, 30 * kDeg), 3s);
    const auto s = h.chassis.snapshot();
    const auto fb = h.last<MotionFeedback>(protocol::kMotionFeedbackId);
    double mean_wheel = 0;
    for (const auto& w : s.wheels)
      mean_wheel += std::abs(w.speed) / 4;
    if (std::string(name) != "manual") {
      EXPECT_NEAR(fb.speed, s.twist.vx, 1e-3);
    } else {
      EXPECT_NEAR(fb.speed, mean_wheel, 1e-3);
    }
    EXPECT_GT(mean_wheel, s.twist.vx * 1.05) << "the readings differ at 30 deg";
  }
}

TEST(ChassisVariants, MiniV1SteersInCentidegreesRightPositiveAndSpinsOnANegatedWheelSpeed) {
  Host h(variant("mini_v1"));
  h.handshake();
  h.drive(ackermann(0.3, -10 * kDeg), 2s);  // a right turn, REP-103
  auto f = h.frames(protocol::kMotionFeedbackId).back();
  EXPECT_EQ(f.dlc, 8);
  // The inner (right) wheel at 10 deg: +1000 in 0.01 deg, right positive.
  EXPECT_NEAR(static_cast<std::int16_t>(f.data[6] << 8 | f.data[7]), 1000, 1);
  EXPECT_LT(h.chassis.snapshot().twist.wz, 0.0);
  h.switch_mode(MotionMode::kSpin);
  MotionCommand cmd;
  cmd.spin_speed = -0.05;  // negated: counter-clockwise
  h.drive(cmd, 2s);
  EXPECT_NEAR(h.chassis.snapshot().twist.wz, 0.05 / std::hypot(0.18, 0.18), 1e-9);
  // 0x271 in spin position: +-45 deg, 4500 in 0.01 deg.
  f = h.frames(protocol::kSteeringAnglesId).back();
  EXPECT_EQ(std::abs(static_cast<std::int16_t>(f.data[0] << 8 | f.data[1])), 4500);
}

// ---- undecidable ------------------------------------------------------------------------------

TEST(ChassisVariants, UndecidableSendsTheManualsIdsAndLengthsWithAgxValues) {
  Host h(variant("undecidable"));
  h.advance(1s);
  const auto manual_ids = protocol::manual_ids();
  std::set<std::uint32_t> seen;
  for (const auto& f : h.bus.sent) {
    seen.insert(f.id);
    EXPECT_NE(std::find(manual_ids.begin(), manual_ids.end(), f.id), manual_ids.end())
        << "an ID the manual lacks: 0x" << std::hex << f.id;
    EXPECT_EQ(f.dlc, protocol::layout_dlc(f.id)) << std::hex << f.id;
  }
  EXPECT_EQ(seen.count(protocol::kSteeringAnglesId), 0u) << "no 0x271";
  EXPECT_EQ(seen.count(protocol::kMotionFeedbackId), 1u);
  // ... but 0x211 byte 7 counts (a changing fault set under the manual's 32-bit word).
  const auto status = h.frames(protocol::kSystemStatusId);
  EXPECT_NE(status.front().data[7], status.back().data[7]);
  // It does not answer a version request.
  h.send_frame(*encode(VersionRequest{}, *protocol_preset("agx_v2")));
  EXPECT_TRUE(h.frames(protocol::kVersionId).empty());
}

TEST(ChassisVariants, UndecidableHidesItsSteeringUnitAtRest) {
  Host h(variant("undecidable"));
  h.handshake();
  h.advance(200ms);
  h.switch_mode(MotionMode::kSpin);  // the spin position would tell the unit through 0x221
  h.advance(200ms);
  // Every frame it sent at rest decodes to the same thing in either steering unit and sign.
  ProtocolProfile a = *protocol_preset("agx_v2");
  ProtocolProfile b = a;
  ASSERT_TRUE(set_setting(b, "steering_unit_221", "centideg").ok());
  ASSERT_TRUE(set_setting(b, "steering_sign_221", "right_positive").ok());
  ASSERT_TRUE(set_setting(b, "steering_unit_271", "centideg").ok());
  for (const auto& f : h.bus.sent) {
    if (f.id != protocol::kMotionFeedbackId) continue;
    auto ma = decode(f, a);
    auto mb = decode(f, b);
    ASSERT_TRUE(ma.ok() && mb.ok());
    EXPECT_EQ(std::get<MotionFeedback>(*ma).steering_angle, 0.0);
    EXPECT_EQ(std::get<MotionFeedback>(*mb).steering_angle, 0.0);
  }
  EXPECT_EQ(h.chassis.snapshot().motion_mode, MotionMode::kSpin);
}

// ---- mini_v3: the RANGER MINI 3.0 as its manual has it (PROTOCOL_MINI_V3.md) -----------------
// The frames it sends and their lengths, the 32-bit fault word without counter, drive modes
// (0x423, 0x291 byte 2), the front and rear odometers in mm, park, lights on/off, its limits.

TEST(ChassisVariantMiniV3, IsTheModelsChassisSpeakingItsManual) {
  const Host m(variant("mini_v3"));
  const ModelPreset model = *model_preset("ranger_mini_v3");
  EXPECT_EQ(m.config.profile, *protocol_preset("mini_v3"));
  EXPECT_EQ(m.config.geometry.wheelbase, model.geometry.wheelbase);
  EXPECT_EQ(m.config.limits.max_linear_speed, 2.0);
  EXPECT_EQ(m.config.limits.max_speed_at_large_steering, 1.0);  // the field's reading
  EXPECT_TRUE(m.config.vendor_frames);
  EXPECT_TRUE(m.config.odometer_frames);
}

TEST(ChassisVariantMiniV3, SendsItsManualsFramesWithTheirLengthsOnly) {
  Host m(variant("mini_v3"));
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

TEST(ChassisVariantMiniV3, FaultsByMeaningInItsFaultWord) {
  Host m(variant("mini_v3"));
  m.handshake();
  EXPECT_TRUE(m.chassis.set_fault(protocol::Fault::kOverCurrent, true));
  EXPECT_TRUE(m.chassis.set_fault(protocol::Fault::kBatteryOverVoltage, true));
  EXPECT_FALSE(m.chassis.set_fault(protocol::Fault::kSafetyEdge, true)) << "not a MINI 3.0 fault";
  m.chassis.set_emergency_stop(true);
  m.advance(40ms);
  const auto s = m.last<SystemStatus>(protocol::kSystemStatusId);
  // Body status 2 (abnormal) with the fault word's e-stop bit, as a real one reports it.
  EXPECT_EQ(s.vehicle_status, protocol::VehicleStatus::kAbnormal);
  EXPECT_EQ(protocol::error_bit_names(s.error_bits, ErrorWordLayout::kMini32),
            (std::vector<std::string>{"battery_over_voltage", "emergency_stop", "over_current"}));
  // 0x441 0x0F clears the over-current, 0x00 the rest once the e-stop is released.
  m.chassis.set_emergency_stop(false);
  m.send(ErrorClearCommand{0x0F});
  m.send(ErrorClearCommand{0x00});
  m.advance(40ms);
  EXPECT_EQ(m.last<SystemStatus>(protocol::kSystemStatusId).error_bits, 0u);
}

TEST(ChassisVariantMiniV3, DriveModesSetBy0x423AndReportedIn0x291) {
  Host m(variant("mini_v3"));
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

TEST(ChassisVariantMiniV3, FrontAndRearOdometersFollowTheWheels) {
  Host m(variant("mini_v3"));
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

TEST(ChassisVariantMiniV3, ParksAsMode3AndHasNoSideSlip) {
  Host m(variant("mini_v3"));
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

TEST(ChassisVariantMiniV3, ItsLimitsBound0x111) {
  Host m(variant("mini_v3"));
  m.handshake();
  MotionCommand fast;
  fast.linear_speed = 2.5;  // beyond the MINI 3.0's 2.0 m/s
  m.drive(fast, 4s);
  EXPECT_NEAR(m.chassis.snapshot().twist.vx, 2.0, 1e-9);
  // Beyond 20 deg of steering: 1.0 m/s (the field's reading of its manual).
  MotionCommand turning;
  turning.linear_speed = 1.5;
  turning.steering_angle = interpretation::manual_from_rep103_command_steering(0.5);  // inner
  m.drive(turning, 4s);
  EXPECT_NEAR(m.chassis.snapshot().target.speed, 1.0, 1e-9);
  // Spin: 3.259 rad/s at most.
  m.switch_mode(MotionMode::kSpin);
  MotionCommand spin;
  spin.yaw_rate = 5.0;
  m.drive(spin, 4s);
  EXPECT_NEAR(m.chassis.snapshot().twist.wz, 3.259, 0.001);
}

TEST(ChassisVariantMiniV3, LightsOnOrOffOnlyAndNoUltrasonicAnswer) {
  Host m(variant("mini_v3"));
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
