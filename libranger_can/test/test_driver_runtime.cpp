// The driver runtime's plumbing (control/driver_runtime.hpp) on its own: the mailbox (what a
// command posts, what is refused and counted), the snapshot publisher (numbering, recycling only
// what no reader holds, waiting for a condition) and the loop's sleep (a pending wake-up ends it).
// Nothing here asserts on time.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "ranger_can/control/driver_runtime.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

MotionRequest twist(double vx) {
  return MotionRequest{BodyTwist{vx, 0.0, 0.0}, std::nullopt};
}

TEST(DriverMailbox, CommandsBeforeTheBusOpenedAreRefusedNamingItAndCounted) {
  DriverMailbox box;
  box.set_open(false, "No such device");
  const Status st = box.post_command(twist(0.2), "can0");
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().code, Errc::kInterfaceDown);
  EXPECT_EQ(st.error().message, "not connected to can0: No such device");
  EXPECT_FALSE(box.take().command) << "nothing posted";
  box.post_command(twist(0.2), "can0");
  std::optional<Error> last;
  EXPECT_EQ(box.take_refused(last), 1u) << "take() took the first";
  ASSERT_TRUE(last);
  EXPECT_EQ(last->code, Errc::kInterfaceDown);
  EXPECT_EQ(box.take_refused(last), 0u);
  EXPECT_FALSE(last);
}

TEST(DriverMailbox, ANonFiniteCommandIsPostedAndCountedAZeroBeforeTheLatestIsKept) {
  DriverMailbox box;
  box.set_open(true, "");
  EXPECT_TRUE(box.post_command(twist(0.0), "sim").ok());
  const Status st = box.post_command(twist(std::numeric_limits<double>::quiet_NaN()), "sim");
  EXPECT_EQ(st.error().code, Errc::kNotFinite);
  DriverMail mail = box.take();
  ASSERT_TRUE(mail.command);
  EXPECT_TRUE(std::isnan(mail.command->twist.vx)) << "posted: the driver commands zero";
  EXPECT_TRUE(mail.zero_seen) << "the zero before it re-arms";
  EXPECT_EQ(mail.refused, 1u);
  EXPECT_FALSE(box.take().command) << "taken whole";
  box.post([](DriverMail& m) { m.mode = protocol::MotionMode::kSpin; });
  EXPECT_EQ(box.take().mode, std::optional<protocol::MotionMode>(protocol::MotionMode::kSpin));
  EXPECT_FALSE(box.stop_requested());
  box.request_stop();
  EXPECT_TRUE(box.stop_requested());
}

TEST(SnapshotPublisher, NumbersPublicationsAndRecyclesOnlyWhatNoReaderHolds) {
  auto first = std::make_shared<DriverSnapshot>();
  first->bus_name = "sim";
  SnapshotPublisher pub(first);
  EXPECT_EQ(pub.latest()->bus_name, "sim");
  EXPECT_EQ(pub.latest()->sequence, 0u);

  auto a = pub.blank();
  DriverSnapshot* a_raw = a.get();
  pub.publish(std::move(a));
  auto b = pub.blank();
  pub.publish(std::move(b));
  EXPECT_EQ(pub.latest()->sequence, 2u);
  EXPECT_EQ(&pub.published(), pub.latest().get());
  // `a` is the one before the last and nobody holds it: handed out again (unless under TSan).
  auto c = pub.blank();
#if !defined(__SANITIZE_THREAD__)
  EXPECT_EQ(c.get(), a_raw);
#endif
  pub.publish(std::move(c));
  // A reader holds the one before the last: a new one is handed out, the held one never changes.
  const auto held = pub.latest();
  pub.publish(pub.blank());
  const std::uint64_t seen = held->sequence;
  auto d = pub.blank();
  EXPECT_NE(d.get(), held.get());
  pub.publish(std::move(d));
  EXPECT_EQ(held->sequence, seen);
  EXPECT_EQ(pub.latest()->sequence, 5u);
}

TEST(SnapshotPublisher, WaitReturnsTheLatestOnceTheConditionHoldsOrAtTheDeadline) {
  SnapshotPublisher pub(std::make_shared<DriverSnapshot>());
  pub.publish(pub.blank());
  const auto now = std::chrono::steady_clock::now();
  EXPECT_EQ(
      pub.wait_until([](const DriverSnapshot& s) { return s.sequence == 1; }, now + 1h)->sequence,
      1u);
  EXPECT_EQ(pub.wait_until([](const DriverSnapshot&) { return false; }, now)->sequence, 1u);
}

TEST(LoopWaker, APendingWakeUpEndsTheNextSleepWhateverTheClock) {
  const SteadyClock steady;  // the timerfd path
  LoopWaker timed(steady);
  timed.wake();
  timed.sleep_until(steady.now() + 1h);
  timed.sleep_until(steady.now() - 1s);  // already due: returns

  const ManualClock manual;  // not monotonic: a plain timed wait
  LoopWaker plain(manual);
  plain.wake();
  plain.sleep_until(manual.now() + 1h);
  SUCCEED() << "both returned";
}

}  // namespace
}  // namespace ranger
