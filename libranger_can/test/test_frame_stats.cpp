// Frame statistics: per-ID counts and sliding-window rates, exact for a steady stream, expiring
// after silence; padding reported once per ID.
#include <gtest/gtest.h>

#include "ranger_can/control/frame_stats.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

TEST(FrameStats, ASteadyStreamHasItsExactRateWhateverThePhase) {
  for (auto phase : {0ms, 1ms, 7ms, 19ms}) {
    FrameStats stats;
    Timestamp t = Timestamp(10s) + phase;
    for (int i = 0; i < 200; ++i, t += 20ms)
      stats.record(0x211, t, true, 0);
    const Timestamp last = t - 20ms;
    for (auto now : {last, last + 5ms, last + 19ms}) {
      EXPECT_NEAR(stats.rate(0x211, now), 50.0, 1.0 + 1e-9)  // at most one frame off
          << "phase " << phase.count() << " ms, " << (now - last).count() << " ns after";
    }
  }
}

TEST(FrameStats, SilenceExpiresTheRateAndCountsStay) {
  FrameStats stats;
  for (int i = 0; i < 100; ++i)
    stats.record(0x221, Timestamp(1s) + i * 10ms, i % 10 != 0, 0);
  EXPECT_GT(stats.rate(0x221, Timestamp(2s)), 90.0);
  EXPECT_EQ(stats.rate(0x221, Timestamp(5s)), 0.0);
  EXPECT_EQ(stats.rate(0x123, Timestamp(2s)), 0.0) << "never seen";
  const auto counts = stats.counts();
  ASSERT_EQ(counts.size(), 1u);
  EXPECT_EQ(counts[0].id, 0x221u);
  EXPECT_EQ(counts[0].frames, 100u);
  EXPECT_EQ(counts[0].rejected, 10u);
  EXPECT_EQ(stats.total(), 100u);
  // A burst after the silence counts only itself.
  stats.record(0x221, Timestamp(9s), true, 0);
  stats.record(0x221, Timestamp(9s) + 10ms, true, 0);
  EXPECT_NEAR(stats.rate(0x221, Timestamp(9s) + 10ms), 2.0 / 1.01, 1e-9);
}

TEST(FrameStats, PaddingIsReportedOncePerId) {
  FrameStats stats;
  EXPECT_FALSE(stats.record(0x291, Timestamp(1s), true, 0));
  EXPECT_TRUE(stats.record(0x291, Timestamp(2s), true, 6));
  EXPECT_FALSE(stats.record(0x291, Timestamp(3s), true, 6));
  EXPECT_TRUE(stats.record(0x361, Timestamp(3s), true, 4));
  EXPECT_EQ(stats.counts()[0].padded, 2u);
}

}  // namespace
}  // namespace ranger
