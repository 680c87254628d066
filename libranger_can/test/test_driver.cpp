// The driver runtime in lock-step with the virtual chassis (sim::SimBusSource, lock_step) under a
// ManualClock: the mailbox, the snapshot, the sent-frame events (the shutdown stop included),
// request outcomes, "motion known" only while the chassis is heard, and the bus sources
// (replay:FILE, a missing interface); every motion mode on either report of a switch (the
// manual's, the field's). No threads of the driver's, no sleeping.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "support/driver_sim_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

// The shared lock-step rig (support/driver_sim_rig.hpp) on the plain `sim`; the commander's every
// command is accepted.
class DriverRig : public test::DriverSimRig {
 public:
  explicit DriverRig(const DriverConfig& config = {},
                     test::SwitchReportUnderTest report = test::SwitchReportUnderTest::kVariants)
      : DriverSimRig("manual", config, {}, report) {}
  void drive(const BodyTwist& twist, std::chrono::nanoseconds d) {
    EXPECT_EQ(DriverSimRig::drive(twist, d), 0) << "a command refused";
  }
};

bool ready(const DriverSnapshot& s) {
  return s.controller.control_mode == protocol::ControlMode::kCan && s.controller.motion_mode &&
         s.controller.refusal == MotionRefusal::kNone;
}

// Every motion mode by the twist, on either report of a switch (the manual's and the field's,
// test::kBothSwitchReports): each switch completes and the chassis obeys again, nothing refused,
// the chassis ends in the mode the twist asks for and moves.
class DriverModeSwitch : public ::testing::TestWithParam<test::SwitchReportUnderTest> {};

TEST_P(DriverModeSwitch, EveryModeByTheTwistOnEitherReport) {
  DriverRig rig({}, GetParam());
  ASSERT_TRUE(rig.ready());
  const struct {
    BodyTwist twist;
    protocol::MotionMode mode;
  } legs[] = {{{0.4, 0.0, 0.2}, protocol::MotionMode::kAckermann},
              {{0.2, 0.2, 0.0}, protocol::MotionMode::kOblique},
              {{0.0, 0.0, 0.5}, protocol::MotionMode::kSpin},
              {{0.4, 0.0, 0.0}, protocol::MotionMode::kAckermann}};
  for (const auto& leg : legs) {
    SCOPED_TRACE(protocol::to_string(leg.mode));
    rig.drive(leg.twist, 3s);
    const sim::ChassisSnapshot c = rig.chassis();
    EXPECT_EQ(c.motion_mode, leg.mode);
    EXPECT_FALSE(c.switching);
    EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kNone);
    EXPECT_GT(std::hypot(c.twist.vx, c.twist.vy) + std::fabs(c.twist.wz), 0.15) << "it moves";
  }
}

INSTANTIATE_TEST_SUITE_P(Reports, DriverModeSwitch, ::testing::ValuesIn(test::kBothSwitchReports),
                         [](const ::testing::TestParamInfo<test::SwitchReportUnderTest>& info) {
                           return test::to_string(info.param);
                         });

TEST(Driver, BeforeTheFirstOpenCommandsSayWhy) {
  ManualClock clock;
  auto source = open_bus_source("nosuchcan0", clock);
  ASSERT_TRUE(source.ok());
  Driver driver(DriverConfig{}, std::move(*source), clock);
  driver.step(clock.now());
  const Status st = driver.command(MotionRequest{BodyTwist{0.2, 0, 0}, std::nullopt});
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().code, Errc::kInterfaceDown);
  EXPECT_NE(st.error().message.find("nosuchcan0"), std::string::npos) << st.error().message;
  const auto s = driver.snapshot();
  EXPECT_FALSE(s->bus_open);
  EXPECT_NE(s->bus_error.find("nosuchcan0"), std::string::npos) << s->bus_error;
  EXPECT_FALSE(s->motion_known);
  // Retried every reconnect_interval, not at every step.
  EXPECT_EQ(driver.next_due(), clock.now() + DriverConfig{}.reconnect_interval);
}

TEST(Driver, ConnectsDrivesAndPublishesWhatItKnows) {
  DriverRig rig;
  rig.step();
  EXPECT_FALSE(rig.snapshot()->motion_known) << "nothing heard yet: no odometry to publish";
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  EXPECT_TRUE(rig.snapshot()->motion_known);
  rig.drive({0.5, 0, 0}, 2s);
  const auto s = rig.snapshot();
  EXPECT_GT(s->odometry.pose.x, 0.3);
  EXPECT_NEAR(s->odometry.pose.x, rig.sim().snapshot().pose.x, 0.02);
  EXPECT_GT(s->joints.wheel_velocity[0], 0.0);
  EXPECT_GT(s->frames.rate(protocol::kSystemStatusId, s->now), 40.0);
  EXPECT_GT(s->sequence, 100u);
  // Odometry is stamped with the frames' time (the bus clock), not the time of publication.
  EXPECT_LE(s->odometry.stamp, s->now);
  EXPECT_GT(s->odometry.stamp, s->now - 40ms);
}

// Snapshots are refilled once no reader holds them: one a reader holds never changes under it,
// and a refilled one carries nothing of its earlier publication.
TEST(Driver, AHeldSnapshotNeverChangesAndARefilledOneKeepsNothingStale) {
  DriverRig rig;
  rig.step();
  const auto early = rig.snapshot();  // connected, nothing driven yet
  const std::uint64_t early_sequence = early->sequence;
  const Timestamp early_now = early->now;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.drive({0.5, 0, 0}, 1s);
  EXPECT_EQ(early->sequence, early_sequence);
  EXPECT_EQ(early->now, early_now);
  EXPECT_FALSE(early->motion_known);
  EXPECT_EQ(early->odometry.pose.x, 0.0);

  // Every step publishes a new one; consecutive ones differ by one in sequence and are current.
  for (int i = 0; i < 5; ++i) {
    rig.step();
    const auto a = rig.snapshot();
    rig.step();
    const auto b = rig.snapshot();
    EXPECT_NE(a.get(), b.get()) << "a held snapshot is not refilled";
    EXPECT_EQ(b->sequence, a->sequence + 1);
    EXPECT_EQ(b->now, rig.clock().now());
    EXPECT_GE(b->odometry.pose.x, a->odometry.pose.x);
  }
  // A request made now shows in the next snapshot, and in none published before it.
  const auto before = rig.snapshot();
  const auto id = rig.driver().clear_errors(0);
  ASSERT_TRUE(id.ok()) << id.error().message;
  EXPECT_EQ(before->request(*id), nullptr);
  rig.step();
  EXPECT_NE(rig.snapshot()->request(*id), nullptr);
  EXPECT_EQ(before->request(*id), nullptr);
}

TEST(Driver, ACommandGoesOutAtTheNextStepAndEverySendIsAnEvent) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  const std::size_t before = rig.sent().size();
  ASSERT_TRUE(rig.driver().command(MotionRequest{BodyTwist{0.4, 0, 0}, std::nullopt}).ok());
  rig.step();
  ASSERT_GT(rig.sent().size(), before);
  const SentEvent& e = rig.sent().back();
  EXPECT_EQ(e.sent.frame.id, protocol::kMotionCommandId);
  EXPECT_NEAR(e.sent.achieved.vx, 0.4, 1e-9);
  EXPECT_FALSE(e.sent.shutdown);
}

// The driver thread wakes at next_due() or for its mailbox, never for a frame: the feedback that
// arrived meanwhile is handled at the next wake-up, in one batch, at most one keep-alive period
// late; a command is sent at the wake-up right after it was posted.
TEST(Driver, FeedbackIsCoalescedIntoWakeUpsAtMostOneKeepAlivePeriodApart) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  const auto period = ControllerConfig{}.keep_alive_period;
  const Timestamp start = rig.clock().now();
  std::size_t wakeups = 0;
  while (rig.clock().now() < start + 1s) {  // as the driver thread runs
    const Timestamp due = rig.driver().next_due();
    ASSERT_LE(due - rig.clock().now(), period);
    while (rig.clock().now() < due) {  // the chassis sends its feedback meanwhile
      rig.clock().advance(1ms);
      rig.sim().step(rig.clock().now());
    }
    rig.driver().step(rig.clock().now());
    ++wakeups;
    // Everything that arrived is handled now: the estimate is as recent as the feedback.
    EXPECT_GE(rig.snapshot()->odometry.stamp, rig.clock().now() - period);
  }
  const auto s = rig.snapshot();
  EXPECT_GT(s->frames.rate(protocol::kMotionFeedbackId, s->now), 40.0);
  EXPECT_GT(s->frames.rate(protocol::kSystemStatusId, s->now), 40.0);
  EXPECT_LE(wakeups, 55u) << "one wake-up per keep-alive period, not one per frame";

  // A command does not wait for the next period: posted, it goes out at the next step.
  const std::size_t before = rig.sent().size();
  ASSERT_TRUE(rig.driver().command(MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt}).ok());
  rig.driver().step(rig.clock().now());
  ASSERT_GT(rig.sent().size(), before);
  EXPECT_EQ(rig.sent().back().sent.frame.id, protocol::kMotionCommandId);
  EXPECT_NEAR(rig.sent().back().sent.achieved.vx, 0.3, 1e-9);
}

TEST(Driver, StopSendsAZeroThatTheObserverSees) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.drive({0.6, 0, 0}, 500ms);
  rig.driver().stop();
  ASSERT_FALSE(rig.sent().empty());
  const SentEvent& last = rig.sent().back();
  EXPECT_TRUE(last.sent.shutdown);
  EXPECT_EQ(last.sent.frame.id, protocol::kMotionCommandId);
  const auto m = decode(last.sent.frame);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(std::get<MotionCommand>(*m).linear_speed, 0.0);
  EXPECT_EQ(last.sent.achieved.vx, 0.0);
  EXPECT_TRUE(rig.snapshot()->controller.shut_down);
  const std::size_t n = rig.sent().size();
  rig.driver().stop();  // idempotent
  EXPECT_EQ(rig.sent().size(), n);
}

TEST(Driver, NonFiniteCommandsAreRefusedAndStop) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.drive({0.6, 0, 0}, 500ms);
  const Status st = rig.driver().command(MotionRequest{BodyTwist{NAN, 0, 0}, std::nullopt});
  EXPECT_EQ(st.error().code, Errc::kNotFinite);
  rig.step();
  const auto m = decode(rig.sent().back().sent.frame);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(std::get<MotionCommand>(*m).linear_speed, 0.0);
}

TEST(Driver, ClearErrorsAnswersWithTheChassisErrorWordAfterItAnswered) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_error_bit(protocol::error_bit_index(6, 7), true);  // over-current
    return 0;
  });
  rig.run_for(100ms);
  ASSERT_NE(rig.snapshot()->controller.error_bits, 0u);
  EXPECT_FALSE(rig.driver().clear_errors(0x11).ok()) << "not a code";
  auto id = rig.driver().clear_errors(0x0F);
  ASSERT_TRUE(id.ok());
  rig.step();
  const RequestOutcome* r = rig.snapshot()->request(*id);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->state, RequestOutcome::State::kSent) << "the old 0x211 is no answer";
  ASSERT_TRUE(rig.run_until(
      [&] {
        const RequestOutcome* o = rig.snapshot()->request(*id);
        return o && o->state == RequestOutcome::State::kAnswered;
      },
      200ms));
  r = rig.snapshot()->request(*id);
  ASSERT_TRUE(r->error_word.has_value());
  EXPECT_EQ(*r->error_word, 0u) << "the chassis cleared it";
}

TEST(Driver, ClearErrorsWithoutAnAnswerFailsAfterTheTimeout) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_silent(true);
    return 0;
  });
  auto id = rig.driver().clear_errors(0x00);
  ASSERT_TRUE(id.ok());
  rig.run_for(600ms);
  const RequestOutcome* r = rig.snapshot()->request(*id);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->state, RequestOutcome::State::kFailed);
  EXPECT_NE(r->message.find("did not answer"), std::string::npos) << r->message;
}

TEST(Driver, ResumeIsRefusedWhileTheEstopIsPressedAndRearmsAfter) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.drive({0.5, 0, 0}, 500ms);
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_emergency_stop(true);
    return 0;
  });
  rig.drive({0.5, 0, 0}, 200ms);
  EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kEstop);
  const std::size_t sent_before = rig.sent().size();
  const auto refused = rig.driver().resume();
  rig.step();
  const RequestOutcome* r = rig.snapshot()->request(refused);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->state, RequestOutcome::State::kFailed);
  EXPECT_NE(r->message.find("emergency_stop"), std::string::npos) << r->message;
  for (std::size_t i = sent_before; i < rig.sent().size(); ++i)
    EXPECT_EQ(rig.sent()[i].sent.frame.id, protocol::kMotionCommandId) << "resume sent something";

  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_emergency_stop(false);
    return 0;
  });
  rig.drive({0.5, 0, 0}, 500ms);
  EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kRearmRequired);
  EXPECT_EQ(rig.sim().snapshot().speed, 0.0);
  const auto ok = rig.driver().resume();
  rig.step();
  EXPECT_EQ(rig.snapshot()->request(ok)->state, RequestOutcome::State::kAnswered);
  rig.drive({0.5, 0, 0}, 1s);
  EXPECT_GT(rig.sim().snapshot().speed, 0.4);
}

// Where the owner opted in to the zero twist's re-arm (rearm_on_zero_twist).
TEST(Driver, AZeroTwistInTheSameBatchAsAMovingOneStillRearms) {
  DriverConfig config;
  config.controller.rearm_on_zero_twist = true;
  DriverRig rig(config);
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_emergency_stop(true);
    return 0;
  });
  rig.run_for(100ms);
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_emergency_stop(false);
    return 0;
  });
  rig.run_for(100ms);
  ASSERT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kRearmRequired);
  // Two commands before the driver looks: the zero must not be lost behind the moving one.
  ASSERT_TRUE(rig.driver().command(MotionRequest{}).ok());
  ASSERT_TRUE(rig.driver().command(MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt}).ok());
  rig.step();
  EXPECT_EQ(rig.snapshot()->controller.refusal, MotionRefusal::kNone);
}

TEST(Driver, LinkLossHidesTheMotionAndTheReturnResumesFromTheLastPose) {
  DriverRig rig;
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.snapshot()); }, 2s));
  rig.drive({0.5, 0, 0}, 1s);
  rig.drive({}, 1s);
  const double x = rig.snapshot()->odometry.pose.x;
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.silence_for(1s);
    return 0;
  });
  ASSERT_TRUE(rig.run_until([&] { return !rig.snapshot()->motion_known; }, 200ms));
  ASSERT_TRUE(rig.run_until([&] { return rig.snapshot()->motion_known; }, 2s));
  EXPECT_NEAR(rig.snapshot()->odometry.pose.x, x, 1e-3);
}

TEST(Driver, AReplayedLogRunsThroughTheDriverAndNothingIsSent) {
  // A short log: the chassis in CAN mode, Ackermann, driving straight at 0.5 m/s for 1 s.
  const std::string path = ::testing::TempDir() + "driver_replay.log";
  {
    std::ofstream log(path);
    for (int i = 0; i <= 50; ++i) {
      const Timestamp t = Timestamp(1700000000s) + i * 20ms;
      SystemStatus st;
      st.control_mode_raw = 1;
      st.control_mode = protocol::ControlMode::kCan;
      st.battery_voltage = 48.0;
      WheelSpeedsFeedback ws;
      ws.speeds = {0.5, 0.5, 0.5, 0.5};
      SteeringAnglesFeedback sa;
      MotionModeFeedback mm;
      for (const Message& m : {Message{st}, Message{ws}, Message{sa}, Message{mm}}) {
        auto f = encode(m);
        ASSERT_TRUE(f.ok());
        f->stamp = t;
        log << format_candump_line(*f, "can0") << "\n";
      }
    }
  }
  ManualClock clock(Timestamp(5s));
  auto source = open_bus_source("replay:" + path, clock);
  ASSERT_TRUE(source.ok()) << source.error().message;
  EXPECT_TRUE((*source)->read_only());
  Driver driver(DriverConfig{}, std::move(*source), clock);
  std::vector<SentEvent> sent;
  driver.set_sent_observer([&](const SentEvent& e) { sent.push_back(e); });
  for (int i = 0; i < 1500; ++i) {
    clock.advance(1ms);
    driver.step(clock.now());
  }
  EXPECT_TRUE(driver.command(MotionRequest{BodyTwist{0.2, 0, 0}, std::nullopt}).ok());
  for (int i = 0; i < 100; ++i) {
    clock.advance(1ms);
    driver.step(clock.now());
  }
  const auto s = driver.snapshot();
  EXPECT_TRUE(s->read_only);
  EXPECT_NEAR(s->odometry.pose.x, 0.5, 0.03);
  EXPECT_TRUE(sent.empty()) << "a replayed log is read-only";
  std::remove(path.c_str());
}

TEST(Driver, BusSourceSpecsAreCheckedWithAMessage) {
  ManualClock clock;
  EXPECT_FALSE(bus_kind("").ok());
  EXPECT_FALSE(bus_kind("replay:").ok());
  EXPECT_EQ(*bus_kind("can0"), BusKind::kSocketCan);
  EXPECT_EQ(*bus_kind("replay:x.log"), BusKind::kReplay);
  EXPECT_EQ(*bus_kind("sim:manual"), BusKind::kSim);
  auto sim = open_bus_source("sim", clock);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.error().message.find("sim::open_bus_source"), std::string::npos);
  auto variant = sim::open_bus_source("sim:nosuchvariant", clock);
  ASSERT_FALSE(variant.ok());
  EXPECT_NE(variant.error().message.find("valid:"), std::string::npos) << variant.error().message;
  auto missing = open_bus_source("replay:/nonexistent/file.log", clock);
  ASSERT_TRUE(missing.ok());  // the file is read at open()
  auto opened = (*missing)->open();
  ASSERT_FALSE(opened.ok());
  EXPECT_NE(opened.error().message.find("/nonexistent/file.log"), std::string::npos);
}

}  // namespace
}  // namespace ranger
