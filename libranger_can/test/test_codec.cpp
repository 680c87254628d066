// The codec against the manual: sample frames byte-exact, every layout round-tripped over its
// representable range, saturation instead of wrapping, NaN/inf refused by field name, DLC and ID
// checks, and no byte past the DLC ever read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

namespace proto = protocol;

constexpr double kDeg = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size() && i < 8; ++i)
    f.data[i] = bytes[i];
  return f;
}

std::string hex(const CanFrame& f) {
  static const char* kHex = "0123456789ABCDEF";
  std::string s;
  for (int i = 0; i < f.dlc; ++i) {
    if (i) s += ' ';
    s += kHex[f.data[i] >> 4];
    s += kHex[f.data[i] & 15];
  }
  return s;
}

CanFrame encode_ok(const Message& m) {
  auto r = encode(m);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : CanFrame{};
}

template <typename T>
T decode_as(const CanFrame& f) {
  auto r = decode(f);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  if (!r.ok()) return T{};
  EXPECT_TRUE(std::holds_alternative<T>(*r)) << "frame 0x" << std::hex << f.id;
  return std::holds_alternative<T>(*r) ? std::get<T>(*r) : T{};
}

// ---- The manual's sample frames ------------------------------------------------------------

TEST(CodecManualSamples, Forward150MmPerSecond) {
  const CanFrame f = encode_ok(MotionCommand{0.150, 0.0, 0.0});
  EXPECT_EQ(f.id, 0x111u);
  EXPECT_EQ(hex(f), "00 96 00 00 00 00 00 00");
  EXPECT_EQ(decode_as<MotionCommand>(f).linear_speed, 0.15);
}

TEST(CodecManualSamples, Steering10Degrees) {
  // steering_angle is in rad with the manual's sign (positive = right): 10 deg -> 1000 = 0x03E8.
  const CanFrame f = encode_ok(MotionCommand{0.0, 0.0, 10.0 * kDeg});
  EXPECT_EQ(hex(f), "00 00 00 00 00 00 03 E8");
  EXPECT_NEAR(decode_as<MotionCommand>(f).steering_angle, 10.0 * kDeg, 1e-15);
}

// ---- Byte layouts, one frame per ID, checked field by field against the manual ---------------

TEST(CodecLayout, MotionCommandFields) {
  const CanFrame f = encode_ok(MotionCommand{-1.0, 0.5, -40.0 * kDeg});
  // -1000 = FC18, spin 500 = 01F4, -4000 = F060; bytes 2-3 reserved.
  EXPECT_EQ(hex(f), "FC 18 00 00 01 F4 F0 60");
}

TEST(CodecLayout, OneByteCommands) {
  EXPECT_EQ(hex(encode_ok(MotionModeCommand{proto::MotionMode::kSpin})), "02");
  EXPECT_EQ(encode_ok(MotionModeCommand{}).id, 0x141u);
  EXPECT_EQ(hex(encode_ok(ControlModeCommand{proto::ControlMode::kCan})), "01");
  EXPECT_EQ(hex(encode_ok(ControlModeCommand{proto::ControlMode::kStandby})), "00");
  EXPECT_EQ(encode_ok(ControlModeCommand{}).id, 0x421u);
  EXPECT_EQ(hex(encode_ok(ErrorClearCommand{0x10})), "10");
  EXPECT_EQ(encode_ok(ErrorClearCommand{}).id, 0x441u);
  EXPECT_EQ(hex(encode_ok(UltrasonicSettingCommand{true})), "01");
  EXPECT_EQ(encode_ok(UltrasonicSettingCommand{}).id, 0x451u);
  EXPECT_EQ(hex(encode_ok(UltrasonicSettingFeedback{true})), "01");
  EXPECT_EQ(encode_ok(UltrasonicSettingFeedback{}).id, 0x45Au);
}

TEST(CodecLayout, SystemStatus) {
  const CanFrame f = frame(0x211, {0x02, 0x03, 0x01, 0xF4, 0x80, 0x20, 0x04, 0x01});
  const auto s = decode_as<SystemStatus>(f);
  EXPECT_EQ(s.vehicle_status, proto::VehicleStatus::kAbnormal);
  EXPECT_EQ(s.control_mode, proto::ControlMode::kRemote);
  EXPECT_DOUBLE_EQ(s.battery_voltage, 50.0);  // 0x01F4 = 500 * 0.1 V
  EXPECT_EQ(s.error_bits, 0x80200401u);       // byte 4 is the most significant
  EXPECT_EQ(encode_ok(s), f);
}

TEST(CodecLayout, MotionFeedbackNegativeIsLeft) {
  // 0x221: speed -0.15 m/s, steering -10 deg (manual: negative = left), bytes 2-5 reserved.
  const CanFrame f = frame(0x221, {0xFF, 0x6A, 0, 0, 0, 0, 0xFC, 0x18});
  const auto m = decode_as<MotionFeedback>(f);
  EXPECT_EQ(m.speed, -0.15);
  EXPECT_NEAR(m.steering_angle, -10.0 * kDeg, 1e-15);
  EXPECT_EQ(encode_ok(m), f);
}

TEST(CodecLayout, MotorHighSpeed) {
  const CanFrame f = frame(0x253, {0xFF, 0xF6, 0x00, 0x7B, 0x80, 0x00, 0x00, 0x01});
  const auto m = decode_as<MotorHighSpeedFeedback>(f);
  EXPECT_EQ(m.motor, 3);
  EXPECT_EQ(m.rpm, -10.0);
  EXPECT_DOUBLE_EQ(m.current, 12.3);
  EXPECT_EQ(m.position, std::numeric_limits<std::int32_t>::min() + 1);
  EXPECT_EQ(encode_ok(m), f);
}

TEST(CodecLayout, MotorLowSpeed) {
  const CanFrame f = frame(0x268, {0x01, 0xE0, 0xFF, 0xFB, 0xF6, 0x41, 0, 0});
  const auto m = decode_as<MotorLowSpeedFeedback>(f);
  EXPECT_EQ(m.motor, 8);
  EXPECT_DOUBLE_EQ(m.driver_voltage, 48.0);
  EXPECT_EQ(m.driver_temperature, -5.0);
  EXPECT_EQ(m.motor_temperature, -10.0);  // int8
  EXPECT_EQ(m.driver_status, 0x41);
  EXPECT_EQ(encode_ok(m), f);
}

TEST(CodecLayout, SteeringAnglesInMotorOrder5To8) {
  const CanFrame f = frame(0x271, {0x03, 0xE8, 0xFC, 0x18, 0x00, 0x01, 0x23, 0x28});
  const auto m = decode_as<SteeringAnglesFeedback>(f);
  EXPECT_NEAR(m.angles[0], 10 * kDeg, 1e-15);    // motor 5, right front
  EXPECT_NEAR(m.angles[1], -10 * kDeg, 1e-15);   // motor 6, right rear
  EXPECT_NEAR(m.angles[2], 0.01 * kDeg, 1e-15);  // motor 7, left rear
  EXPECT_NEAR(m.angles[3], 90 * kDeg, 1e-15);    // motor 8, left front
  EXPECT_EQ(encode_ok(m), f);
}

TEST(CodecLayout, WheelSpeedsInMotorOrder1To4) {
  const CanFrame f = frame(0x281, {0x00, 0x96, 0xFF, 0x6A, 0x7F, 0xFF, 0x80, 0x00});
  const auto m = decode_as<WheelSpeedsFeedback>(f);
  EXPECT_EQ(m.speeds[0], 0.15);
  EXPECT_EQ(m.speeds[1], -0.15);
  EXPECT_EQ(m.speeds[2], 32.767);
  EXPECT_EQ(m.speeds[3], -32.768);
  EXPECT_EQ(encode_ok(m), f);
}

TEST(CodecLayout, MotionModeFeedback) {
  const auto m = decode_as<MotionModeFeedback>(frame(0x291, {0x01, 0x01}));
  EXPECT_EQ(m.mode, proto::MotionMode::kOblique);
  EXPECT_TRUE(m.switching);
  EXPECT_FALSE(decode_as<MotionModeFeedback>(frame(0x291, {0x02, 0x00})).switching);
}

TEST(CodecLayout, UltrasonicPairs) {
  const auto a =
      decode_as<UltrasonicFeedback>(frame(0x342, {0x04, 0xB0, 0xFF, 0xFF, 0, 0, 0xFF, 0xFC}));
  EXPECT_EQ(a.first_sensor, 1);
  EXPECT_EQ(a.raw[0], 1200);
  EXPECT_EQ(a.raw[1], -1);
  EXPECT_EQ(a.raw[3], -4);
  const auto b = decode_as<UltrasonicFeedback>(frame(0x343, {0, 1, 0, 2, 0, 3, 0, 4}));
  EXPECT_EQ(b.first_sensor, 5);
  EXPECT_EQ(b.raw[3], 4);
  EXPECT_EQ(encode_ok(b).id, 0x343u);
}

TEST(CodecLayout, BmsDataAndAlarmForEveryBattery) {
  for (int k = 0; k <= 4; ++k) {
    const auto id = static_cast<std::uint32_t>(0x361 + 2 * k);
    const CanFrame data = frame(id, {87, 98, 0x14, 0x00, 0xFF, 0xE0, 0x00, 0xFD});
    const auto b = decode_as<BmsData>(data);
    EXPECT_EQ(b.battery, k);
    EXPECT_EQ(b.soc, 87.0);
    EXPECT_EQ(b.soh, 98.0);
    EXPECT_EQ(b.voltage, 51.2);      // 5120 * 0.01 V
    EXPECT_EQ(b.current, -3.2);      // -32 * 0.1 A
    EXPECT_EQ(b.temperature, 25.3);  // 253 * 0.1 degC
    EXPECT_EQ(encode_ok(b), data);

    const CanFrame alarm = frame(id + 1, {0x82, 0x01, 0x18, 0x00});
    const auto a = decode_as<BmsAlarm>(alarm);
    EXPECT_EQ(a.battery, k);
    EXPECT_EQ(a.alarm1, 0x82);
    EXPECT_EQ(a.alarm2, 0x01);
    EXPECT_EQ(a.warning1, 0x18);
    EXPECT_EQ(a.warning2, 0x00);
    EXPECT_EQ(encode_ok(a), alarm);
  }
}

// ---- Round trip over every layout's representable range ----------------------------------------

struct Field {
  int offset;
  int size;  // bytes
  bool is_signed;
  long long min, max;  // the range the encoder can reproduce (valid range for commands)
};
struct Layout {
  std::uint32_t id;
  std::vector<Field> fields;  // bytes not covered are reserved (zero)
};

constexpr long long kI16Min = -32768, kI16Max = 32767;

std::vector<Layout> layouts() {
  const Field i16a{0, 2, true, kI16Min, kI16Max}, i16b{2, 2, true, kI16Min, kI16Max},
      i16c{4, 2, true, kI16Min, kI16Max}, i16d{6, 2, true, kI16Min, kI16Max};
  std::vector<Layout> all = {
      {0x111, {{0, 2, true, -2600, 2600}, {4, 2, true, -1000, 1000}, {6, 2, true, -9000, 9000}}},
      {0x141, {{0, 1, false, 0, 2}}},
      {0x421, {{0, 1, false, 0, 1}}},
      {0x441, {{0, 1, false, 0, 0x10}}},
      {0x451, {{0, 1, false, 0, 1}}},
      // Any vehicle status / control mode byte is kept raw and re-encoded as it was.
      {0x211,
       {{0, 1, false, 0, 255},
        {1, 1, false, 0, 255},
        {2, 2, false, 0, 65535},
        {4, 4, false, 0, 0xFFFFFFFFLL}}},
      {0x221, {i16a, i16d}},
      {0x271, {i16a, i16b, i16c, i16d}},
      {0x281, {i16a, i16b, i16c, i16d}},
      {0x291, {{0, 1, false, 0, 255}, {1, 1, false, 0, 1}}},
      {0x342, {i16a, i16b, i16c, i16d}},
      {0x343, {i16a, i16b, i16c, i16d}},
      {0x45A, {{0, 1, false, 0, 1}}},
  };
  for (std::uint32_t m = 1; m <= 8; ++m) {
    all.push_back({0x250 + m, {i16a, i16b, {4, 4, true, INT32_MIN, INT32_MAX}}});
    all.push_back(
        {0x260 + m,
         {{0, 2, false, 0, 65535}, i16b, {4, 1, true, -128, 127}, {5, 1, false, 0, 255}}});
  }
  for (std::uint32_t k = 0; k < 5; ++k) {
    all.push_back(
        {0x361 + 2 * k,
         {{0, 1, false, 0, 100}, {1, 1, false, 0, 100}, {2, 2, false, 0, 65535}, i16c, i16d}});
    all.push_back({0x362 + 2 * k,
                   {{0, 1, false, 0, 255},
                    {1, 1, false, 0, 255},
                    {2, 1, false, 0, 255},
                    {3, 1, false, 0, 255}}});
  }
  return all;
}

void put(CanFrame& f, const Field& field, long long v) {
  auto u = static_cast<unsigned long long>(v);
  for (int i = field.size - 1; i >= 0; --i) {
    f.data[static_cast<std::size_t>(field.offset + i)] = static_cast<std::uint8_t>(u & 0xFF);
    u >>= 8;
  }
}

void expect_round_trip(const CanFrame& f) {
  const auto decoded = decode(f);
  ASSERT_TRUE(decoded.ok()) << decoded.error().message;
  EXPECT_EQ(id_of(*decoded), f.id);
  const auto encoded = encode(*decoded);
  ASSERT_TRUE(encoded.ok()) << encoded.error().message;
  EXPECT_EQ(*encoded, f) << "ID 0x" << std::hex << f.id << ": " << hex(f) << " came back as "
                         << hex(*encoded);
}

TEST(CodecRoundTrip, CoversEveryProtocolId) {
  std::vector<std::uint32_t> ids;
  for (const auto& l : layouts())
    ids.push_back(l.id);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, proto::manual_ids());
}

TEST(CodecRoundTrip, EveryFieldAtItsLimitsAndRandomValues) {
  std::mt19937_64 rng(20240611);
  for (const auto& layout : layouts()) {
    SCOPED_TRACE("ID 0x" + std::to_string(layout.id));
    auto random_frame = [&] {
      CanFrame f;
      f.id = layout.id;
      f.dlc = static_cast<std::uint8_t>(proto::expected_dlc(layout.id));
      for (const auto& field : layout.fields) {
        std::uniform_int_distribution<long long> d(field.min, field.max);
        put(f, field, d(rng));
      }
      return f;
    };
    for (const auto& field : layout.fields) {
      for (long long v : {field.min, field.min + 1, field.max - 1, field.max,
                          std::max(field.min, std::min(field.max, 0LL)),
                          std::max(field.min, std::min(field.max, -1LL)),
                          std::max(field.min, std::min(field.max, 1LL))}) {
        CanFrame f = random_frame();
        put(f, field, v);
        expect_round_trip(f);
      }
    }
    for (int i = 0; i < 2000; ++i)
      expect_round_trip(random_frame());
  }
}

TEST(CodecRoundTrip, Int16FieldsExhaustively) {
  // Every int16 of 0x221 speed and angle, every valid 0x111 value: decode then encode is exact.
  for (long long v = kI16Min; v <= kI16Max; ++v) {
    CanFrame f = frame(0x221, {0, 0, 0, 0, 0, 0, 0, 0});
    put(f, {0, 2, true, 0, 0}, v);
    put(f, {6, 2, true, 0, 0}, -1 - v);
    expect_round_trip(f);
    if (std::abs(v) <= 9000) {
      CanFrame c = frame(0x111, {0, 0, 0, 0, 0, 0, 0, 0});
      put(c, {6, 2, true, 0, 0}, v);
      put(c, {0, 2, true, 0, 0}, v % 2601);
      put(c, {4, 2, true, 0, 0}, v % 1001);
      expect_round_trip(c);
    }
  }
}

TEST(CodecRoundTrip, ValuesSurviveWithinHalfAStep) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> speed(-2.6, 2.6), spin(-1.0, 1.0),
      angle(-90 * kDeg, 90 * kDeg);
  for (int i = 0; i < 10000; ++i) {
    const MotionCommand in{speed(rng), spin(rng), angle(rng)};
    const auto out = decode_as<MotionCommand>(encode_ok(in));
    EXPECT_NEAR(out.linear_speed, in.linear_speed, 0.0005 + 1e-12);
    EXPECT_NEAR(out.spin_speed, in.spin_speed, 0.0005 + 1e-12);
    EXPECT_NEAR(out.steering_angle, in.steering_angle, 0.005 * kDeg + 1e-12);
  }
}

// ---- Saturation: never wrap -------------------------------------------------------------------

std::int16_t i16_at(const CanFrame& f, int at) {
  return static_cast<std::int16_t>(f.data[at] << 8 | f.data[at + 1]);
}

TEST(CodecSaturation, MotionCommandClampsToValidRanges) {
  const CanFrame hi = encode_ok(MotionCommand{100.0, 50.0, 3.0});
  EXPECT_EQ(i16_at(hi, 0), 2600);  // interpretation::kMaxLinearSpeedMps
  EXPECT_EQ(i16_at(hi, 4), 1000);
  EXPECT_EQ(i16_at(hi, 6), 9000);
  const CanFrame lo = encode_ok(MotionCommand{-1e300, -50.0, -3.0});
  EXPECT_EQ(i16_at(lo, 0), -2600);
  EXPECT_EQ(i16_at(lo, 4), -1000);
  EXPECT_EQ(i16_at(lo, 6), -9000);
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{2.6004, 0, 0}), 0), 2600);
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{2.5996, 0, 0}), 0), 2600);
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{2.5994, 0, 0}), 0), 2599);
}

TEST(CodecSaturation, SignIsKeptForEveryMagnitude) {
  // Sweep magnitudes across and far beyond int16: the wire value never changes sign.
  for (double mag = 1e-3; mag < 1e30; mag *= 1.37) {
    for (double s : {1.0, -1.0}) {
      const CanFrame f = encode_ok(MotionFeedback{s * mag, s * mag});
      EXPECT_GE(s * i16_at(f, 0), 0) << mag;
      EXPECT_GE(s * i16_at(f, 6), 0) << mag;
      const CanFrame w = encode_ok(WheelSpeedsFeedback{{s * mag, s * mag, s * mag, s * mag}});
      for (int i = 0; i < 4; ++i)
        EXPECT_GE(s * i16_at(w, 2 * i), 0) << mag;
    }
  }
  const CanFrame top = encode_ok(MotionFeedback{40.0, 1000.0});
  EXPECT_EQ(hex(top), "7F FF 00 00 00 00 7F FF");
  const CanFrame bottom = encode_ok(MotionFeedback{-40.0, -1000.0});
  EXPECT_EQ(hex(bottom), "80 00 00 00 00 00 80 00");
}

TEST(CodecSaturation, UnsignedAndSmallFieldsClamp) {
  SystemStatus s;
  s.battery_voltage = -5.0;
  EXPECT_EQ(hex(encode_ok(s)).substr(6, 5), "00 00");
  s.battery_voltage = 1e9;
  EXPECT_EQ(hex(encode_ok(s)).substr(6, 5), "FF FF");
  MotorLowSpeedFeedback m;
  m.motor_temperature = 200;
  EXPECT_EQ(encode_ok(m).data[4], 0x7F);
  m.motor_temperature = -200;
  EXPECT_EQ(encode_ok(m).data[4], 0x80);
  BmsData b;
  b.soc = 150;
  b.soh = -3;
  b.current = -1e6;
  const CanFrame f = encode_ok(b);
  EXPECT_EQ(f.data[0], 100);
  EXPECT_EQ(f.data[1], 0);
  EXPECT_EQ(i16_at(f, 4), -32768);
}

TEST(CodecSaturation, WireHelpers) {
  EXPECT_EQ(wire::saturate_i16(32767.4), 32767);
  EXPECT_EQ(wire::saturate_i16(32767.5), 32767);
  EXPECT_EQ(wire::saturate_i16(40000.0), 32767);
  EXPECT_EQ(wire::saturate_i16(-32768.6), -32768);
  EXPECT_EQ(wire::saturate_i16(-1e300), -32768);
  EXPECT_EQ(wire::saturate_i16(2.5), 3);  // half away from zero
  EXPECT_EQ(wire::saturate_i16(-2.5), -3);
  EXPECT_EQ(wire::saturate_i16(kNaN), 0);
  EXPECT_EQ(wire::saturate_u16(-0.4), 0);
  EXPECT_EQ(wire::saturate_u16(70000.0), 65535);
  EXPECT_EQ(wire::saturate_i8(128.0), 127);
  EXPECT_EQ(wire::saturate_i8(-129.0), -128);
  EXPECT_EQ(wire::saturate_u8(255.6), 255);
  EXPECT_EQ(wire::saturate_u8(-kInf), 0);
}

// ---- NaN / inf refused, naming the field ------------------------------------------------------

struct NonFiniteCase {
  Message message;
  const char* field;
};

std::vector<NonFiniteCase> non_finite_cases(double bad) {
  std::vector<NonFiniteCase> c;
  c.push_back({MotionCommand{bad, 0, 0}, "motion_command.linear_speed"});
  c.push_back({MotionCommand{0, bad, 0}, "motion_command.spin_speed"});
  c.push_back({MotionCommand{0, 0, bad}, "motion_command.steering_angle"});
  SystemStatus s;
  s.battery_voltage = bad;
  c.push_back({s, "system_status.battery_voltage"});
  c.push_back({MotionFeedback{bad, 0}, "motion_feedback.speed"});
  c.push_back({MotionFeedback{0, bad}, "motion_feedback.steering_angle"});
  MotorHighSpeedFeedback h;
  h.rpm = bad;
  c.push_back({h, "motor_high_speed.rpm"});
  h = {};
  h.current = bad;
  c.push_back({h, "motor_high_speed.current"});
  MotorLowSpeedFeedback l;
  l.driver_voltage = bad;
  c.push_back({l, "motor_low_speed.driver_voltage"});
  l = {};
  l.driver_temperature = bad;
  c.push_back({l, "motor_low_speed.driver_temperature"});
  l = {};
  l.motor_temperature = bad;
  c.push_back({l, "motor_low_speed.motor_temperature"});
  for (int i = 0; i < 4; ++i) {
    SteeringAnglesFeedback a;
    a.angles[i] = bad;
    c.push_back({a, i == 0   ? "steering_angles.angles[0]"
                    : i == 3 ? "steering_angles.angles[3]"
                             : "steering_angles.angles["});
    WheelSpeedsFeedback w;
    w.speeds[i] = bad;
    c.push_back({w, i == 0 ? "wheel_speeds.speeds[0]" : "wheel_speeds.speeds["});
  }
  const char* bms_fields[] = {"bms.soc", "bms.soh", "bms.voltage", "bms.current",
                              "bms.temperature"};
  for (int i = 0; i < 5; ++i) {
    BmsData b;
    double* fields[] = {&b.soc, &b.soh, &b.voltage, &b.current, &b.temperature};
    *fields[i] = bad;
    c.push_back({b, bms_fields[i]});
  }
  return c;
}

TEST(CodecNonFinite, RefusedWithTheFieldName) {
  for (double bad : {kNaN, kInf, -kInf}) {
    for (const auto& c : non_finite_cases(bad)) {
      const auto r = encode(c.message);
      ASSERT_FALSE(r.ok()) << c.field;
      EXPECT_EQ(r.error().code, Errc::kNotFinite) << c.field;
      EXPECT_NE(r.error().message.find(c.field), std::string::npos)
          << "'" << r.error().message << "' does not name " << c.field;
      EXPECT_NE(r.error().message.find(std::isnan(bad) ? "NaN" : "infinite"), std::string::npos);
    }
  }
}

// ---- Invalid indices and command values -------------------------------------------------------

TEST(CodecInvalid, IndicesAndCommandsOutsideTheProtocol) {
  auto expect_invalid = [](const Message& m, const char* what) {
    const auto r = encode(m);
    ASSERT_FALSE(r.ok()) << what;
    EXPECT_EQ(r.error().code, Errc::kInvalidArgument) << what;
    EXPECT_NE(r.error().message.find(what), std::string::npos) << r.error().message;
  };
  MotorHighSpeedFeedback h;
  h.motor = 0;
  expect_invalid(h, "motor_high_speed.motor");
  h.motor = 9;
  expect_invalid(h, "motor_high_speed.motor");
  MotorLowSpeedFeedback l;
  l.motor = 9;
  expect_invalid(l, "motor_low_speed.motor");
  BmsData b;
  b.battery = 5;
  expect_invalid(b, "bms.battery");
  b.battery = -1;
  expect_invalid(b, "bms.battery");
  BmsAlarm a;
  a.battery = 5;
  expect_invalid(a, "bms_alarm.battery");
  UltrasonicFeedback u;
  u.first_sensor = 3;
  expect_invalid(u, "ultrasonic.first_sensor");
  expect_invalid(ErrorClearCommand{0x11}, "error_clear_command.code");
  expect_invalid(MotionModeCommand{static_cast<proto::MotionMode>(3)}, "motion_mode_command.mode");
  expect_invalid(ControlModeCommand{proto::ControlMode::kRemote}, "control_mode_command.mode");
  SystemStatus s;
  s.vehicle_status = static_cast<proto::VehicleStatus>(9);
  expect_invalid(s, "system_status.vehicle_status");
}

// ---- Decoding errors --------------------------------------------------------------------------

TEST(CodecDecodeErrors, WrongDlcForEveryId) {
  for (std::uint32_t id : proto::manual_ids()) {
    const int want = proto::expected_dlc(id);
    for (int dlc = 0; dlc <= 15; ++dlc) {
      if (dlc == want) continue;
      CanFrame f;
      f.id = id;
      f.dlc = static_cast<std::uint8_t>(dlc);
      const auto r = decode(f);
      ASSERT_FALSE(r.ok()) << id << " dlc " << dlc;
      EXPECT_EQ(r.error().code, Errc::kBadDlc);
      char idtext[8];
      std::snprintf(idtext, sizeof idtext, "0x%03X", id);
      EXPECT_NE(r.error().message.find(idtext), std::string::npos) << r.error().message;
      EXPECT_NE(r.error().message.find("DLC " + std::to_string(dlc)), std::string::npos);
      EXPECT_NE(r.error().message.find("expected " + std::to_string(want)), std::string::npos);
    }
  }
}

TEST(CodecDecodeErrors, UnknownIds) {
  int unknown = 0;
  for (std::uint32_t id = 0; id <= 0x7FF; ++id) {
    if (proto::is_known_id(id)) continue;
    ++unknown;
    CanFrame f;
    f.id = id;
    f.dlc = 8;
    const auto r = decode(f);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, Errc::kUnknownId);
    EXPECT_NE(r.error().message.find("not part of the RANGER protocol"), std::string::npos);
  }
  EXPECT_EQ(unknown, 0x800 - static_cast<int>(proto::all_ids().size()));
  CanFrame extended;
  extended.id = 0x18FF0111;  // low bits of a RANGER ID do not make an extended frame one
  extended.dlc = 8;
  EXPECT_EQ(decode(extended).error().code, Errc::kUnknownId);
}

TEST(CodecDecodeErrors, ErrorFramesAreNotDecoded) {
  CanFrame f = frame(0x221, {0, 0, 0, 0, 0, 0, 0, 0});
  f.is_error = true;
  const auto r = decode(f);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
  EXPECT_NE(r.error().message.find("error frame"), std::string::npos);
}

TEST(CodecDecode, NeverReadsPastTheDlc) {
  // Bytes past `dlc` (zero by contract) are set to garbage: the decoded message is the same.
  std::mt19937 rng(3);
  for (std::uint32_t id : proto::manual_ids()) {
    const int dlc = proto::expected_dlc(id);
    for (int trial = 0; trial < 50; ++trial) {
      CanFrame clean;
      clean.id = id;
      clean.dlc = static_cast<std::uint8_t>(dlc);
      for (int i = 0; i < dlc; ++i)
        clean.data[i] = static_cast<std::uint8_t>(rng());
      CanFrame dirty = clean;
      for (int i = dlc; i < 8; ++i)
        dirty.data[i] = static_cast<std::uint8_t>(rng() | 1);
      const auto a = decode(clean), b = decode(dirty);
      ASSERT_TRUE(a.ok() && b.ok());
      const auto ea = encode(*a), eb = encode(*b);
      ASSERT_EQ(ea.ok(), eb.ok());
      if (ea.ok()) {
        EXPECT_EQ(*ea, *eb) << "ID 0x" << std::hex << id;
      }
      EXPECT_EQ(a->index(), b->index());
    }
  }
}

TEST(CodecDecode, UnknownEnumValuesAreKeptRaw) {
  const auto s = decode_as<SystemStatus>(frame(0x211, {0x07, 0x05, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(s.vehicle_status, proto::VehicleStatus::kAbnormal);  // undefined = not normal
  EXPECT_EQ(s.vehicle_status_raw, 0x07);
  EXPECT_EQ(s.control_mode_raw, 0x05);  // 0x02 is agx_v2's UART mode now
  EXPECT_EQ(proto::to_string(s.control_mode), "unknown");
  const auto m = decode_as<MotionModeFeedback>(frame(0x291, {0x09, 0x00}));
  EXPECT_EQ(m.mode_raw, 0x09);
  EXPECT_EQ(proto::to_string(m.mode), "unknown");
}

TEST(CodecDecode, VehicleStatus1FollowsInterpretation) {
  const auto s = decode_as<SystemStatus>(frame(0x211, {0x01, 0x01, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(s.vehicle_status, interpretation::kVehicleStatus1IsEmergencyStop
                                  ? proto::VehicleStatus::kEmergencyStop
                                  : proto::VehicleStatus::kAbnormal);
  EXPECT_EQ(s.vehicle_status_raw, 0x01);
}

TEST(CodecEncode, VehicleStatusEnumWinsOverAStaleRawByte) {
  SystemStatus s;
  s.vehicle_status = proto::VehicleStatus::kAbnormal;  // raw left at 0 by a simulator
  EXPECT_EQ(encode_ok(s).data[0], 0x02);
  s.vehicle_status_raw = 0x05;  // a raw value that decodes to kAbnormal is kept
  EXPECT_EQ(encode_ok(s).data[0], 0x05);
  s.vehicle_status = proto::VehicleStatus::kNormal;
  EXPECT_EQ(encode_ok(s).data[0], 0x00);
}

TEST(CodecEncode, IdOfEveryMessage) {
  EXPECT_EQ(id_of(MotionCommand{}), 0x111u);
  EXPECT_EQ(id_of(MotionModeCommand{}), 0x141u);
  EXPECT_EQ(id_of(ControlModeCommand{}), 0x421u);
  EXPECT_EQ(id_of(ErrorClearCommand{}), 0x441u);
  EXPECT_EQ(id_of(UltrasonicSettingCommand{}), 0x451u);
  EXPECT_EQ(id_of(SystemStatus{}), 0x211u);
  EXPECT_EQ(id_of(MotionFeedback{}), 0x221u);
  MotorHighSpeedFeedback h;
  h.motor = 8;
  EXPECT_EQ(id_of(h), 0x258u);
  MotorLowSpeedFeedback l;
  l.motor = 1;
  EXPECT_EQ(id_of(l), 0x261u);
  EXPECT_EQ(id_of(SteeringAnglesFeedback{}), 0x271u);
  EXPECT_EQ(id_of(WheelSpeedsFeedback{}), 0x281u);
  EXPECT_EQ(id_of(MotionModeFeedback{}), 0x291u);
  UltrasonicFeedback u;
  u.first_sensor = 5;
  EXPECT_EQ(id_of(u), 0x343u);
  EXPECT_EQ(id_of(UltrasonicSettingFeedback{}), 0x45Au);
  BmsData b;
  b.battery = 4;
  EXPECT_EQ(id_of(b), 0x369u);
  BmsAlarm a;
  a.battery = 2;
  EXPECT_EQ(id_of(a), 0x366u);
}

TEST(CodecEncode, FramesCarryTheProtocolDlcAndNoStamp) {
  for (const auto& layout : layouts()) {
    CanFrame f;
    f.id = layout.id;
    f.dlc = static_cast<std::uint8_t>(proto::expected_dlc(layout.id));
    const auto m = decode(f);
    ASSERT_TRUE(m.ok());
    const CanFrame e = encode_ok(*m);
    EXPECT_EQ(e.dlc, proto::expected_dlc(layout.id));
    EXPECT_EQ(e.stamp.count(), 0);
    for (int i = e.dlc; i < 8; ++i)
      EXPECT_EQ(e.data[i], 0);
  }
}

}  // namespace
}  // namespace ranger
