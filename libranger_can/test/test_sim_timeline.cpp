// The threaded virtual chassis keeps its own timeline (issue 34): when the host does not run its
// thread for a while, a reader of the in-process bus still finds the frames of the time that
// passed, each stamped with its due time, as it would find a real chassis's frames waiting in the
// kernel's queue. The clock is a ManualClock: the chassis thread steps only to the clock's now, so
// "the host did not run it" is the clock jumping while the test reads at once; whether the thread
// ran in between or not, the reader sees the same frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

std::vector<Timestamp> stamps_of(std::uint32_t id, const std::vector<Result<CanFrame>>& frames) {
  std::vector<Timestamp> out;
  for (const auto& f : frames) {
    if (f && f->id == id) out.push_back(f->stamp);
  }
  return out;
}

std::vector<Result<CanFrame>> take_all(Bus& bus) {
  std::vector<Result<CanFrame>> out;
  while (bus.receive_queued(out, 4096) > 0) {
  }
  return out;
}

TEST(SimTimeline, AReaderAfterAStallFindsEveryFrameOfItStampedWithItsDueTime) {
  ManualClock clock(Timestamp(100s));
  auto source = sim::open_bus_source("sim", clock);
  ASSERT_TRUE(source.ok()) << source.error().message;
  auto bus = (*source)->open();
  ASSERT_TRUE(bus.ok());
  take_all(**bus);  // what the boot sent

  const Timestamp before = clock.now();
  clock.advance(300ms);  // the host ran neither the chassis's thread nor the reader for 300 ms
  const auto frames = take_all(**bus);
  const auto status = stamps_of(protocol::kSystemStatusId, frames);
  // 0x211 every 20 ms: the 15 that fell due, in order, 20 ms apart, none later than now.
  ASSERT_EQ(status.size(), 15u);
  for (std::size_t i = 0; i < status.size(); ++i) {
    EXPECT_GT(status[i], before);
    EXPECT_LE(status[i], clock.now());
    if (i > 0) EXPECT_EQ(status[i] - status[i - 1], 20ms);
  }
}

TEST(SimTimeline, AStallLongerThanTheReplayWindowResumesFromNow) {
  ManualClock clock(Timestamp(100s));
  auto source = sim::open_bus_source("sim", clock);
  ASSERT_TRUE(source.ok());
  auto bus = (*source)->open();
  ASSERT_TRUE(bus.ok());
  take_all(**bus);

  clock.advance(5s);  // longer than the one-second window: a burst of stale frames is not sent
  const auto status = stamps_of(protocol::kSystemStatusId, take_all(**bus));
  ASSERT_FALSE(status.empty());
  EXPECT_LE(status.size(), 2u);
  EXPECT_EQ(status.back(), clock.now());
}

// The driver on the threaded chassis, stepped by the test after the clock jumped further than the
// link timeout: it reads the chassis's frames before it judges the link, so it never sees a silent
// chassis however long the host left both threads unrun.
TEST(SimTimeline, TheDriverNeverHearsASilentChassisWhenTheHostWasSlow) {
  ManualClock clock(Timestamp(100s));
  auto source = sim::open_bus_source("sim", clock);
  ASSERT_TRUE(source.ok());
  DriverConfig config;
  Driver driver(config, *source, clock);
  for (int i = 0; i < 200; ++i) {  // 2 s of 10 ms steps: connected
    clock.advance(10ms);
    driver.step(clock.now());
  }
  ASSERT_EQ(driver.snapshot()->controller.link, LinkState::kConnected);
  const auto losses = driver.snapshot()->controller.counters.link_losses;
  for (int i = 0; i < 10; ++i) {
    clock.advance(config.controller.link_timeout * 3);  // a stall three link timeouts long
    driver.step(clock.now());
    EXPECT_EQ(driver.snapshot()->controller.link, LinkState::kConnected) << "stall " << i;
  }
  EXPECT_EQ(driver.snapshot()->controller.counters.link_losses, losses);
}

}  // namespace
}  // namespace ranger
