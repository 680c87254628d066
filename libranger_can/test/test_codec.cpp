// The codec against the manual and the vendor's revision: sample frames byte-exact, every layout
// of both revisions round-tripped over its representable range (padded and unpadded), saturation
// instead of wrapping, NaN/inf refused by field name, longer frames read from their leading bytes
// and shorter ones refused, impossible content refused naming ID and value, ID checks, and no
// byte past the DLC ever read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

// Counts the global allocations of this test program (for CodecDecode.DoesNotAllocateOnSuccess).
namespace {
std::size_t g_allocations = 0;
}  // namespace
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

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

const ProtocolProfile& agx_v2() {
  static const ProtocolProfile kAgx = *protocol_preset("agx_v2");
  return kAgx;
}
const ProtocolProfile& mini_v3() {
  static const ProtocolProfile kMini = *protocol_preset("mini_v3");
  return kMini;
}
ProtocolProfile with(ProtocolProfile p, const char* name, const char* value) {
  const Status st = set_setting(p, name, value);
  EXPECT_TRUE(st.ok()) << st.error().message;
  return p;
}

CanFrame encode_ok(const Message& m, const ProtocolProfile& p = manual_profile()) {
  auto r = encode(m, p);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : CanFrame{};
}

template <typename T>
T decode_as(const CanFrame& f, const ProtocolProfile& p = manual_profile()) {
  auto r = decode(f, p);
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

// Wire units of the largest plausible feedback angle (100 deg): 10000 x 0.01 deg, 1745 x 0.001 rad.
long long plausible_limit(AngleUnit unit) {
  return unit == AngleUnit::kMilliradian ? 1745 : 10000;
}
// Wire units of 0x111's +-90 deg: 9000 x 0.01 deg, 1571 x 0.001 rad.
long long command_limit(AngleUnit unit) {
  return unit == AngleUnit::kMilliradian ? 1571 : 9000;
}

// Every layout of any revision as `p` reads it (a command only where `p`'s frame layout has it).
std::vector<Layout> layouts(const ProtocolProfile& p = manual_profile()) {
  const Field i16a{0, 2, true, kI16Min, kI16Max}, i16b{2, 2, true, kI16Min, kI16Max},
      i16c{4, 2, true, kI16Min, kI16Max}, i16d{6, 2, true, kI16Min, kI16Max};
  const long long a221 = plausible_limit(p.steering_unit_221);
  const long long a271 = plausible_limit(p.steering_unit_271);
  const long long a111 = command_limit(p.steering_unit_111);
  const long long spin = p.spin_field == SpinField::kWheelSpeed ? 1000 : kI16Max;
  const auto modes = static_cast<long long>(protocol::motion_modes(p.mode_numbering).size());
  const bool on_off = p.light_modes == LightModes::kOnOff;
  const Field light_mode_byte = on_off ? Field{1, 1, false, 0, 1} : Field{1, 1, false, 0, 3};
  std::vector<Field> light_command = {{0, 1, false, 0, 1}, light_mode_byte};
  if (!on_off) {
    light_command.insert(
        light_command.end(),
        {{2, 1, false, 0, 255}, {3, 1, false, 0, 3}, {4, 1, false, 0, 255}, {7, 1, false, 0, 255}});
  }
  std::vector<Field> motion_mode = {{0, 1, false, 0, 255}, {1, 1, false, 0, 1}};
  if (proto::layout_dlc(0x291, p.frame_layout) >= 3) motion_mode.push_back({2, 1, false, 0, 255});
  std::vector<Layout> all = {
      {0x111,
       {{0, 2, true, -2600, 2600}, i16b, {4, 2, true, -spin, spin}, {6, 2, true, -a111, a111}}},
      {0x121, light_command},
      {0x141, {{0, 1, false, 0, modes - 1}}},
      {0x421, {{0, 1, false, 0, 1}}},
      {0x441, {{0, 1, false, 0, 0x10}}},
      {0x451, {{0, 1, false, 0, 1}}},
      {0x4A1, {{0, 1, false, 2, 255}}},  // an answer (the request: VersionRequestBothLengths)
      {0x221, {i16a, i16b, i16c, {6, 2, true, -a221, a221}}},
      // Light state: any mode byte is kept (under on_off, bytes 2-6 are reserved).
      {0x231,
       on_off
           ? std::vector<Field>{{0, 1, false, 0, 1}, {1, 1, false, 0, 255}, {7, 1, false, 0, 255}}
           : std::vector<Field>{{0, 1, false, 0, 1},
                                {1, 1, false, 0, 255},
                                {2, 1, false, 0, 255},
                                {3, 1, false, 0, 255},
                                {4, 1, false, 0, 255},
                                {7, 1, false, 0, 255}}},
      {0x241,
       {{0, 1, false, 0, 255},
        {1, 1, true, -128, 127},
        {2, 1, true, -128, 127},
        {3, 1, true, -128, 127},
        {4, 1, true, -128, 127},
        {5, 1, true, -128, 127},
        {7, 1, false, 0, 255}}},
      {0x271,
       {{0, 2, true, -a271, a271},
        {2, 2, true, -a271, a271},
        {4, 2, true, -a271, a271},
        {6, 2, true, -a271, a271}}},
      {0x281, {i16a, i16b, i16c, i16d}},
      {0x291, motion_mode},
      {0x311, {{0, 4, true, INT32_MIN, INT32_MAX}, {4, 4, true, INT32_MIN, INT32_MAX}}},
      {0x312, {{0, 4, true, INT32_MIN, INT32_MAX}, {4, 4, true, INT32_MIN, INT32_MAX}}},
      {0x342, {i16a, i16b, i16c, i16d}},
      {0x343, {i16a, i16b, i16c, i16d}},
      {0x45A, {{0, 1, false, 0, 1}}},
  };
  // Any vehicle status / control mode byte is kept raw and re-encoded as it was.
  if (p.error_word == ErrorWordLayout::kAgxV2_16) {
    all.push_back({0x211,
                   {{0, 1, false, 0, 255},
                    {1, 1, false, 0, 255},
                    {2, 2, false, 0, 65535},
                    {4, 2, false, 0, 65535},
                    {7, 1, false, 0, 255}}});
  } else {
    all.push_back({0x211,
                   {{0, 1, false, 0, 255},
                    {1, 1, false, 0, 255},
                    {2, 2, false, 0, 65535},
                    {4, 4, false, 0, 0xFFFFFFFFLL}}});
  }
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
  if (proto::find_frame(0x423)->in(p.frame_layout)) all.push_back({0x423, {{0, 1, false, 0, 1}}});
  std::sort(all.begin(), all.end(), [](const Layout& a, const Layout& b) { return a.id < b.id; });
  return all;
}

// The profiles the round trips run under: the three presets, and mixes of their settings.
std::vector<ProtocolProfile> profiles() {
  std::vector<ProtocolProfile> out = {manual_profile(), agx_v2(), mini_v3()};
  out.push_back(with(with(mini_v3(), "tx_dlc", "8"), "odometer_unit", "unknown"));
  out.push_back(with(with(manual_profile(), "frame_layout", "mini_v3"), "error_word", "mini32"));
  out.push_back(with(with(agx_v2(), "tx_dlc", "0"), "steering_unit_271", "centideg"));
  out.push_back(with(with(manual_profile(), "tx_dlc", "8"), "mode_numbering", "mini_v1"));
  out.push_back(
      with(with(manual_profile(), "error_word", "agx16"), "steering_sign_221", "left_positive"));
  return out;
}

void put(CanFrame& f, const Field& field, long long v) {
  auto u = static_cast<unsigned long long>(v);
  for (int i = field.size - 1; i >= 0; --i) {
    f.data[static_cast<std::size_t>(field.offset + i)] = static_cast<std::uint8_t>(u & 0xFF);
    u >>= 8;
  }
}

void expect_round_trip(const CanFrame& f, const ProtocolProfile& p = manual_profile()) {
  const auto decoded = decode(f, p);
  ASSERT_TRUE(decoded.ok()) << decoded.error().message;
  EXPECT_EQ(id_of(*decoded), f.id);
  const auto encoded = encode(*decoded, p);
  ASSERT_TRUE(encoded.ok()) << encoded.error().message;
  EXPECT_EQ(*encoded, f) << "ID 0x" << std::hex << f.id << " under " << describe(p) << ": "
                         << hex(f) << " came back as " << hex(*encoded);
}

// The DLC an encoder under `p` gives `id` (its layout, or 8 under tx_dlc 8).
std::uint8_t tx_dlc_of(std::uint32_t id, const ProtocolProfile& p) {
  return static_cast<std::uint8_t>(p.tx_dlc == 8 ? 8 : proto::layout_dlc(id, p.frame_layout));
}

TEST(CodecRoundTrip, CoversEveryProtocolId) {
  std::set<std::uint32_t> ids;
  for (const ProtocolProfile& p : {manual_profile(), agx_v2(), mini_v3()}) {
    for (const auto& l : layouts(p))
      ids.insert(l.id);
  }
  EXPECT_EQ(std::vector<std::uint32_t>(ids.begin(), ids.end()), proto::all_ids());
}

TEST(CodecRoundTrip, EveryFieldAtItsLimitsAndRandomValuesUnderEveryProfile) {
  std::mt19937_64 rng(20240611);
  for (const ProtocolProfile& p : profiles()) {
    SCOPED_TRACE(describe(p));
    for (const auto& layout : layouts(p)) {
      SCOPED_TRACE("ID 0x" + std::to_string(layout.id));
      auto random_frame = [&] {
        CanFrame f;
        f.id = layout.id;
        f.dlc = tx_dlc_of(layout.id, p);
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
          expect_round_trip(f, p);
        }
      }
      for (int i = 0; i < 500; ++i)
        expect_round_trip(random_frame(), p);
    }
  }
}

TEST(CodecRoundTrip, VersionRequestBothLengths) {
  CanFrame request;
  request.id = 0x4A1;
  request.dlc = 1;
  request.data[0] = 0x01;
  expect_round_trip(request);
  EXPECT_TRUE(std::holds_alternative<VersionRequest>(*decode(request)));
  CanFrame padded = request;
  padded.dlc = 8;
  expect_round_trip(padded, agx_v2());
  EXPECT_TRUE(std::holds_alternative<VersionRequest>(*decode(padded)));
  EXPECT_EQ(hex(encode_ok(VersionRequest{})), "01");
  EXPECT_EQ(hex(encode_ok(VersionRequest{}, agx_v2())), "01 00 00 00 00 00 00 00");
}

TEST(CodecRoundTrip, Int16FieldsExhaustively) {
  // Every int16 of 0x221 speed, every plausible angle (|a| <= 100 deg), every valid 0x111 value:
  // decode then encode is exact.
  for (long long v = kI16Min; v <= kI16Max; ++v) {
    CanFrame f = frame(0x221, {0, 0, 0, 0, 0, 0, 0, 0});
    put(f, {0, 2, true, 0, 0}, v);
    put(f, {2, 2, true, 0, 0}, -v - 1);
    put(f, {4, 2, true, 0, 0}, v / 2);
    put(f, {6, 2, true, 0, 0}, v % 10001);
    expect_round_trip(f);
    CanFrame g = f;
    put(g, {6, 2, true, 0, 0}, v % 1746);
    expect_round_trip(g, with(manual_profile(), "steering_unit_221", "millirad"));
    if (std::abs(v) <= 9000) {
      CanFrame c = frame(0x111, {0, 0, 0, 0, 0, 0, 0, 0});
      put(c, {6, 2, true, 0, 0}, v);
      put(c, {0, 2, true, 0, 0}, v % 2601);
      put(c, {2, 2, true, 0, 0}, -v);
      put(c, {4, 2, true, 0, 0}, v % 1001);
      expect_round_trip(c);
    }
  }
}

TEST(CodecRoundTrip, ValuesSurviveWithinHalfAStep) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> speed(-2.6, 2.6), spin(-1.0, 1.0),
      angle(-90 * kDeg, 90 * kDeg);
  std::uniform_real_distribution<double> yaw(-5.0, 5.0);
  for (int i = 0; i < 10000; ++i) {
    const MotionCommand in{speed(rng), spin(rng), angle(rng), yaw(rng)};
    const auto out = decode_as<MotionCommand>(encode_ok(in));
    EXPECT_NEAR(out.linear_speed, in.linear_speed, 0.0005 + 1e-12);
    EXPECT_NEAR(out.spin_speed, in.spin_speed, 0.0005 + 1e-12);
    EXPECT_NEAR(out.steering_angle, in.steering_angle, 0.005 * kDeg + 1e-12);
    EXPECT_NEAR(out.yaw_rate, in.yaw_rate, 0.0005 + 1e-12);
    // agx_v2: 0.001 rad steps, left positive on the wire, the same value back.
    const auto v2 = decode_as<MotionCommand>(encode_ok(in, agx_v2()), agx_v2());
    EXPECT_NEAR(v2.steering_angle, in.steering_angle, 0.0005 + 1e-12);
    EXPECT_NEAR(v2.yaw_rate, in.yaw_rate, 0.0005 + 1e-12);
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
  c.push_back({MotionCommand{0, 0, 0, bad}, "motion_command.yaw_rate"});
  SystemStatus s;
  s.battery_voltage = bad;
  c.push_back({s, "system_status.battery_voltage"});
  c.push_back({MotionFeedback{bad, 0}, "motion_feedback.speed"});
  c.push_back({MotionFeedback{0, bad}, "motion_feedback.steering_angle"});
  c.push_back({MotionFeedback{0, 0, bad}, "motion_feedback.yaw_rate"});
  c.push_back({MotionFeedback{0, 0, 0, bad}, "motion_feedback.lateral_speed"});
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
  expect_invalid(ControlModeCommand{proto::ControlMode::kUart}, "control_mode_command.mode");
  SystemStatus s;
  s.vehicle_status = static_cast<proto::VehicleStatus>(9);
  expect_invalid(s, "system_status.vehicle_status");
}

// ---- Decoding errors --------------------------------------------------------------------------

TEST(CodecDecodeErrors, ShorterThanItsLayoutForEveryId) {
  for (const ProtocolProfile& p : {manual_profile(), agx_v2(), mini_v3()}) {
    for (std::uint32_t id : proto::all_ids()) {
      const int want = proto::layout_dlc(id, p.frame_layout);
      for (int dlc = 0; dlc < want; ++dlc) {
        CanFrame f;
        f.id = id;
        f.dlc = static_cast<std::uint8_t>(dlc);
        const auto r = decode(f, p);
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
}

TEST(CodecDecodeErrors, DlcAboveEightIsRefused) {
  for (std::uint32_t id : proto::all_ids()) {
    for (int dlc = 9; dlc <= 15; ++dlc) {
      CanFrame f;
      f.id = id;
      f.dlc = static_cast<std::uint8_t>(dlc);
      const auto r = decode(f);
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.error().code, Errc::kBadDlc);
      EXPECT_NE(r.error().message.find("DLC " + std::to_string(dlc) + " exceeds"),
                std::string::npos)
          << r.error().message;
    }
  }
}

TEST(CodecDecode, LongerFramesDecodeTheirLeadingBytes) {
  // The vendor's software pads to 8 and never checks a length. Every ID, every longer
  // DLC, random padding: the message is the one of the leading bytes.
  std::mt19937 rng(14);
  for (const ProtocolProfile& p : {manual_profile(), agx_v2(), mini_v3()}) {
    for (std::uint32_t id : proto::all_ids()) {
      if (id == proto::kVersionId) continue;  // an answer's text is the whole frame: below
      const proto::FrameInfo* row = proto::find_frame(id);
      // A command of another revision decodes, but is not sent under `p` (0x423 outside mini_v3).
      if (row->direction == proto::Direction::kToChassis && !row->in(p.frame_layout)) continue;
      const int layout = proto::layout_dlc(id, p.frame_layout);
      CanFrame exact = frame(id, std::vector<std::uint8_t>(static_cast<std::size_t>(layout), 0));
      for (int i = 0; i < layout; ++i)  // small values: plausible angles, sendable modes
        exact.data[i] = static_cast<std::uint8_t>(rng() & 0x01);
      const auto reference = decode(exact, p);
      ASSERT_TRUE(reference.ok()) << reference.error().message;
      const auto canonical = encode(*reference, with(p, "tx_dlc", "0"));
      ASSERT_TRUE(canonical.ok());
      for (int dlc = layout + 1; dlc <= 8; ++dlc) {
        CanFrame longer = exact;
        longer.dlc = static_cast<std::uint8_t>(dlc);
        for (int i = layout; i < dlc; ++i)
          longer.data[i] = static_cast<std::uint8_t>(rng());
        EXPECT_EQ(proto::extra_bytes(longer, p.frame_layout), dlc - layout);
        const auto r = decode(longer, p);
        ASSERT_TRUE(r.ok()) << "ID 0x" << std::hex << id << " DLC " << dlc << ": "
                            << r.error().message;
        EXPECT_EQ(r->index(), reference->index());
        const auto e = encode(*r, with(p, "tx_dlc", "0"));
        ASSERT_TRUE(e.ok());
        EXPECT_EQ(*e, *canonical) << "ID 0x" << std::hex << id << " DLC " << std::dec << dlc;
      }
    }
  }
}

TEST(CodecDecode, DoesNotAllocateOnSuccess) {
  std::vector<CanFrame> frames;
  for (std::uint32_t id : proto::all_ids()) {
    CanFrame f;
    f.id = id;
    f.dlc = 8;  // padded: every layout, read from its leading bytes
    f.data = {0x01, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x02};
    frames.push_back(f);
  }
  const ProtocolProfile profiles_[] = {manual_profile(), agx_v2()};
  std::size_t decoded = 0;
  const std::size_t before = g_allocations;
  for (const ProtocolProfile& p : profiles_) {
    for (const CanFrame& f : frames)
      decoded += decode(f, p).ok() ? 1 : 0;
  }
  EXPECT_EQ(g_allocations - before, 0u);
  EXPECT_EQ(decoded, 2 * frames.size());
}

TEST(CodecDecode, PaddedSampleFrames) {
  // 0x291 and 0x141 as the vendor sends them: DLC 8, zero-padded.
  const auto mode = decode_as<MotionModeFeedback>(frame(0x291, {0x02, 0x01, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(mode.mode, proto::MotionMode::kSpin);
  EXPECT_TRUE(mode.mode_known);
  EXPECT_TRUE(mode.switching);
  EXPECT_EQ(decode_as<MotionModeCommand>(frame(0x141, {0x01, 0, 0, 0, 0, 0, 0, 0})).mode,
            proto::MotionMode::kOblique);
  EXPECT_EQ(decode_as<ControlModeCommand>(frame(0x421, {0x01, 0, 0, 0, 0, 0, 0, 0})).mode,
            proto::ControlMode::kCan);
  const auto alarm = decode_as<BmsAlarm>(frame(0x362, {0x04, 0, 0x08, 0, 0xAA, 0xBB, 0xCC, 0xDD}));
  EXPECT_EQ(alarm.alarm1, 0x04);
  EXPECT_EQ(alarm.warning1, 0x08);
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
  // Other revisions' and other models' IDs are not ours: the V1 family's 0x151, the SDK's
  // 0x131 braking and 0x411 version request.
  for (std::uint32_t id : {0x131u, 0x151u, 0x411u, 0x41Au}) {
    CanFrame f;
    f.id = id;
    f.dlc = 8;
    EXPECT_EQ(decode(f, agx_v2()).error().code, Errc::kUnknownId) << std::hex << id;
  }
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
  // Bytes past `dlc` (zero by contract) are set to garbage: the result is the same (the same
  // message, or the same error for content impossible under the profile).
  std::mt19937 rng(3);
  for (const ProtocolProfile& p : {manual_profile(), agx_v2()}) {
    for (std::uint32_t id : proto::all_ids()) {
      const int dlc = proto::layout_dlc(id);
      for (int trial = 0; trial < 50; ++trial) {
        CanFrame clean;
        clean.id = id;
        clean.dlc = static_cast<std::uint8_t>(dlc);
        for (int i = 0; i < dlc; ++i)
          clean.data[i] = static_cast<std::uint8_t>(rng());
        CanFrame dirty = clean;
        for (int i = dlc; i < 8; ++i)
          dirty.data[i] = static_cast<std::uint8_t>(rng() | 1);
        const auto a = decode(clean, p), b = decode(dirty, p);
        ASSERT_EQ(a.ok(), b.ok());
        if (!a.ok()) {
          EXPECT_EQ(a.error().code, Errc::kOutOfRange) << a.error().message;
          EXPECT_EQ(a.error().message, b.error().message);
          continue;
        }
        const auto ea = encode(*a, p), eb = encode(*b, p);
        ASSERT_EQ(ea.ok(), eb.ok());
        if (ea.ok()) {
          EXPECT_EQ(*ea, *eb) << "ID 0x" << std::hex << id;
        }
        EXPECT_EQ(a->index(), b->index());
      }
    }
  }
}

TEST(CodecDecode, UnknownEnumValuesAreKeptRaw) {
  const auto s = decode_as<SystemStatus>(frame(0x211, {0x07, 0x05, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(s.vehicle_status, proto::VehicleStatus::kAbnormal);  // undefined = not normal
  EXPECT_EQ(s.vehicle_status_raw, 0x07);
  EXPECT_EQ(s.control_mode_raw, 0x05);
  EXPECT_EQ(proto::to_string(s.control_mode), "unknown");
  // agx_v2's UART control mode has a name now.
  EXPECT_EQ(decode_as<SystemStatus>(frame(0x211, {0, 0x02, 0, 0, 0, 0, 0, 0})).control_mode,
            proto::ControlMode::kUart);
  // A mode the numbering does not define: known = false, mode = Ackermann (not to be acted on),
  // the switching flag still read.
  const auto m = decode_as<MotionModeFeedback>(frame(0x291, {0x09, 0x01}));
  EXPECT_EQ(m.mode_raw, 0x09);
  EXPECT_FALSE(m.mode_known);
  EXPECT_EQ(m.mode, proto::MotionMode::kAckermann);
  EXPECT_TRUE(m.switching);
  EXPECT_EQ(encode_ok(m), frame(0x291, {0x09, 0x01})) << "the raw byte goes back";
  const auto c = decode_as<MotionModeCommand>(frame(0x141, {0x03}));
  EXPECT_FALSE(c.mode_known);
  EXPECT_EQ(c.mode_raw, 0x03);
  EXPECT_EQ(proto::to_string(c.mode), "unknown");
  EXPECT_EQ(encode(c).error().code, Errc::kInvalidArgument) << "never sent";
}

TEST(CodecDecode, VehicleStatus1FollowsTheProfile) {
  const CanFrame f = frame(0x211, {0x01, 0x01, 0, 0, 0, 0, 0, 0});
  const auto s = decode_as<SystemStatus>(f);
  EXPECT_EQ(s.vehicle_status, interpretation::kVehicleStatus1IsEmergencyStop
                                  ? proto::VehicleStatus::kEmergencyStop
                                  : proto::VehicleStatus::kAbnormal);
  EXPECT_EQ(s.vehicle_status_raw, 0x01);
  const ProtocolProfile no_estop = with(manual_profile(), "vehicle_status_1_is_estop", "false");
  const auto a = decode_as<SystemStatus>(f, no_estop);
  EXPECT_EQ(a.vehicle_status, proto::VehicleStatus::kAbnormal);
  EXPECT_EQ(encode_ok(a, no_estop), f);
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
  EXPECT_EQ(id_of(LightCommand{}), 0x121u);
  EXPECT_EQ(id_of(LightState{}), 0x231u);
  EXPECT_EQ(id_of(RemoteControlState{}), 0x241u);
  EXPECT_EQ(id_of(OdometerFeedback{}), 0x311u);
  EXPECT_EQ(id_of(VersionRequest{}), 0x4A1u);
  EXPECT_EQ(id_of(VersionResponse{}), 0x4A1u);
}

TEST(CodecEncode, FramesCarryTheLayoutDlcOrEightAndNoStamp) {
  for (const ProtocolProfile& p : profiles()) {
    for (const auto& layout : layouts(p)) {
      CanFrame f;
      f.id = layout.id;
      f.dlc = static_cast<std::uint8_t>(proto::layout_dlc(layout.id, p.frame_layout));
      const auto m = decode(f, p);
      ASSERT_TRUE(m.ok());
      const CanFrame e = encode_ok(*m, p);
      EXPECT_EQ(e.dlc, tx_dlc_of(layout.id, p));
      EXPECT_EQ(e.stamp.count(), 0);
      for (int i = proto::layout_dlc(layout.id, p.frame_layout); i < 8; ++i)
        EXPECT_EQ(e.data[i], 0) << "zero padding";
    }
  }
}

// ---- agx_v2: units, signs, layouts -------------------------------------------------------------

TEST(CodecAgxV2, SteeringInMilliradiansLeftPositive) {
  // 10 deg to the right (the manual's sign) = 0.1745 rad; agx_v2 sends left positive: -175.
  const CanFrame f = encode_ok(MotionCommand{0.0, 0.0, 10.0 * kDeg}, agx_v2());
  EXPECT_EQ(hex(f), "00 00 00 00 00 00 FF 51");
  EXPECT_NEAR(decode_as<MotionCommand>(f, agx_v2()).steering_angle, 0.175, 1e-15);
  // The same angle with the sign setting flipped.
  const ProtocolProfile right = with(agx_v2(), "steering_sign_111", "right_positive");
  EXPECT_EQ(hex(encode_ok(MotionCommand{0.0, 0.0, 10.0 * kDeg}, right)), "00 00 00 00 00 00 00 AF");
  // 0x221 and 0x271 each with their own unit and sign: 1014 mrad left = the spin position.
  const auto fb = decode_as<MotionFeedback>(frame(0x221, {0, 0, 0, 0, 0, 0, 0x03, 0xF6}), agx_v2());
  EXPECT_DOUBLE_EQ(fb.steering_angle, -1.014);
  const auto wheels = decode_as<SteeringAnglesFeedback>(
      frame(0x271, {0x03, 0xF6, 0xFC, 0x0A, 0, 1, 0, 0}), agx_v2());
  EXPECT_DOUBLE_EQ(wheels.angles[0], -1.014);
  EXPECT_DOUBLE_EQ(wheels.angles[1], 1.014);
  EXPECT_DOUBLE_EQ(wheels.angles[2], -0.001);
  EXPECT_EQ(wheels.angles[3], 0.0);
  EXPECT_FALSE(std::signbit(wheels.angles[3])) << "zero stays +0";
  // The older firmware's 0x271 in 0.01 deg, right positive (a per-frame setting).
  const ProtocolProfile old_271 =
      with(with(agx_v2(), "steering_unit_271", "centideg"), "steering_sign_271", "right_positive");
  EXPECT_NEAR(
      decode_as<SteeringAnglesFeedback>(frame(0x271, {0x16, 0xB2, 0, 0, 0, 0, 0, 0}), old_271)
          .angles[0],
      58.1 * kDeg, 1e-12);
}

TEST(CodecAgxV2, CommandSteeringSaturatesAtNinetyDegreesInEitherUnit) {
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{0, 0, 3.0}, agx_v2()), 6), -1571);
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{0, 0, -3.0}, agx_v2()), 6), 1571);
  EXPECT_EQ(i16_at(encode_ok(MotionCommand{0, 0, 3.0}), 6), 9000);
}

TEST(CodecAgxV2, YawRateAndLateralFields) {
  // 0x111: yaw rate 0.5 rad/s CCW in bytes 2-3 (as on the wire: the codec applies no spin sign).
  MotionCommand c;
  c.yaw_rate = 0.5;
  EXPECT_EQ(hex(encode_ok(c, agx_v2())), "00 00 01 F4 00 00 00 00");
  EXPECT_EQ(decode_as<MotionCommand>(encode_ok(c, agx_v2()), agx_v2()).yaw_rate, 0.5);
  const ProtocolProfile cw = with(agx_v2(), "spin_sign", "cw");
  EXPECT_EQ(hex(encode_ok(c, cw)), "00 00 01 F4 00 00 00 00") << "spin sign: not the codec's";
  // Bytes 4-5 are agx_v2's lateral speed: no +-1 m/s spin clamp there.
  c = {};
  c.spin_speed = 1.5;
  EXPECT_EQ(i16_at(encode_ok(c, agx_v2()), 4), 1500);
  EXPECT_EQ(i16_at(encode_ok(c), 4), 1000);
  // 0x221: speed, yaw rate, lateral speed, steering.
  const auto fb = decode_as<MotionFeedback>(
      frame(0x221, {0x01, 0xF4, 0xFF, 0x38, 0x00, 0x64, 0x00, 0x00}), agx_v2());
  EXPECT_EQ(fb.speed, 0.5);
  EXPECT_EQ(fb.yaw_rate, -0.2);
  EXPECT_EQ(fb.lateral_speed, 0.1);
}

TEST(CodecAgxV2, SixteenBitErrorWordWithCounterHasNoPhantomFaults) {
  // A chassis counting in byte 7 with no fault at all: under agx16 every frame reads clean; under
  // the manual's 32-bit word the counter reads as motor-driver communication faults.
  for (int counter = 0; counter < 256; ++counter) {
    const CanFrame f = frame(
        0x211, {0x00, 0x01, 0x01, 0xE0, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(counter)});
    const auto s = decode_as<SystemStatus>(f, agx_v2());
    EXPECT_EQ(s.error_bits, 0u);
    ASSERT_TRUE(s.counter.has_value());
    EXPECT_EQ(*s.counter, counter);
    EXPECT_TRUE(proto::error_bit_names(s.error_bits, ErrorWordLayout::kAgxV2_16).empty());
    EXPECT_FALSE(proto::is_critical_error(s.error_bits, ErrorWordLayout::kAgxV2_16));
    EXPECT_DOUBLE_EQ(s.battery_voltage, 48.0);
    EXPECT_EQ(encode_ok(s, agx_v2()), f);
    const auto manual = decode_as<SystemStatus>(f);
    EXPECT_FALSE(manual.counter.has_value());
    if (counter & 0x78) {
      EXPECT_FALSE(proto::error_bit_names(manual.error_bits).empty()) << "phantom faults";
    }
  }
  // Bytes 4-5 carry the word (host communication lost); byte 6 is reserved.
  const auto s =
      decode_as<SystemStatus>(frame(0x211, {0, 1, 1, 0xE0, 0x02, 0x00, 0xFF, 7}), agx_v2());
  EXPECT_EQ(s.error_bits, 0x0200u);
  EXPECT_EQ(proto::error_bit_names(s.error_bits, ErrorWordLayout::kAgxV2_16),
            std::vector<std::string>{"host_communication_lost"});
  // A word wider than the layout cannot be sent.
  SystemStatus wide;
  wide.error_bits = 0x10000;
  const auto r = encode(wide, agx_v2());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
  EXPECT_NE(r.error().message.find("system_status.error_bits"), std::string::npos);
  // The manual's layout has no counter: it is not sent.
  SystemStatus counted;
  counted.counter = 9;
  EXPECT_EQ(encode_ok(counted).data[7], 0);
  EXPECT_EQ(encode_ok(counted, agx_v2()).data[7], 9);
}

TEST(CodecAgxV2, BmsVoltageInTenthsOfAVolt) {
  const CanFrame f = frame(0x361, {87, 98, 0x01, 0xE0, 0xFF, 0xE0, 0x00, 0xFD});
  EXPECT_DOUBLE_EQ(decode_as<BmsData>(f, agx_v2()).voltage, 48.0);
  EXPECT_DOUBLE_EQ(decode_as<BmsData>(f).voltage, 4.8) << "the manual's 0.01 V: a 48 V pack";
  BmsData b;
  b.voltage = 51.2;
  EXPECT_EQ(i16_at(encode_ok(b, agx_v2()), 2), 512);
  EXPECT_EQ(i16_at(encode_ok(b), 2), 5120);
  // The current's sign is an interpretation above the codec: passed as on the wire.
  EXPECT_EQ(decode_as<BmsData>(f, agx_v2()).current, -3.2);
}

TEST(CodecAgxV2, MotionModeNumberings) {
  using M = proto::MotionMode;
  const ProtocolProfile mini = with(manual_profile(), "mode_numbering", "mini_v1");
  // 0x291 = 3: unknown to the manual, park for agx_v2, side slip for the MINI V1.
  EXPECT_FALSE(decode_as<MotionModeFeedback>(frame(0x291, {3, 0})).mode_known);
  EXPECT_EQ(decode_as<MotionModeFeedback>(frame(0x291, {3, 0}), agx_v2()).mode, M::kPark);
  EXPECT_EQ(decode_as<MotionModeFeedback>(frame(0x291, {3, 0}), mini).mode, M::kSideSlip);
  EXPECT_EQ(decode_as<MotionModeFeedback>(frame(0x291, {4, 0}), agx_v2()).mode, M::kSideSlip);
  EXPECT_FALSE(decode_as<MotionModeFeedback>(frame(0x291, {4, 0}), mini).mode_known);
  // Commands by the numbering: side slip is 3 on the MINI V1, 4 on agx_v2, nothing on the manual.
  EXPECT_EQ(hex(encode_ok(MotionModeCommand{M::kSideSlip}, mini)), "03");
  EXPECT_EQ(hex(encode_ok(MotionModeCommand{M::kSideSlip}, agx_v2())), "04 00 00 00 00 00 00 00");
  EXPECT_EQ(hex(encode_ok(MotionModeCommand{M::kPark}, agx_v2())), "03 00 00 00 00 00 00 00");
  for (const auto& [mode, profile] :
       {std::pair{M::kSideSlip, manual_profile()}, std::pair{M::kPark, manual_profile()},
        std::pair{M::kPark, mini}}) {
    const auto r = encode(MotionModeCommand{mode}, profile);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
    EXPECT_NE(r.error().message.find("motion_mode_command.mode"), std::string::npos);
    EXPECT_NE(r.error().message.find(std::string(to_string(profile.mode_numbering))),
              std::string::npos)
        << r.error().message;
  }
  MotionModeFeedback park;
  park.mode = M::kPark;
  EXPECT_EQ(encode(park).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(encode_ok(park, agx_v2()).data[0], 3);
}

TEST(CodecAgxV2, DriverEnableBit) {
  // agx_v2: bit 6 = enabled; decoded in the manual's meaning (bit 6 = disabled).
  const auto on =
      decode_as<MotorLowSpeedFeedback>(frame(0x261, {1, 0xE0, 0, 25, 25, 0x40, 0, 0}), agx_v2());
  EXPECT_EQ(on.driver_status, 0x00);
  const auto off =
      decode_as<MotorLowSpeedFeedback>(frame(0x261, {1, 0xE0, 0, 25, 25, 0x21, 0, 0}), agx_v2());
  EXPECT_EQ(off.driver_status, proto::driver_status::kDriverDisabled | 0x21);
  EXPECT_EQ(encode_ok(off, agx_v2()).data[5], 0x21);
  EXPECT_EQ(decode_as<MotorLowSpeedFeedback>(frame(0x261, {1, 0xE0, 0, 25, 25, 0x40, 0, 0}))
                .driver_status,
            0x40)
      << "manual: as on the wire";
}

TEST(CodecAgxV2, NewFrames) {
  const CanFrame light = frame(0x121, {0x01, 0x03, 0x64, 0x02, 0x00, 0, 0, 0x05});
  const auto l = decode_as<LightCommand>(light, agx_v2());
  EXPECT_TRUE(l.enable);
  EXPECT_EQ(l.front_mode, proto::LightMode::kCustom);
  EXPECT_EQ(l.front_custom, 100);
  EXPECT_EQ(l.rear_mode, proto::LightMode::kBreathing);
  EXPECT_EQ(l.counter, 5);
  EXPECT_EQ(encode_ok(l, agx_v2()), light);
  LightCommand bad;
  bad.rear_mode = static_cast<proto::LightMode>(4);
  EXPECT_EQ(encode(bad).error().code, Errc::kInvalidArgument);
  LightState state;
  state.front_mode = static_cast<proto::LightMode>(9);  // feedback: written as it is
  EXPECT_EQ(encode_ok(state).data[1], 9);
  EXPECT_EQ(decode_as<LightState>(frame(0x231, {0, 1, 0, 1, 0, 0, 0, 9})).counter, 9);

  // SWA up (2), SWB middle (1), SWC down (3), SWD up (2): 10 11 01 10 = 0xB6.
  const CanFrame rc = frame(0x241, {0xB6, 0x80, 0x7F, 0x01, 0xFF, 0x10, 0, 0x2A});
  const auto r = decode_as<RemoteControlState>(rc);
  EXPECT_EQ(r.swa, proto::RemoteSwitch::kUp);
  EXPECT_EQ(r.swb, proto::RemoteSwitch::kMiddle);
  EXPECT_EQ(r.swc, proto::RemoteSwitch::kDown);
  EXPECT_EQ(r.swd, proto::RemoteSwitch::kUp);
  EXPECT_EQ(r.stick_right_h, -128);
  EXPECT_EQ(r.stick_right_v, 127);
  EXPECT_EQ(r.stick_left_v, 1);
  EXPECT_EQ(r.stick_left_h, -1);
  EXPECT_EQ(r.var_a, 16);
  EXPECT_EQ(r.counter, 42);
  EXPECT_EQ(encode_ok(r), rc);

  const CanFrame odo = frame(0x311, {0x80, 0, 0, 0, 0, 0, 0x30, 0x39});
  const auto o = decode_as<OdometerFeedback>(odo);
  EXPECT_EQ(o.left_wheel, std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(o.right_wheel, 12345);
  EXPECT_EQ(encode_ok(o), odo);

  const CanFrame version = frame(0x4A1, {'V', '1', '.', '2', '.', '3', 0, 0});
  const auto v = decode_as<VersionResponse>(version);
  EXPECT_EQ(v.view(), "V1.2.3");
  EXPECT_EQ(v.length, 8);
  EXPECT_EQ(encode_ok(v), version);
  EXPECT_EQ(decode_as<VersionResponse>(frame(0x4A1, {'A'})).view(), "A");
  VersionResponse empty;
  EXPECT_EQ(encode(empty).error().code, Errc::kInvalidArgument);
}

// ---- Content impossible under the profile
// --------------------------------------------------------

TEST(CodecImpossible, SteeringBeyondAnyModelIsRefusedNamingIdAndValue) {
  auto expect_refused = [](const CanFrame& f, const ProtocolProfile& p, const char* id,
                           const char* value) {
    const auto r = decode(f, p);
    ASSERT_FALSE(r.ok()) << hex(f);
    EXPECT_EQ(r.error().code, Errc::kOutOfRange);
    EXPECT_NE(r.error().message.find(id), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(value), std::string::npos) << r.error().message;
  };
  // 0x221: 100.01 deg in 0.01 deg; 1746 mrad.
  expect_refused(frame(0x221, {0, 0, 0, 0, 0, 0, 0x27, 0x11}), manual_profile(), "0x221", "10001");
  expect_refused(frame(0x221, {0, 0, 0, 0, 0, 0, 0xD8, 0xEF}), manual_profile(), "0x221", "-10001");
  expect_refused(frame(0x221, {0, 0, 0, 0, 0, 0, 0x06, 0xD2}), agx_v2(), "0x221", "1746");
  // 0x271 names the motor: motor 7 (bytes 4-5).
  expect_refused(frame(0x271, {0, 0, 0, 0, 0x80, 0x00, 0, 0}), manual_profile(), "angle of motor 7",
                 "-32768");
  // The spin position (58.1 deg) in the manual's unit read under agx_v2: 5810 mrad = 333 deg.
  // A wrong unit shows as refused frames, never as motion.
  const CanFrame spin_position = frame(0x271, {0x16, 0xB2, 0, 0, 0, 0, 0, 0});
  EXPECT_TRUE(decode(spin_position).ok());
  expect_refused(spin_position, agx_v2(), "0x271", "5810");
  // The limits themselves are possible.
  EXPECT_TRUE(decode(frame(0x221, {0, 0, 0, 0, 0, 0, 0x27, 0x10})).ok());
  EXPECT_TRUE(decode(frame(0x221, {0, 0, 0, 0, 0, 0, 0x06, 0xD1}), agx_v2()).ok());
  // 0x111 is what a host sends: it is decoded as it is (the chassis clamps).
  EXPECT_TRUE(decode(frame(0x111, {0, 0, 0, 0, 0, 0, 0x7F, 0xFF})).ok());
}

}  // namespace
}  // namespace ranger
