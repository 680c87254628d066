// `ranger_can odom`: a synthetic candump log (straight, spin, crab) replays to the expected final
// pose with both sources; options, usage errors and logs without timestamps.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "cli_commands.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "support/cli_run.hpp"
#include "support/synthetic_feedback.hpp"

namespace ranger::cli {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;

using Outcome = test::CliOutcome;
using test::lines_of;

Outcome run(const Args& args, const std::string& input = "") {
  return test::run_cli(run_odom, args, input);
}

struct FinalPose {
  double t, x, y, yaw;
};

// Parses the final line, which must be exactly {"t":..,"x":..,"y":..,"yaw":..}.
bool parse_final(const std::string& line, FinalPose& p) {
  static const std::regex re(
      R"(^\{"t":(-?[0-9.]+),"x":(-?[0-9.eE+-]+),"y":(-?[0-9.eE+-]+),"yaw":(-?[0-9.eE+-]+)\}$)");
  std::smatch m;
  if (!std::regex_match(line, m, re)) return false;
  p = {std::stod(m[1]), std::stod(m[2]), std::stod(m[3]), std::stod(m[4])};
  return true;
}

// A drive as a candump -L log: 1 s straight at 0.5 m/s (Ackermann), a quarter turn on the spot
// (spin, 2 s), then 1 s of crab to the left at 0.3 m/s. Each segment is flanked by samples at
// rest (the mode switches happen there), so the trapezoidal steps at its edges add up to exactly
// `samples * 20 ms` of motion. From the origin the body ends at (0.2, 0) facing +y.
std::string synthetic_log(Timestamp start = 1700000000s) {
  const VehicleGeometry g;
  struct Segment {
    MotionMode mode;
    BodyTwist twist;
    int samples;
  } segments[] = {{MotionMode::kAckermann, {0.5, 0, 0}, 50},
                  {MotionMode::kSpin, {0, 0, M_PI / 4}, 100},
                  {MotionMode::kOblique, {0, 0.3, 0}, 50}};
  std::string log;
  Timestamp t = start;
  auto emit = [&](MotionMode mode, const BodyTwist& twist) {
    for (const CanFrame& f : test::feedback_frames(twist, mode, g, t)) {
      log += format_candump_line(f, "can0");
      log += '\n';
    }
    t += 20ms;
  };
  for (const Segment& s : segments) {
    for (int i = 0; i < 5; ++i)
      emit(s.mode, {});
    for (int i = 0; i < s.samples; ++i)
      emit(s.mode, s.twist);
    for (int i = 0; i < 5; ++i)
      emit(s.mode, {});
  }
  return log;
}

TEST(CliOdom, SyntheticLogReplaysToTheExpectedFinalPose) {
  const std::string log = synthetic_log();
  for (const char* source : {"wheels", "motion"}) {
    SCOPED_TRACE(source);
    const Outcome o = run({"--source", source}, log);
    ASSERT_EQ(o.rc, 0) << o.err;
    EXPECT_EQ(o.err, "");
    const auto lines = lines_of(o.out);
    ASSERT_GT(lines.size(), 200u);
    FinalPose p{};
    ASSERT_TRUE(parse_final(lines.back(), p)) << lines.back();
    EXPECT_NEAR(p.x, 0.2, 0.002);
    EXPECT_NEAR(p.y, 0.0, 0.002);
    EXPECT_NEAR(p.yaw, M_PI / 2, 0.1 * M_PI / 180);
    EXPECT_NEAR(p.t, 1700000000.0 + 229 * 0.02, 1e-6);
    // Step lines carry the twist and the source.
    EXPECT_NE(lines.front().find("\"vx\":"), std::string::npos) << lines.front();
    EXPECT_NE(lines.front().find(std::string("\"source\":\"") + source + "\""), std::string::npos);
  }
}

TEST(CliOdom, ReadsAFileAndHonoursQuietAndEvery) {
  const std::string path = ::testing::TempDir() + "ranger_cli_odom.log";
  {
    std::ofstream f(path);
    f << synthetic_log();
  }
  const Outcome quiet = run({path, "--quiet"});
  ASSERT_EQ(quiet.rc, 0) << quiet.err;
  ASSERT_EQ(lines_of(quiet.out).size(), 1u);
  FinalPose p{};
  EXPECT_TRUE(parse_final(lines_of(quiet.out)[0], p));
  const Outcome all = run({path});
  const Outcome every = run({path, "--every", "10"});
  ASSERT_EQ(every.rc, 0);
  const std::size_t steps = lines_of(all.out).size() - 1;
  EXPECT_EQ(lines_of(every.out).size() - 1, steps / 10);
  EXPECT_EQ(lines_of(every.out).back(), lines_of(all.out).back());
  std::remove(path.c_str());
}

TEST(CliOdom, GeometryOptionsChangeTheSpinEstimate) {
  // The same wheel speeds on a vehicle twice as large turn it half as far.
  const Outcome big = run({"--wheelbase", "1.78", "--track", "1.12", "--quiet"}, synthetic_log());
  ASSERT_EQ(big.rc, 0) << big.err;
  FinalPose p{};
  ASSERT_TRUE(parse_final(lines_of(big.out).back(), p));
  EXPECT_NEAR(p.yaw, M_PI / 4, 0.2 * M_PI / 180);
}

TEST(CliOdom, UsageErrorsAndHelp) {
  EXPECT_EQ(run({"--help"}).rc, 0);
  EXPECT_NE(run({"--help"}).out.find("usage: ranger_can odom"), std::string::npos);
  EXPECT_EQ(run({"--source", "imu"}).rc, 2);
  EXPECT_EQ(run({"--wheelbase", "nan"}).rc, 2);
  EXPECT_EQ(run({"--wheelbase", "-1"}).rc, 2);
  EXPECT_EQ(run({"--track"}).rc, 2);
  EXPECT_EQ(run({"--every", "0"}).rc, 2);
  EXPECT_EQ(run({"--bogus"}).rc, 2);
  EXPECT_EQ(run({"a.log", "b.log"}).rc, 2);
  const Outcome missing = run({"/nonexistent/ranger.log"});
  EXPECT_EQ(missing.rc, 1);
  EXPECT_NE(missing.err.find("cannot open"), std::string::npos);
  const Outcome directory = run({RANGER_DATA_DIR});  // a read error, reported, never thrown
  EXPECT_EQ(directory.rc, 1);
  EXPECT_NE(directory.err.find("is a directory"), std::string::npos) << directory.err;
}

TEST(CliOdom, BadLinesAreReportedAndLogsWithoutTimestampsFail) {
  const Outcome bad = run({"--quiet"}, "garbage\n" + synthetic_log());
  EXPECT_EQ(bad.rc, 0);
  EXPECT_NE(bad.err.find("line 1:"), std::string::npos) << bad.err;
  FinalPose p{};
  EXPECT_TRUE(parse_final(lines_of(bad.out).back(), p));
  EXPECT_NEAR(p.x, 0.2, 0.002);

  // Without what odometry needs: exit 1, one line saying why, and no pose as if there were one.
  struct Case {
    std::string input;
    std::string reason;
  };
  const Case cases[] = {
      {"", "ranger_can odom: no pose: the input is empty"},
      {"can0  221   [8]  00 96 00 00 00 00 00 00\ncan0  221   [8]  00 96 00 00 00 00 00 00\n",
       "ranger_can odom: no pose: the log has no timestamps; record it with 'candump -L' (or -ta)"},
      {"(1.0) can0 211#0001020000002001\n(1.02) can0 221#0096000000000000\n",
       "ranger_can odom: no pose: none of the 2 frame(s) gave an odometry step (that needs two "
       "timestamped motion feedback frames: 0x221, or 0x271 + 0x281, less than 0.5 s apart)"},
      {"(1.0) can0 18FF1234#01\nnonsense\n",
       "ranger_can odom: no pose: no RANGER frames in 2 line(s) (1 malformed, 1 with extended IDs "
       "(other devices))"},
  };
  for (const auto& c : cases) {
    const Outcome o = run({}, c.input);
    EXPECT_EQ(o.rc, 1) << c.input;
    EXPECT_EQ(o.out, "") << c.input;
    ASSERT_FALSE(lines_of(o.err).empty());
    EXPECT_EQ(lines_of(o.err).back(), c.reason);
  }
}

}  // namespace
}  // namespace ranger::cli
