// The adversarial trial (issue 28) as lock-step tests: the driver runtime (protocol auto, as the
// node runs it) against the virtual chassis on the manual's reading (`sim`), the vendor's
// (`sim:agx_v2`) and the manual's with the field's report of a mode switch (`sim:field_switch`:
// the mode-switch thrash on both reports), each attack judged by the chassis's ground truth, never
// by a log line:
//  * after an e-stop, a remote takeover and link loss, a zero twist and then 0.5 m/s for 4 s move
//    nothing; resume drives;
//  * NaN and infinities in every one of the twist's six components move nothing and are named
//    (MotionRefusal::kInvalidCommand) while they last;
//  * 1 kHz sign flips, two publishers fighting, motion-mode thrash every 100 ms for 20 s;
//  * bad requests change nothing; a huge rotation at standstill is named a saturated rotation;
//  * odometry across a silence while driving, straight and on an arc: the gap is said and the
//    covariance holds the ground truth.
// No threads, no sleeping: 1 ms steps of a ManualClock.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "support/identify_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;
using test::IdentifyRig;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// A switch starts once every wheel is slower than this (ControllerConfig::standstill_speed).
const double kStandstill = ControllerConfig{}.standstill_speed;

class Adversarial : public ::testing::TestWithParam<const char*> {
 protected:
  // A rig on the parameter's chassis, the driver as the node runs it (protocol auto), ready.
  static std::unique_ptr<IdentifyRig> ready_rig() {
    auto rig = std::make_unique<IdentifyRig>(GetParam(), test::auto_config());
    EXPECT_TRUE(rig->wait_ready()) << to_string(rig->snapshot()->controller.refusal);
    return rig;
  }
  static std::size_t sent_with_id(const IdentifyRig& rig, std::uint32_t id, std::size_t from = 0) {
    std::size_t n = 0;
    for (std::size_t i = from; i < rig.sent().size(); ++i)
      n += rig.sent()[i].sent.frame.id == id ? 1 : 0;
    return n;
  }
  static RequestOutcome outcome(IdentifyRig& rig, std::uint64_t id) {
    rig.run_until(
        [&] {
          const RequestOutcome* r = rig.snapshot()->request(id);
          return r && (r->state == RequestOutcome::State::kAnswered ||
                       r->state == RequestOutcome::State::kFailed);
        },
        3s);
    const RequestOutcome* r = rig.snapshot()->request(id);
    return r ? *r : RequestOutcome{};
  }
  static double moved(const Pose2D& a, const Pose2D& b) { return std::hypot(a.x - b.x, a.y - b.y); }
};

// The ground truth of a chassis asked only to go forward (and to turn): the worst backwards and
// sideways speed seen, and whether it ever rolled (faster than the standstill a switch waits for)
// while switching mode.
struct ForwardOnly {
  double backwards = 0.0;
  double sideways = 0.0;
  bool rolled_while_switching = false;
  void watch(const sim::ChassisSnapshot& t) {
    backwards = std::max(backwards, -t.twist.vx);
    sideways = std::max(sideways, std::fabs(t.twist.vy));
    rolled_while_switching |= t.switching && t.speed > kStandstill;
  }
  void expect_held() const {
    EXPECT_LE(backwards, 1e-6);
    EXPECT_LE(sideways, 1e-6);
    EXPECT_FALSE(rolled_while_switching);
  }
};

// An involuntary stop, how it ends on the chassis, and the cause the driver latches.
struct Stop {
  const char* cause;
  std::function<void(sim::VirtualChassis&)> begin;
  std::function<void(sim::VirtualChassis&)> end;
};

TEST_P(Adversarial, AfterAStopAZeroTwistAndFourSecondsOfMotionMoveNothingUntilResume) {
  const Stop stops[] = {
      {"emergency_stop", [](sim::VirtualChassis& c) { c.set_emergency_stop(true); },
       [](sim::VirtualChassis& c) { c.set_emergency_stop(false); }},
      {"remote", [](sim::VirtualChassis& c) { c.remote_takeover(); },
       [](sim::VirtualChassis& c) { c.remote_hand_back(); }},  // SWB up: CAN mode again
      {"link_lost", [](sim::VirtualChassis& c) { c.set_silent(true); },
       [](sim::VirtualChassis& c) { c.set_silent(false); }},
  };
  for (const Stop& stop : stops) {
    SCOPED_TRACE(stop.cause);
    auto rig = ready_rig();
    rig->drive({0.5, 0, 0}, std::nullopt, 2s);
    ASSERT_GT(rig->chassis().speed, 0.4);
    rig->sim().with_chassis([&](sim::VirtualChassis& c) { return stop.begin(c), 0; });
    rig->drive({0.5, 0, 0}, std::nullopt, 1s);  // the commander does not notice
    ASSERT_TRUE(rig->run_until([&] { return rig->chassis().speed == 0.0; }, 2s));
    rig->sim().with_chassis([&](sim::VirtualChassis& c) { return stop.end(c), 0; });
    rig->drive({0.5, 0, 0}, std::nullopt, 1s);
    ASSERT_EQ(rig->snapshot()->controller.refusal, MotionRefusal::kRearmRequired);
    EXPECT_NE(describe(rig->snapshot()->controller.latched_causes).find(stop.cause),
              std::string::npos);

    // A zero twist (what a navigation stack publishes at a goal), then 0.5 m/s for 4 s.
    rig->drive({}, std::nullopt, 200ms);
    const Pose2D at = rig->chassis().pose;
    double fastest = 0.0;
    rig->drive({0.5, 0, 0}, std::nullopt, 4s,
               [&] { fastest = std::max(fastest, std::fabs(rig->chassis().speed)); });
    EXPECT_EQ(fastest, 0.0) << "moved without resume";
    EXPECT_EQ(moved(rig->chassis().pose, at), 0.0);
    EXPECT_EQ(rig->snapshot()->controller.refusal, MotionRefusal::kRearmRequired);

    // resume: the twist that keeps coming drives.
    EXPECT_EQ(outcome(*rig, rig->driver().resume()).state, RequestOutcome::State::kAnswered);
    rig->drive({0.5, 0, 0}, std::nullopt, 2s);
    EXPECT_GT(rig->chassis().speed, 0.4);
    EXPECT_GT(moved(rig->chassis().pose, at), 0.3);
  }
}

TEST_P(Adversarial, NaNOrInfinityInAnyOfTheSixComponentsMovesNothingAndIsNamedWhileItLasts) {
  auto rig = ready_rig();
  const char* const names[] = {"linear.x",  "linear.y",  "linear.z",
                               "angular.x", "angular.y", "angular.z"};
  for (int field = 0; field < 6; ++field) {
    for (const double bad : {kNaN, kInf, -kInf}) {
      // {linear: {x: 0.3}} with the bad value in one component ({x: 0.3, z: .nan} and the like).
      double v[6] = {0.3, 0, 0, 0, 0, 0};
      v[field] = bad;
      const MotionRequest request{BodyTwist{v[0], v[1], v[5]}, std::nullopt,
                                  OutOfPlaneTwist{v[2], v[3], v[4]}};
      const std::string named =
          std::string(names[field]) + (std::isnan(bad) ? " is NaN" : " is infinite");
      SCOPED_TRACE(named);
      EXPECT_EQ(rig->driver().command(request).error().code, Errc::kNotFinite);
      const Pose2D at = rig->chassis().pose;
      int named_steps = 0, steps = 0;
      rig->command(request);  // a stream, every 50 ms, for 1 s
      rig->run_for(1ms);
      const Timestamp end = rig->clock().now() + 1s;
      while (rig->clock().now() < end) {
        rig->step();
        ++steps;
        const auto snap = rig->snapshot();
        const ControllerState& c = snap->controller;
        if (c.refusal == MotionRefusal::kInvalidCommand && c.invalid_command == named) {
          ++named_steps;
        }
        ASSERT_EQ(rig->chassis().speed, 0.0);
      }
      EXPECT_EQ(named_steps, steps) << "named for as long as it lasts";
      EXPECT_EQ(moved(rig->chassis().pose, at), 0.0);
      // The commander's next valid twist ends it (its own mistake: no re-arm).
      rig->drive({}, std::nullopt, 100ms);
      EXPECT_EQ(rig->snapshot()->controller.refusal, MotionRefusal::kNone);
    }
  }
  rig->drive({0.3, 0, 0}, std::nullopt, 2s);
  EXPECT_NEAR(rig->chassis().speed, 0.3, 0.01);
}

TEST_P(Adversarial, SignFlipsAtOneKilohertzGoNowhereAndTheBusLoadStaysBounded) {
  auto rig = ready_rig();
  rig->silence();
  const Pose2D at = rig->chassis().pose;
  const std::size_t sent_before = rig->sent().size();
  double fastest = 0.0;
  for (int ms = 0; ms < 3000; ++ms) {
    ASSERT_TRUE(rig->driver().command(MotionRequest{BodyTwist{ms % 2 ? 0.5 : -0.5, 0, 0}}).ok());
    rig->step();
    fastest = std::max(fastest, std::fabs(rig->chassis().speed));
  }
  EXPECT_LE(fastest, 0.5 + 1e-9);
  EXPECT_LT(moved(rig->chassis().pose, at), 0.05);
  const auto snap = rig->snapshot();
  const ControllerState& c = snap->controller;
  EXPECT_TRUE(c.faults.empty());
  // Changed commands at most every min_command_interval, plus the keep-alive.
  EXPECT_LE(sent_with_id(*rig, protocol::kMotionCommandId, sent_before),
            3000u / 5 + 3000u / 20 + 2);
  // Still obeying: the latest command drives.
  rig->drive({0.3, 0, 0}, std::nullopt, 2s);
  EXPECT_NEAR(rig->chassis().twist.vx, 0.3, 0.01);
}

TEST_P(Adversarial, TwoPublishersFightingNeverDriveADirectionNeitherAsked) {
  auto rig = ready_rig();
  rig->silence();
  const std::size_t sent_before = rig->sent().size();
  ForwardOnly truth;
  // Forward at 20 Hz and a spin at 20 Hz, 25 ms apart, for 10 s: the latest one wins each time.
  for (int ms = 0; ms < 10000; ++ms) {
    if (ms % 50 == 0) ASSERT_TRUE(rig->driver().command(MotionRequest{BodyTwist{0.4, 0, 0}}).ok());
    if (ms % 50 == 25) ASSERT_TRUE(rig->driver().command(MotionRequest{BodyTwist{0, 0, 0.5}}).ok());
    rig->step();
    truth.watch(rig->chassis());
  }
  truth.expect_held();
  EXPECT_TRUE(rig->snapshot()->controller.faults.empty());
  // The selector's dwell bounds the mode switches (min_dwell 1 s).
  EXPECT_LE(sent_with_id(*rig, protocol::kMotionModeCommandId, sent_before), 11u);
  rig->drive({0.3, 0, 0}, std::nullopt, 3s);
  EXPECT_NEAR(rig->chassis().twist.vx, 0.3, 0.01);
}

TEST_P(Adversarial, ModeThrashEveryHundredMillisecondsNeverDrivesWhileSwitching) {
  auto rig = ready_rig();
  rig->command({0.3, 0, 0});
  const std::size_t sent_before = rig->sent().size();
  ForwardOnly truth;
  for (int i = 0; i < 200; ++i) {  // 20 s
    ASSERT_TRUE(
        rig->driver().set_motion_mode(i % 2 ? MotionMode::kOblique : MotionMode::kAckermann).ok());
    for (int ms = 0; ms < 100; ++ms) {
      rig->step();
      truth.watch(rig->chassis());
    }
  }
  truth.expect_held();
  EXPECT_TRUE(rig->snapshot()->controller.faults.empty());
  EXPECT_GT(sent_with_id(*rig, protocol::kMotionModeCommandId, sent_before), 20u)
      << "the thrash did reach the chassis";
  ASSERT_TRUE(rig->driver().set_motion_mode(std::nullopt).ok());
  rig->drive({0.3, 0, 0}, std::nullopt, 3s);
  EXPECT_NEAR(rig->chassis().twist.vx, 0.3, 0.01);
}

TEST_P(Adversarial, BadRequestsAreRefusedByNameAndChangeNothing) {
  auto rig = ready_rig();
  // The manual's reading (sim:field_switch differs in its report of a switch only).
  const bool manual = std::string(GetParam()) != "sim:agx_v2";
  const Pose2D at = rig->chassis().pose;
  const std::size_t sent_before = rig->sent().size();
  EXPECT_EQ(rig->driver().clear_errors(0x11).error().code, Errc::kInvalidArgument);
  EXPECT_EQ(rig->driver().clear_errors(0xFF).error().code, Errc::kInvalidArgument);
  EXPECT_FALSE(rig->driver().set_lights(LightsRequest{protocol::LightMode::kCustom, 101}).ok());
  EXPECT_FALSE(rig->driver().set_motion_mode(MotionMode::kPark).ok());
  const Status side_slip = rig->driver().set_motion_mode(MotionMode::kSideSlip);
  EXPECT_EQ(side_slip.ok(), !manual);
  if (manual) {
    EXPECT_EQ(side_slip.error().message,
              "side_slip: unsupported by protocol manual (it drives ackermann, oblique, spin)");
  } else {
    ASSERT_TRUE(rig->driver().set_motion_mode(std::nullopt).ok());
  }
  // Park where there is none: refused, releasing it too (never answered with success).
  for (const bool on : {true, false}) {
    const RequestOutcome r = outcome(*rig, rig->driver().set_park(on));
    if (manual) {
      EXPECT_EQ(r.state, RequestOutcome::State::kFailed) << r.message;
      EXPECT_NE(r.message.find("park: unsupported by protocol manual"), std::string::npos);
    }
  }
  rig->run_for(500ms);
  if (manual) {
    for (std::size_t i = sent_before; i < rig->sent().size(); ++i) {
      EXPECT_EQ(rig->sent()[i].sent.frame.id, protocol::kMotionCommandId)
          << "a refused request sent something";
    }
  }
  EXPECT_EQ(moved(rig->chassis().pose, at), 0.0);
  rig->drive({0.3, 0, 0}, std::nullopt, 2s);
  EXPECT_NEAR(rig->chassis().twist.vx, 0.3, 0.01);
}

// 1e6 rad/s at standstill: a saturated rotation (spin at its limit), never "translation dropped"
// or "rotation dropped" on its way from Ackermann to spin.
TEST_P(Adversarial, AHugeRotationAtStandstillIsNamedASaturatedRotation) {
  auto rig = ready_rig();
  std::uint32_t seen = 0;
  rig->drive({0, 0, 1e6}, std::nullopt, 3s,
             [&] { seen |= rig->snapshot()->controller.adjustments; });
  EXPECT_EQ(seen & (kTranslationDropped | kRotationDropped | kLateralDropped), 0u)
      << kinematics_flags_to_string(seen);
  const auto snap = rig->snapshot();
  const ControllerState& c = snap->controller;
  EXPECT_EQ(c.adjustments, static_cast<std::uint32_t>(kSpinSaturated));
  ASSERT_TRUE(c.last_solution);
  const std::string words =
      describe_adjustments(c.adjustments, c.requested.twist, c.last_solution->achieved);
  EXPECT_EQ(words.find("spin_saturated: asked (vx, vy, wz) = (0 m/s, 0 m/s, 1e+06 rad/s)"), 0u)
      << words;
  EXPECT_GT(std::fabs(rig->chassis().twist.wz), 0.5);
  EXPECT_LT(rig->chassis().speed, 1.6);
  // Stopped: nothing is adjusted any more.
  rig->drive({}, std::nullopt, 2s);
  EXPECT_EQ(rig->snapshot()->controller.adjustments, 0u);
}

// Silent for 2 s while driving (straight, and on an arc): the odometry says how long the gap was
// and its covariance holds the ground truth (within 3 standard deviations), although the pose
// itself could not follow the chassis through the gap.
TEST_P(Adversarial, OdometryAcrossASilenceSaysTheGapAndItsCovarianceHoldsTheTruth) {
  for (const BodyTwist twist : {BodyTwist{0.5, 0, 0}, BodyTwist{0.5, 0, 0.3}}) {
    SCOPED_TRACE(twist.wz == 0.0 ? "straight" : "arc");
    auto rig = ready_rig();
    rig->drive(twist, std::nullopt, 3s);
    const auto before = rig->snapshot()->odometry;
    EXPECT_EQ(before.gaps, 0u);
    EXPECT_LT(before.pose_variance[0], 0.01);
    rig->sim().with_chassis([](sim::VirtualChassis& c) { return c.silence_for(2s), 0; });
    rig->drive(twist, std::nullopt, 2s);
    ASSERT_TRUE(rig->run_until([&] { return rig->snapshot()->motion_known; }, 1s));
    rig->run_for(100ms);
    const auto s = rig->snapshot();
    const OdometryState& o = s->odometry;
    EXPECT_EQ(o.gaps, 1u);
    EXPECT_NEAR(seconds(o.last_gap), 2.0, 0.05);
    EXPECT_GT(o.last_gap_end, Timestamp{0});
    // What the chassis could have moved in the gap: its limits times the gap.
    const double reach = KinematicsLimits{}.max_linear_speed * seconds(o.last_gap);
    EXPECT_GE(o.pose_variance[0], before.pose_variance[0] + reach * reach - 1e-9);
    EXPECT_GE(o.pose_variance[1], before.pose_variance[1] + reach * reach - 1e-9);
    EXPECT_GT(o.pose_variance[2], before.pose_variance[2]);
    const Pose2D truth = rig->chassis().pose;
    const double dx = truth.x - o.pose.x, dy = truth.y - o.pose.y;
    EXPECT_GT(std::hypot(dx, dy), 0.01) << "the pose missed the coasting in the gap";
    EXPECT_LE(std::fabs(dx), 3.0 * std::sqrt(o.pose_variance[0]));
    EXPECT_LE(std::fabs(dy), 3.0 * std::sqrt(o.pose_variance[1]));
    EXPECT_LE(std::fabs(std::remainder(truth.yaw - o.pose.yaw, 2 * M_PI)),
              3.0 * std::sqrt(o.pose_variance[2]));
  }
}

// The RANGER MINI 3.0 counts its wheels' distance itself (0x311/0x312, mm): what it counted across
// the silence is added along the path the driver's commands in it make (the wheels turning toward
// the commanded angle at the chassis's steering rate, the field's 3.26 rad/s), so the pose follows
// the chassis through the gap (straight and on an arc) instead of missing its coasting; the gap is
// said as on the others.
TEST(AdversarialMiniV3, TheChassissOwnOdometerCarriesThePoseThroughASilence) {
  for (const BodyTwist twist : {BodyTwist{0.5, 0, 0}, BodyTwist{0.5, 0, 0.3}}) {
    SCOPED_TRACE(twist.wz == 0.0 ? "straight" : "arc");
    DriverConfig config = test::auto_config();
    const ModelPreset model = *model_preset("ranger_mini_v3");
    config.controller.geometry = model.geometry;
    config.controller.limits = model.limits;
    IdentifyRig rig("sim:mini_v3", config);
    ASSERT_TRUE(rig.wait_ready()) << to_string(rig.snapshot()->controller.refusal);
    rig.drive(twist, std::nullopt, 3s);
    const Pose2D truth_before = rig.chassis().pose;
    rig.sim().with_chassis([](sim::VirtualChassis& c) { return c.silence_for(2s), 0; });
    rig.drive(twist, std::nullopt, 2s);
    ASSERT_TRUE(rig.run_until([&] { return rig.snapshot()->motion_known; }, 1s));
    rig.run_for(100ms);
    const OdometryState o = rig.snapshot()->odometry;
    EXPECT_EQ(o.gaps, 1u);
    EXPECT_NEAR(seconds(o.last_gap), 2.0, 0.05);
    const Pose2D truth = rig.chassis().pose;
    const double coasted = std::hypot(truth.x - truth_before.x, truth.y - truth_before.y);
    EXPECT_GT(coasted, 0.05) << "the chassis rolled on in the silence";
    EXPECT_NEAR(o.last_gap_odometer_distance, coasted, 0.25 * coasted);
    const double position_error = std::hypot(truth.x - o.pose.x, truth.y - o.pose.y);
    const double yaw_error = std::fabs(std::remainder(truth.yaw - o.pose.yaw, 2 * M_PI));
    std::printf("[silence] %s coasted %.3f m: position off %.4f m, yaw off %.4f rad\n",
                twist.wz == 0.0 ? "straight" : "arc", coasted, position_error, yaw_error);
    EXPECT_LE(position_error, 0.03) << "the pose follows the truth through the gap";
    // The driver's gap model turns the wheels toward what it commanded in the silence (its stop)
    // at the chassis's steering rate: 0.005 rad off on the arc, where the last curve carried
    // through the gap is 0.026 off (0.034 at a pure 3.26 rad/s).
    EXPECT_LE(yaw_error, 0.015);
  }
}

INSTANTIATE_TEST_SUITE_P(Chassis, Adversarial,
                         ::testing::Values("sim", "sim:agx_v2", "sim:field_switch"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           const std::string spec = info.param;
                           return spec == "sim" ? std::string("manual") : spec.substr(4);
                         });

}  // namespace
}  // namespace ranger
