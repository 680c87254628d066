// The plausibility monitors (control/plausibility.hpp): their decisions as values (the pure
// judge_* functions), and the driver in lock-step with the virtual chassis under a ManualClock —
// right settings never trip over long drives in every mode, each wrong forced setting is caught
// and the robot stopped within a bounded distance (each distance printed as "[stop] ..."), and
// resume clears a stop that trips again while the mismatch persists.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "support/identify_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;
using test::IdentifyRig;
using test::preset;

// ---- the plausibility monitors' decisions, as values -------------------------------------------

TEST(PlausibilityJudgement, SteeringNamesTheSettingTheWitnessesPointAt) {
  const double r = PlausibilityConfig{}.unit_ratio;
  EXPECT_EQ(judge_steering(1.0, 1.0, r).mismatch, SteeringMismatch::kNone);
  EXPECT_EQ(judge_steering(1.0, std::nullopt, r).mismatch, SteeringMismatch::kNone);
  EXPECT_EQ(judge_steering(-1.0, -1.0, r).mismatch, SteeringMismatch::kSign111);
  EXPECT_EQ(judge_steering(-1.0, 1.0, r).mismatch, SteeringMismatch::kSign271);
  EXPECT_EQ(judge_steering(-1.0, std::nullopt, r).mismatch, SteeringMismatch::kSign111Or271);
  const SteeringJudgement more = judge_steering(5.7, 5.7, r);
  EXPECT_EQ(more.mismatch, SteeringMismatch::kUnit111);
  EXPECT_TRUE(more.more);
  const SteeringJudgement less = judge_steering(1 / 5.7, 1.0, r);
  EXPECT_EQ(less.mismatch, SteeringMismatch::kUnit271);
  EXPECT_FALSE(less.more);
  EXPECT_EQ(judge_steering(5.7, std::nullopt, r).mismatch, SteeringMismatch::kUnit111Or271);
  EXPECT_EQ(judge_steering(1.0, -1.0, r).mismatch, SteeringMismatch::kSign221);
  EXPECT_EQ(judge_steering(1.0, 5.7, r).mismatch, SteeringMismatch::kUnit221);
}

TEST(PlausibilityJudgement, ReferenceAndSpeedNameTheOtherReadingOnlyWhenItFitsClearly) {
  const double d = M_PI / 180.0;
  const std::array<double, kWheelCount> ours{10 * d, 8 * d, 8 * d, 10 * d};
  const std::array<double, kWheelCount> other{10.6 * d, 8.5 * d, 8.5 * d, 10.6 * d};
  EXPECT_FALSE(judge_reference(ours, ours, other).other_fits);
  const ReferenceJudgement j = judge_reference(other, ours, other);
  EXPECT_TRUE(j.other_fits);
  EXPECT_NEAR(j.error, 0.6 * d, 1e-9);
  EXPECT_NEAR(j.error_other, 0.0, 1e-12);
  // 0x221 reporting the body centre's 0.50 m/s where the wheels' mean is 0.52 m/s.
  EXPECT_TRUE(judge_feedback_speed(0.50, 0.52, 0.50, FeedbackSpeed::kMeanWheel).other_fits);
  EXPECT_FALSE(judge_feedback_speed(0.50, 0.52, 0.50, FeedbackSpeed::kBodyCentre).other_fits);
  EXPECT_FALSE(judge_feedback_speed(0.52, 0.52, 0.50, FeedbackSpeed::kMeanWheel).other_fits);
}

TEST(PlausibilityJudgement, FreshnessIsOneValidatedSetting) {
  PlausibilityConfig c;
  EXPECT_EQ(c.feedback_freshness, std::chrono::milliseconds(100));
  EXPECT_TRUE(c.validate().ok());
  c.feedback_freshness = std::chrono::nanoseconds(0);
  EXPECT_FALSE(c.validate().ok());
}

// ---- the monitors ----------------------------------------------------------------------------

TEST(Plausibility, RightSettingsNeverTripOverALongDriveInEveryMode) {
  IdentifyRig rig("sim", test::forced_config(preset("manual")));
  ASSERT_TRUE(rig.wait_ready());
  const struct {
    BodyTwist twist;
    std::optional<MotionMode> mode;
    std::chrono::seconds d;
  } legs[] = {
      {{0.8, 0.0, 0.3}, MotionMode::kAckermann, 12s},
      {{1.2, 0.0, -0.6}, MotionMode::kAckermann, 6s},
      {{-0.5, 0.0, 0.25}, MotionMode::kAckermann, 6s},
      {{0.6, 0.0, 0.0}, std::nullopt, 4s},
      {{0.3, 0.4, 0.0}, MotionMode::kOblique, 8s},
      {{0.5, -0.2, 0.0}, MotionMode::kOblique, 5s},
      {{0.0, 0.0, 0.9}, MotionMode::kSpin, 8s},
      {{0.0, 0.0, -0.6}, MotionMode::kSpin, 5s},
      {{0.4, 0.0, 0.5}, std::nullopt, 8s},
      {{0.0, 0.0, 0.0}, std::nullopt, 2s},
      {{0.8, 0.0, 0.8}, MotionMode::kAckermann, 6s},
      {{0.2, 0.0, -0.3}, std::nullopt, 6s},
  };
  std::size_t warned = 0;
  for (const auto& leg : legs) {
    rig.drive(leg.twist, leg.mode, leg.d,
              [&] { warned += rig.snapshot()->plausibility.warnings.size(); });
  }
  const auto s = rig.snapshot();
  EXPECT_FALSE(s->plausibility.stop) << s->plausibility.stop->text();
  EXPECT_EQ(warned, 0u);
  EXPECT_GT(s->plausibility.checks, 1000u) << "the monitors did judge";
  EXPECT_GT(rig.chassis().distance_travelled, 20.0);
}

struct WrongSetting {
  const char* name;
  std::function<void(ProtocolProfile&)> change;
  std::string expect_setting;  // in the stop reason
  BodyTwist twist;
  std::optional<MotionMode> mode;
  double max_distance;  // m the robot may roll before it stops
};

void expect_caught(const WrongSetting& w) {
  SCOPED_TRACE(w.name);
  ProtocolProfile p = preset("manual");
  w.change(p);
  IdentifyRig rig("sim", test::forced_config(p));
  ASSERT_TRUE(rig.wait_ready(true));
  const bool stopped = rig.drive_until_stopped(w.twist, w.mode, 20s);
  const auto s = rig.snapshot();
  ASSERT_TRUE(stopped) << "never stopped; refusal " << to_string(s->controller.refusal);
  EXPECT_EQ(s->controller.refusal, MotionRefusal::kImplausible);
  EXPECT_NE(s->controller.implausible_reason.find(w.expect_setting), std::string::npos)
      << s->controller.implausible_reason;
  rig.run_for(2s);
  const double distance = rig.chassis().distance_travelled;
  const double turned = rig.chassis().yaw_travelled * 180.0 / M_PI;
  std::printf("[stop] wrong=%s distance=%.3f m turned=%.1f deg caught_after=%.2f s reason=%s\n",
              w.name, distance, turned, seconds(rig.stopped_after()),
              s->controller.implausible_reason.c_str());
  EXPECT_LE(distance, w.max_distance);
  EXPECT_EQ(rig.chassis().speed, 0.0) << "at rest after the stop";
  ::testing::Test::RecordProperty("stop_distance_m", std::to_string(distance));
}

TEST(Plausibility, AReversedSteeringSignIsCaughtBeforeItRolls) {
  expect_caught({"steering_sign_111",
                 [](ProtocolProfile& p) { p.steering_sign_111 = SteeringSign::kLeftPositive; },
                 "steering_sign_111",
                 {0.6, 0.0, 0.3},
                 MotionMode::kAckermann,
                 0.05});
}

TEST(Plausibility, AWrongSteeringUnitIsCaughtBeforeItRolls) {
  expect_caught({"steering_unit_111",
                 [](ProtocolProfile& p) { p.steering_unit_111 = AngleUnit::kMilliradian; },
                 "steering_unit_111",
                 {0.6, 0.0, 0.3},
                 MotionMode::kAckermann,
                 1.0});
}

TEST(Plausibility, AWrongWheelAngleSignIsCaught) {
  expect_caught({"steering_sign_271",
                 [](ProtocolProfile& p) { p.steering_sign_271 = SteeringSign::kLeftPositive; },
                 "steering_sign_271",
                 {0.6, 0.0, 0.3},
                 MotionMode::kAckermann,
                 0.05});
}

TEST(Plausibility, TheWrongSteeringReferenceIsCaught) {
  expect_caught({"steering_reference",
                 [](ProtocolProfile& p) { p.steering_reference = SteeringReference::kInnerFront; },
                 "steering_reference",
                 {0.6, 0.0, 0.4},
                 MotionMode::kAckermann,
                 3.0});
}

TEST(Plausibility, AWrongSpeedReadingIsCaught) {
  expect_caught({"feedback_speed",
                 [](ProtocolProfile& p) { p.feedback_speed = FeedbackSpeed::kBodyCentre; },
                 "feedback_speed",
                 {0.8, 0.0, 0.6},
                 MotionMode::kAckermann,
                 4.0});
}

TEST(Plausibility, AReversedSpinSignIsCaught) {
  expect_caught({"spin_sign",
                 [](ProtocolProfile& p) { p.spin_sign = -1; },
                 "spin_sign",
                 {0.0, 0.0, 0.6},
                 MotionMode::kSpin,
                 0.05});
}

TEST(Plausibility, TheWrongSpinFieldIsCaught) {
  expect_caught({"spin_field",
                 [](ProtocolProfile& p) { p.spin_field = SpinField::kYawRate; },
                 "spin_field",
                 {0.0, 0.0, 0.6},
                 MotionMode::kSpin,
                 0.05});
}

TEST(Plausibility, AnAgxDriverOnAManualChassisIsCaught) {
  expect_caught({"agx_v2 on manual",
                 [](ProtocolProfile& p) { p = preset("agx_v2"); },
                 "steering_unit_271 and steering_sign_271",
                 {0.6, 0.0, 0.3},
                 MotionMode::kAckermann,
                 1.0});
}

TEST(Plausibility, ResumeClearsTheStopAndTheMonitorTripsAgain) {
  ProtocolProfile p = preset("manual");
  p.steering_sign_111 = SteeringSign::kLeftPositive;
  IdentifyRig rig("sim", test::forced_config(p));
  ASSERT_TRUE(rig.wait_ready(true));
  ASSERT_TRUE(rig.drive_until_stopped({0.6, 0.0, 0.3}, MotionMode::kAckermann, 20s));
  rig.command({0.0, 0.0, 0.0});
  rig.run_for(200ms);
  EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kImplausible)
      << "a zero twist does not re-arm a contradicted setting";
  rig.driver().resume();
  rig.run_for(50ms);
  EXPECT_NE(rig.snapshot()->controller.refusal, MotionRefusal::kImplausible);
  EXPECT_FALSE(rig.snapshot()->plausibility.stop);
  ASSERT_TRUE(rig.drive_until_stopped({0.6, 0.0, 0.3}, MotionMode::kAckermann, 20s));
  EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kImplausible);
}

TEST(Plausibility, AManualDriverOnAnAgxChassisIsCaught) {
  const auto& names = sim::variant_names();
  ASSERT_NE(std::find(names.begin(), names.end(), "agx_v2"), names.end())
      << "sim:agx_v2 is no variant of the library";
  IdentifyRig rig("sim:agx_v2", test::forced_config(preset("manual")));
  rig.command({0.6, 0.0, 0.3}, MotionMode::kAckermann);
  const Timestamp began = rig.clock().now();
  ASSERT_TRUE(
      rig.run_until([&] { return !rig.snapshot()->controller.implausible_reason.empty(); }, 10s));
  const std::string reason = rig.snapshot()->controller.implausible_reason;
  const double after = seconds(rig.clock().now() - began);
  rig.run_for(2s);
  const double distance = rig.chassis().distance_travelled;
  std::printf("[stop] wrong=manual_on_agx_v2 distance=%.3f m caught_after=%.2f s reason=%s\n",
              distance, after, reason.c_str());
  EXPECT_NE(reason.find("error_word: try agx16"), std::string::npos) << reason;
  EXPECT_NE(rig.snapshot()->controller.refusal, MotionRefusal::kNone);
  EXPECT_LE(distance, 0.05);
  EXPECT_EQ(rig.chassis().speed, 0.0);
}

}  // namespace
}  // namespace ranger
