// The RANGER MINI 3.0's reading (`mini_v3`, shared/reference/PROTOCOL_MINI_V3.md) on the wire:
// every frame of its table decoded to the transcription's values and units, its own frames
// (0x423 drive mode, 0x312 rear odometer, 0x291 of 3 bytes, 0x362 of 4) encoded byte-exact, its
// 32-bit fault word by meaning, and what it lacks refused by name (side slip, breathing lights,
// a rear light, a brightness; 0x423 where the frame layout has none).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

namespace proto = protocol;
using Names = std::vector<std::string>;

const ProtocolProfile& mini() {
  static const ProtocolProfile kMini = *protocol_preset("mini_v3");
  return kMini;
}
const ProtocolProfile& agx() {
  static const ProtocolProfile kAgx = *protocol_preset("agx_v2");
  return kAgx;
}

ProtocolProfile with_tx_dlc_0(ProtocolProfile p) {
  p.tx_dlc = 0;
  return p;
}

CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size() && i < 8; ++i)
    f.data[i] = bytes[i];
  return f;
}

template <typename T>
T decode_as(const CanFrame& f, const ProtocolProfile& p = mini()) {
  auto r = decode(f, p);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  if (!r.ok() || !std::holds_alternative<T>(*r)) {
    ADD_FAILURE() << "frame 0x" << std::hex << f.id << " did not decode as expected";
    return T{};
  }
  return std::get<T>(*r);
}

CanFrame encode_ok(const Message& m, const ProtocolProfile& p = mini()) {
  auto r = encode(m, p);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : CanFrame{};
}

std::string refusal(const Message& m, const ProtocolProfile& p = mini()) {
  auto r = encode(m, p);
  EXPECT_FALSE(r.ok());
  if (r.ok()) return {};
  EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
  return r.error().message;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ---- Host -> chassis ------------------------------------------------------------------------

TEST(MiniV3Wire, MotionCommandLinearSpinAngularVelocityAndInnerAngleInRad) {
  // 1.5 m/s, spin 0.5 rad/s counter-clockwise, bytes 4-5 zero, inner angle 0.3 rad to the left.
  const CanFrame f = frame(0x111, {0x05, 0xDC, 0x01, 0xF4, 0x00, 0x00, 0x01, 0x2C});
  const auto m = decode_as<MotionCommand>(f);
  EXPECT_EQ(m.linear_speed, 1.5);
  EXPECT_EQ(m.yaw_rate, 0.5);
  EXPECT_EQ(m.spin_speed, 0.0);
  EXPECT_DOUBLE_EQ(m.steering_angle, -0.3);  // the codec's convention: positive = right
  EXPECT_EQ(encode_ok(m), f);
}

TEST(MiniV3Wire, MotionModesParkIsThreeAndThereIsNoSideSlip) {
  EXPECT_EQ(decode_as<MotionModeCommand>(frame(0x141, {0x03})).mode, proto::MotionMode::kPark);
  const auto four = decode_as<MotionModeCommand>(frame(0x141, {0x04}));
  EXPECT_FALSE(four.mode_known);
  const CanFrame park = encode_ok(MotionModeCommand{proto::MotionMode::kPark});
  EXPECT_EQ(park, frame(0x141, {0x03}));  // DLC 1, as its manual gives it
  const std::string side_slip = refusal(MotionModeCommand{proto::MotionMode::kSideSlip});
  EXPECT_TRUE(contains(side_slip, "3 park under mode numbering mini_v3")) << side_slip;
}

TEST(MiniV3Wire, DriveModeCommand0x423) {
  EXPECT_EQ(encode_ok(DriveModeCommand{proto::DriveMode::kVoltage}), frame(0x423, {0x01}));
  EXPECT_EQ(encode_ok(DriveModeCommand{proto::DriveMode::kCurrent}), frame(0x423, {0x00}));
  const auto v = decode_as<DriveModeCommand>(frame(0x423, {0x01}));
  EXPECT_EQ(v.mode, proto::DriveMode::kVoltage);
  EXPECT_TRUE(v.mode_known);
  EXPECT_FALSE(decode_as<DriveModeCommand>(frame(0x423, {0x07})).mode_known);
  // A chassis without drive modes is never sent one; the frame still decodes (liberal).
  for (const char* revision : {"manual", "agx_v2"}) {
    const std::string why =
        refusal(DriveModeCommand{proto::DriveMode::kVoltage}, *protocol_preset(revision));
    EXPECT_TRUE(contains(why, "0x423 is not a frame of frame layout " + std::string(revision)))
        << why;
    EXPECT_TRUE(decode(frame(0x423, {0x01}), *protocol_preset(revision)).ok());
  }
  EXPECT_EQ(proto::frame_name(0x423), "drive_mode_command");
}

TEST(MiniV3Wire, ControlModeAndClearCodesAsItsManualListsThem) {
  EXPECT_EQ(encode_ok(ControlModeCommand{proto::ControlMode::kCan}), frame(0x421, {0x01}));
  for (int code = 0x00; code <= 0x10; ++code) {
    const auto c = static_cast<std::uint8_t>(code);
    EXPECT_EQ(encode_ok(ErrorClearCommand{c}), frame(0x441, {c}));
    EXPECT_NE(proto::error_clear_description(c).rfind("undefined", 0), 0u) << code;
  }
  EXPECT_EQ(proto::error_clear_description(0x0B), "steering calibration fault of motor 5");
  EXPECT_FALSE(encode(ErrorClearCommand{0x11}, mini()).ok());
}

TEST(MiniV3Wire, LightsOnOffOnlyAndWhatTheyLackRefusedByName) {
  LightCommand on;
  on.enable = true;
  on.front_mode = proto::LightMode::kOn;
  EXPECT_EQ(encode_ok(on), frame(0x121, {0x01, 0x01, 0, 0, 0, 0, 0, 0}));
  LightCommand off = on;
  off.front_mode = proto::LightMode::kOff;
  EXPECT_EQ(encode_ok(off), frame(0x121, {0x01, 0x00, 0, 0, 0, 0, 0, 0}));
  LightCommand breathing = on;
  breathing.front_mode = proto::LightMode::kBreathing;
  EXPECT_TRUE(contains(refusal(breathing), "no breathing")) << refusal(breathing);
  LightCommand rear = on;
  rear.rear_mode = proto::LightMode::kOn;
  EXPECT_TRUE(contains(refusal(rear), "no rear light")) << refusal(rear);
  LightCommand custom = on;
  custom.front_custom = 40;
  EXPECT_TRUE(contains(refusal(custom), "no brightness")) << refusal(custom);
  // The vendor's lights stay what they were under agx_v2.
  EXPECT_TRUE(encode(breathing, agx()).ok());
  EXPECT_TRUE(encode(rear, agx()).ok());
  // 0x231: byte 0 enable, 1 on/off, 2-6 reserved, 7 counter.
  const auto state = decode_as<LightState>(frame(0x231, {0x01, 0x01, 9, 9, 9, 9, 9, 0x2A}));
  EXPECT_TRUE(state.enable);
  EXPECT_EQ(state.front_mode, proto::LightMode::kOn);
  EXPECT_EQ(state.rear_mode, proto::LightMode::kOff);
  EXPECT_EQ(state.front_custom, 0);
  EXPECT_EQ(state.counter, 0x2A);
}

// ---- Chassis -> host ------------------------------------------------------------------------

TEST(MiniV3Wire, SystemStatusA32BitFaultWordWithoutCounterByMeaning) {
  // Body 0, CAN mode, 48.0 V; faults: under-voltage (0), over-voltage (1), e-stop (7),
  // over-current (15), steering zero calibration of wheel 1 (16), calibration timeout (20).
  const CanFrame f = frame(0x211, {0x00, 0x01, 0x01, 0xE0, 0x00, 0x11, 0x80, 0x83});
  const auto s = decode_as<SystemStatus>(f);
  EXPECT_EQ(s.control_mode, proto::ControlMode::kCan);
  EXPECT_DOUBLE_EQ(s.battery_voltage, 48.0);
  EXPECT_EQ(s.error_bits, 0x00118083u);
  EXPECT_FALSE(s.counter.has_value()) << "no counter in byte 7: it holds faults";
  EXPECT_EQ(
      proto::error_bit_names(s.error_bits, ErrorWordLayout::kMini32),
      (Names{"battery_under_voltage", "battery_over_voltage", "emergency_stop", "over_current",
             "steering_calibration_fault_front_right", "steering_calibration_timeout"}));
  EXPECT_EQ(encode_ok(s), f);
}

TEST(MiniV3Wire, EveryFaultBitOfTheMini30ByMeaning) {
  using F = proto::Fault;
  const auto layout = ErrorWordLayout::kMini32;
  struct Bit {
    int bit;
    F fault;
    int motor;
  };
  const Bit bits[] = {
      {0, F::kBatteryUnderVoltage, 0},  {1, F::kBatteryOverVoltage, 0},
      {2, F::kRemoteSignalLost, 0},     {3, F::kMotorCommunication, 1},
      {4, F::kMotorCommunication, 2},   {5, F::kMotorCommunication, 3},
      {6, F::kMotorCommunication, 4},   {7, F::kEmergencyStop, 0},
      {8, F::kDriverStatusError, 0},    {10, F::kMotorCommunication, 5},
      {11, F::kMotorCommunication, 6},  {12, F::kMotorCommunication, 7},
      {13, F::kMotorCommunication, 8},  {14, F::kOverTemperature, 0},
      {15, F::kOverCurrent, 0},         {16, F::kSteeringCalibration, 5},
      {17, F::kSteeringCalibration, 6}, {18, F::kSteeringCalibration, 7},
      {19, F::kSteeringCalibration, 8}, {20, F::kSteeringCalibrationTimeout, 0},
  };
  std::uint32_t defined = 0;
  for (const Bit& b : bits) {
    EXPECT_EQ(proto::fault_bit(b.fault, layout, b.motor), 1u << b.bit) << b.bit;
    defined |= 1u << b.bit;
  }
  // The others are reserved: named so, and no fault of the manual's or agx_v2's lands there
  // (host link lost, ultrasonic, safety edge, steering servo warnings, battery warning, encoder).
  for (int i = 0; i < 32; ++i) {
    if (defined & (1u << i)) continue;
    EXPECT_EQ(proto::error_bit_names(1u << i, layout), Names{"reserved_bit_" + std::to_string(i)});
  }
  // The same meaning carries the same name on every revision: over-current is bit 15 here and
  // byte 6 bit 7 of the manual's word (also 15), absent from agx16.
  EXPECT_EQ(proto::error_bit_names(proto::fault_bit(F::kOverCurrent, layout), layout),
            proto::error_bit_names(proto::fault_bit(F::kOverCurrent, ErrorWordLayout::kManual32),
                                   ErrorWordLayout::kManual32));
  // Critical: the faults the chassis does not drive with; over-voltage and the e-stop bit (0x441
  // code 0x00 clears them) are not.
  EXPECT_TRUE(proto::is_critical_error(1u << 15, layout));
  EXPECT_TRUE(proto::is_critical_error(1u << 16, layout));
  EXPECT_FALSE(proto::is_critical_error(1u << 1, layout));
  EXPECT_FALSE(proto::is_critical_error(1u << 7, layout));
  EXPECT_FALSE(proto::is_critical_error(1u << 2, layout));
}

TEST(MiniV3Wire, MotionFeedbackWheelsAndAngles) {
  // -0.2 m/s, spin 0.7 rad/s, lateral 0, inner angle 0.1 rad to the left.
  const auto m =
      decode_as<MotionFeedback>(frame(0x221, {0xFF, 0x38, 0x02, 0xBC, 0x00, 0x00, 0x00, 0x64}));
  EXPECT_EQ(m.speed, -0.2);
  EXPECT_EQ(m.yaw_rate, 0.7);
  EXPECT_EQ(m.lateral_speed, 0.0);
  EXPECT_DOUBLE_EQ(m.steering_angle, -0.1);
  // 0x271: four i16 x 0.001 rad (motors 5-8); 0x281: four i16 x 0.001 m/s (motors 1-4).
  const auto a = decode_as<SteeringAnglesFeedback>(
      frame(0x271, {0x03, 0xF1, 0xFC, 0x0F, 0x03, 0xF1, 0xFC, 0x0F}));
  EXPECT_DOUBLE_EQ(a.angles[0], -1.009);  // left positive on the wire
  EXPECT_DOUBLE_EQ(a.angles[1], 1.009);
  const auto w = decode_as<WheelSpeedsFeedback>(
      frame(0x281, {0x01, 0xF4, 0xFE, 0x0C, 0x00, 0x00, 0x00, 0x01}));
  EXPECT_EQ(w.speeds[0], 0.5);
  EXPECT_EQ(w.speeds[1], -0.5);
  EXPECT_EQ(w.speeds[3], 0.001);
}

TEST(MiniV3Wire, MotionModeFeedbackOfThreeBytesCarriesTheDriveMode) {
  const CanFrame f = frame(0x291, {0x03, 0x00, 0x01});
  EXPECT_EQ(proto::layout_dlc(0x291, FrameLayout::kMiniV3), 3);
  EXPECT_EQ(proto::layout_dlc(0x291, FrameLayout::kAgxV2), 2);
  const auto m = decode_as<MotionModeFeedback>(f);
  EXPECT_EQ(m.mode, proto::MotionMode::kPark);
  EXPECT_FALSE(m.switching);
  ASSERT_TRUE(m.drive_mode.has_value());
  EXPECT_EQ(proto::drive_mode_from_wire(*m.drive_mode), proto::DriveMode::kVoltage);
  EXPECT_EQ(encode_ok(m), f);
  // Shorter than the layout: refused; longer: its leading bytes, the rest ignored and counted.
  const auto short_one = decode(frame(0x291, {0x00, 0x00}), mini());
  ASSERT_FALSE(short_one.ok());
  EXPECT_EQ(short_one.error().code, Errc::kBadDlc);
  EXPECT_TRUE(contains(short_one.error().message, "expected 3 or more"));
  const CanFrame padded = frame(0x291, {0x02, 0x01, 0x00, 0, 0, 0, 0, 0});
  EXPECT_EQ(proto::extra_bytes(padded, FrameLayout::kMiniV3), 5);
  EXPECT_EQ(decode_as<MotionModeFeedback>(padded).drive_mode, std::uint8_t{0});
  // The vendor's reading has no drive mode: byte 2 is an extra byte there.
  EXPECT_FALSE(decode_as<MotionModeFeedback>(f, agx()).drive_mode.has_value());
  EXPECT_EQ(proto::extra_bytes(f, FrameLayout::kAgxV2), 1);
  // Encoded under agx_v2 the byte is dropped.
  MotionModeFeedback fb;
  fb.drive_mode = 1;
  EXPECT_EQ(encode_ok(fb, with_tx_dlc_0(agx())).dlc, 2);
}

TEST(MiniV3Wire, FrontAndRearOdometersInMillimetresDecodeInMetres) {
  // left 12345 mm, right -250 mm
  const CanFrame front = frame(0x311, {0x00, 0x00, 0x30, 0x39, 0xFF, 0xFF, 0xFF, 0x06});
  const auto f = decode_as<OdometerFeedback>(front);
  EXPECT_FALSE(f.rear);
  EXPECT_EQ(f.left_wheel, 12345);
  EXPECT_EQ(f.right_wheel, -250);
  EXPECT_EQ(f.left_distance, 12.345);
  EXPECT_EQ(f.right_distance, -0.25);
  EXPECT_EQ(encode_ok(f), front);
  CanFrame rear_frame = front;
  rear_frame.id = 0x312;
  const auto r = decode_as<OdometerFeedback>(rear_frame);
  EXPECT_TRUE(r.rear);
  EXPECT_EQ(r.left_distance, 12.345);
  EXPECT_EQ(encode_ok(r), rear_frame);
  EXPECT_EQ(proto::frame_name(0x312), "rear_odometer");
  // Metres win over the raw values when encoding under mm (saturated, never wrapped).
  OdometerFeedback m;
  m.rear = true;
  m.left_distance = 1.0;
  m.right_distance = 1e9;
  const CanFrame e = encode_ok(m);
  EXPECT_EQ(e, frame(0x312, {0x00, 0x00, 0x03, 0xE8, 0x7F, 0xFF, 0xFF, 0xFF}));
  m.left_distance = std::nan("");
  EXPECT_EQ(encode(m, mini()).error().code, Errc::kNotFinite);
  // agx_v2 does not state the unit: raw counts only.
  const auto raw = decode_as<OdometerFeedback>(front, agx());
  EXPECT_EQ(raw.left_wheel, 12345);
  EXPECT_FALSE(raw.left_distance.has_value());
}

TEST(MiniV3Wire, BmsPackDataAndItsAlarmFrameOfFourBytes) {
  // SOC 80 %, SOH 99 %, 48.5 V (0.01 V, the field's reading), -3.0 A, 26.5 degC.
  const auto b = decode_as<BmsData>(frame(0x361, {80, 99, 0x12, 0xF2, 0xFF, 0xE2, 0x01, 0x09}));
  EXPECT_EQ(b.soc, 80.0);
  EXPECT_EQ(b.soh, 99.0);
  EXPECT_DOUBLE_EQ(b.voltage, 48.5);
  EXPECT_EQ(b.current, -3.0);
  EXPECT_EQ(b.temperature, 26.5);
  EXPECT_EQ(proto::layout_dlc(0x362, FrameLayout::kMiniV3), 4);
  const CanFrame alarm_frame = frame(0x362, {0x04, 0x01, 0x08, 0x00});
  const auto a = decode_as<BmsAlarm>(alarm_frame);
  EXPECT_EQ(proto::bms_status_names(a.alarm1, a.alarm2),
            (Names{"under_voltage", "charge_over_current"}));
  EXPECT_EQ(proto::bms_status_names(a.warning1, a.warning2), Names{"high_temperature"});
  EXPECT_EQ(encode_ok(a), alarm_frame);
}

TEST(MiniV3Wire, TheFrameTableColumnOfTheMini30) {
  const auto ids = proto::ids_of(FrameLayout::kMiniV3);
  auto has = [&](std::uint32_t id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); };
  for (std::uint32_t id :
       {0x111u, 0x121u, 0x141u, 0x421u, 0x423u, 0x441u, 0x4A1u, 0x211u, 0x221u, 0x231u, 0x241u,
        0x251u, 0x258u, 0x261u, 0x268u, 0x271u, 0x281u, 0x291u, 0x311u, 0x312u, 0x361u, 0x362u}) {
    EXPECT_TRUE(has(id)) << std::hex << id;
  }
  // Not in its manual: the ultrasonic frames, battery slots 1-4.
  for (std::uint32_t id : {0x342u, 0x343u, 0x451u, 0x45Au, 0x363u, 0x36Au})
    EXPECT_FALSE(has(id)) << std::hex << id;
  // Every frame but 0x291 (3) and 0x362 (4) has DLC 8 among what the chassis sends.
  for (std::uint32_t id : ids) {
    const proto::FrameInfo* f = proto::find_frame(id);
    if (f->direction != proto::Direction::kFromChassis) continue;
    const int want = id == 0x291 ? 3 : id == 0x362 ? 4 : 8;
    EXPECT_EQ(f->length(FrameLayout::kMiniV3), want) << std::hex << id;
  }
}

}  // namespace
}  // namespace ranger
