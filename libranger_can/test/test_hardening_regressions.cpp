// Regression tests for the bugs the fuzzers found (docs/HARDENING.md lists them). Each test
// replays the smallest input that triggered the bug, as a plain unit test, so the fix stays in
// place even when the fuzzers are not run.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/fake_bus.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

// fuzz_candump: a timestamp of 1.7e11 s overflowed int64 nanoseconds (undefined behaviour).
TEST(HardeningRegressions, CandumpTimestampBeyondTheRepresentableRangeIsAParseError) {
  const auto entry = parse_candump_line("(170000050000.0000) can0 221#0000000000000000");
  ASSERT_FALSE(entry.ok());
  EXPECT_EQ(entry.error().code, Errc::kParseError);
  EXPECT_NE(entry.error().message.find("out of range"), std::string::npos) << entry.error().message;
  // The largest accepted stamp keeps the difference of any two within int64.
  const auto last = parse_candump_line("(4611686017.999999) can0 221#0000000000000000");
  ASSERT_TRUE(last.ok()) << last.error().message;
  EXPECT_FALSE(parse_candump_line("(4611686018.000000) can0 221#0000000000000000").ok());
}

// fuzz_candump: a stamp in (-1 us, 0) was written as "-0.000000", which reads back as 0 and is
// written differently the second time.
TEST(HardeningRegressions, CandumpStampBetweenMinusOneMicrosecondAndZeroIsWrittenAsZero) {
  CanFrame f;
  f.id = 0x362;
  f.dlc = 4;
  f.stamp = Timestamp{-100};
  const std::string line = format_candump_line(f, "can0");
  EXPECT_EQ(line.rfind("(0.000000) can0 362#", 0), 0u) << line;
  f.stamp = Timestamp{-1500};
  EXPECT_EQ(format_candump_line(f, "can0").rfind("(-0.000001) ", 0), 0u);
}

// fuzz_controller: a 0x291 naming an unknown motion mode (with its switching bit set) was
// ignored, so the controller kept driving in the previous mode while the chassis switched.
TEST(HardeningRegressions, UnknownMotionModeFeedbackStopsMotion) {
  test::FakeBus bus;
  ChassisController ctl(bus);
  Timestamp now{1s};
  auto feed = [&](std::uint32_t id, std::uint8_t dlc, std::array<std::uint8_t, 8> data) {
    CanFrame f;
    f.id = id;
    f.dlc = dlc;
    f.data = data;
    f.stamp = now;
    ctl.on_frame(f, now);
  };
  auto status_can_mode = [&] { feed(protocol::kSystemStatusId, 8, {0, 1, 1, 0xE0, 0, 0, 0, 0}); };
  status_can_mode();
  feed(protocol::kMotionModeFeedbackId, 2, {0x00, 0x00});
  ASSERT_TRUE(ctl.set_command(BodyTwist{0.5, 0, 0}, now).ok());
  for (int i = 0; i < 40; ++i) {
    now += 5ms;
    if (i % 4 == 0) status_can_mode();
    ctl.tick(now);
  }
  ASSERT_EQ(ctl.state().refusal, MotionRefusal::kNone);

  feed(protocol::kMotionModeFeedbackId, 2, {0xE0, 0x61});  // unknown mode, switching
  bus.clear_sent();
  for (int i = 0; i < 40; ++i) {
    now += 5ms;
    if (i % 4 == 0) status_can_mode();
    ASSERT_TRUE(ctl.set_command(BodyTwist{0.5, 0, 0}, now).ok());
    ctl.tick(now);
  }
  EXPECT_EQ(ctl.state().refusal, MotionRefusal::kModeUnknown);
  EXPECT_FALSE(ctl.state().motion_mode.has_value());
  EXPECT_TRUE(ctl.state().chassis_switching);
  const auto commands = bus.sent_with_id(protocol::kMotionCommandId);
  ASSERT_FALSE(commands.empty());
  for (const CanFrame& f : commands) {
    const auto m = decode(f);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(std::get<MotionCommand>(*m).linear_speed, 0.0);
  }

  // A known mode again: driving resumes.
  feed(protocol::kMotionModeFeedbackId, 2, {0x00, 0x00});
  now += 5ms;
  ASSERT_TRUE(ctl.set_command(BodyTwist{0.5, 0, 0}, now).ok());
  ctl.tick(now);
  EXPECT_EQ(ctl.state().refusal, MotionRefusal::kNone);
}

// fuzz_odometry: a corrupt 0x221 reporting a steering angle of 90 deg or more in Ackermann mode
// made the curvature infinite and the twist (and from then on the pose) NaN.
TEST(HardeningRegressions, AckermannSteeringOfNinetyDegreesOrMoreGivesAFiniteTwist) {
  const VehicleGeometry g;
  for (const double deg : {90.0, -90.0, 120.0, -295.56, 327.67}) {
    MotionFeedback fb;
    fb.speed = -0.193;
    fb.steering_angle = deg * M_PI / 180.0;
    const BodyTwist t = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g);
    EXPECT_TRUE(std::isfinite(t.vx) && std::isfinite(t.vy) && std::isfinite(t.wz)) << deg;
    // The limit of a tightening turn: a rotation about the body centre at the wheels' speed.
    EXPECT_EQ(t.vx, 0.0) << deg;
    EXPECT_NEAR(std::abs(t.wz), 0.193 / std::hypot(g.wheelbase / 2, g.track / 2), 1e-12) << deg;
  }
  // And just below 90 deg the formula approaches that limit continuously.
  MotionFeedback fb;
  fb.speed = -0.193;
  fb.steering_angle = -89.99 * M_PI / 180.0;
  const BodyTwist near = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g);
  fb.steering_angle = -90.0 * M_PI / 180.0;
  const BodyTwist at = twist_from_motion_feedback(fb, protocol::MotionMode::kAckermann, g);
  EXPECT_NEAR(near.wz, at.wz, 1e-3);
  EXPECT_NEAR(near.vx, at.vx, 1e-3);
}

}  // namespace
}  // namespace ranger
