// The front ends' pacing (frontend/publication.hpp): the fixed-rate schedule with its early
// margin and stall recovery, and the motion publication's decision (each estimate once, nothing
// while the chassis is not heard, a wait for the next estimate when due with nothing new). Time is
// given, never read: the tests assert the schedule, not a clock.
#include <gtest/gtest.h>

#include "ranger_can/frontend/publication.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

TEST(Publication, ThePeriodAndTheEarlyMargin) {
  EXPECT_EQ(publication_period(50.0), std::chrono::duration_cast<SteadyDuration>(20ms));
  EXPECT_EQ(publication_early(publication_period(50.0)), SteadyDuration(5ms));
  EXPECT_EQ(publication_early(publication_period(1000.0)), SteadyDuration(250us));
}

TEST(Publication, AFixedRateScheduleKeepsItsRateAndRestartsAfterAStall) {
  const SteadyTime t0{};
  PublicationSchedule s(50.0);
  s.start(t0);
  EXPECT_TRUE(s.due(t0));
  s.advance(t0 + 1ms);  // published a little late: the next is still due at t0 + 20 ms
  EXPECT_EQ(s.next(), t0 + 20ms);
  EXPECT_FALSE(s.due(t0 + 14ms));
  EXPECT_TRUE(s.due(t0 + 15ms));  // 5 ms early
  EXPECT_EQ(s.wake_at(), t0 + 15ms);
  s.advance(t0 + 200ms);  // a stall: from now, no burst
  EXPECT_EQ(s.next(), t0 + 220ms);
  s.set_rate(10.0);  // a new rate counts from the next advance
  s.advance(t0 + 220ms);
  EXPECT_EQ(s.next(), t0 + 320ms);
}

DriverSnapshot heard(Timestamp odometry, Timestamp wheels) {
  DriverSnapshot s;
  s.motion_known = true;
  s.odometry.stamp = odometry;
  s.joints.has_wheels = true;
  s.feedback.wheel_speeds.emplace();
  s.feedback.wheel_speeds->stamp = wheels;
  return s;
}

TEST(Publication, EachEstimateIsPublishedOnceAndADueTimeWaitsForTheNext) {
  const SteadyTime t0{};
  MotionPacer pacer(50.0);
  pacer.start(t0);
  const auto first = pacer.decide(heard(Timestamp{1s}, Timestamp{1s}), t0);
  EXPECT_TRUE(first.odometry);
  EXPECT_TRUE(first.joints);
  EXPECT_FALSE(first.wait_for_estimate);
  EXPECT_EQ(pacer.next(), t0 + 20ms);
  // Due again, the same estimate: nothing to publish, wait for the next (no advance).
  const auto same = pacer.decide(heard(Timestamp{1s}, Timestamp{1s}), t0 + 20ms);
  EXPECT_FALSE(same.publish());
  EXPECT_TRUE(same.wait_for_estimate);
  EXPECT_EQ(pacer.next(), t0 + 20ms);
  // Only the joints moved on.
  const auto joints = pacer.decide(heard(Timestamp{1s}, Timestamp{2s}), t0 + 21ms);
  EXPECT_FALSE(joints.odometry);
  EXPECT_TRUE(joints.joints);
  EXPECT_EQ(pacer.next(), t0 + 40ms);
}

TEST(Publication, NothingWhileTheChassisIsNotHeardAndTheScheduleGoesOn) {
  const SteadyTime t0{};
  MotionPacer pacer(50.0);
  pacer.start(t0);
  DriverSnapshot unheard = heard(Timestamp{1s}, Timestamp{1s});
  unheard.motion_known = false;
  const auto d = pacer.decide(unheard, t0);
  EXPECT_FALSE(d.publish());
  EXPECT_FALSE(d.wait_for_estimate);
  EXPECT_EQ(pacer.next(), t0 + 20ms);
  pacer.skip(t0 + 20ms);  // nobody listens
  EXPECT_EQ(pacer.next(), t0 + 40ms);
  // Heard again: the estimate it had not published is new.
  EXPECT_TRUE(pacer.decide(heard(Timestamp{1s}, Timestamp{1s}), t0 + 40ms).odometry);
}

}  // namespace
}  // namespace ranger
