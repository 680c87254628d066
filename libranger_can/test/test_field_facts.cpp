// The field facts (docs/FIELD_FACTS.md): what a real RANGER MINI 3.0 was observed to do, as tests
// against the virtual chassis's frames and, where it touches the driver, against the driver.
// The motion-mode switch first: the new mode in 0x291 as soon as 0x141 arrives, the switching flag
// on some switches only, the wheels at about 3.26 rad/s (t = d / 3.26 + 0.064 s, triangular below
// 0.21 rad), speed commands ignored until they are there (sim:mini_v3 and the RANGER's variant
// sim:field_switch); then the driver on them: 100 switches at field timing in lock-step with a
// ManualClock, no sleeping; then the run as a candump record; then the other facts of the table,
// and the table itself: every row names tests that exist.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/chassis_model.hpp"
#include "ranger_can/sim/frame_schedule.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/switch_model.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "support/cli_run.hpp"
#include "support/driver_sim_rig.hpp"
#include "support/fake_bus.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;

// ---- the virtual chassis's frames --------------------------------------------------------------

sim::VirtualChassisConfig chassis_of(const std::string& variant) {
  auto c = sim::apply_variant(variant, {});
  EXPECT_TRUE(c.ok());
  return c ? *c : sim::VirtualChassisConfig{};
}

struct Chassis {
  explicit Chassis(const std::string& variant)
      : config(chassis_of(variant)), chassis(bus, config, Timestamp{0}) {
    chassis.step(t);
    send(ControlModeCommand{ControlMode::kCan});
    advance(20ms);
  }
  sim::VirtualChassisConfig config;
  Timestamp t{0};
  test::FakeBus bus;
  sim::VirtualChassis chassis;

  void send(const Message& m) {
    auto f = encode(m, config.profile);
    ASSERT_TRUE(f.ok());
    chassis.on_frame(*f, t);
  }
  void advance(std::chrono::nanoseconds d) {
    const Timestamp end = t + d;
    while (t < end) {
      t += 1ms;
      chassis.step(t);
    }
  }
  // Every 0x291 and 0x271 sent since `from` (index into bus.sent), decoded.
  std::vector<MotionModeFeedback> modes(std::size_t from = 0) const {
    std::vector<MotionModeFeedback> out;
    for (std::size_t i = from; i < bus.sent.size(); ++i) {
      if (bus.sent[i].id != protocol::kMotionModeFeedbackId) continue;
      auto m = decode(bus.sent[i], config.profile);
      if (m) out.push_back(std::get<MotionModeFeedback>(*m));
    }
    return out;
  }
  std::vector<std::pair<Timestamp, SteeringAnglesFeedback>> angles(std::size_t from = 0) const {
    std::vector<std::pair<Timestamp, SteeringAnglesFeedback>> out;
    for (std::size_t i = from; i < bus.sent.size(); ++i) {
      if (bus.sent[i].id != protocol::kSteeringAnglesId) continue;
      auto m = decode(bus.sent[i], config.profile);
      if (m) out.emplace_back(bus.sent[i].stamp, std::get<SteeringAnglesFeedback>(*m));
    }
    return out;
  }
};

TEST(FieldSwitchModel, TheTurnFollowsTheFieldFit) {
  const sim::TurnProfile p = sim::SwitchModel(sim::field_switch_model(), 0.5).turn_profile();
  // t = d / 3.26 + 0.064 s above 0.21 rad: 1.57 rad in about 0.54 s.
  EXPECT_NEAR(p.duration(1.57), 1.57 / 3.26 + 0.064, 1e-9);
  EXPECT_NEAR(p.duration(1.57), 0.546, 0.005);
  EXPECT_NEAR(p.duration(0.5), 0.5 / 3.26 + 0.064, 1e-9);
  // Triangular below 3.26 * 0.064 = 0.209 rad: both formulas meet there.
  EXPECT_NEAR(p.duration(0.2086), 0.2086 / 3.26 + 0.064, 1e-3);
  EXPECT_LT(p.duration(0.15), 0.15 / 3.26 + 0.064);
  EXPECT_NEAR(p.duration(0.0), 0.08, 1e-12) << "the shortest median by transition";
  // The wheels move monotonically and never faster than 3.26 rad/s.
  const double d = 1.0, T = p.duration(d);
  double last = 0.0, fastest = 0.0;
  for (double t = 0.001; t <= T + 0.01; t += 0.001) {
    const double f = p.fraction(t, d);
    EXPECT_GE(f, last - 1e-12);
    fastest = std::max(fastest, (f - last) * d / 0.001);
    last = f;
  }
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_NEAR(fastest, 3.26, 0.02);
}

class FieldChassis : public ::testing::TestWithParam<const char*> {};

TEST_P(FieldChassis, ReportsTheNewModeAtOnceAndTurnsAtTheFieldRate) {
  Chassis c(GetParam());
  const std::size_t from = c.bus.sent.size();
  c.send(MotionModeCommand{MotionMode::kSpin});
  c.advance(20ms);
  const auto first = c.modes(from);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front().mode, MotionMode::kSpin) << "0x291 shows the target at once";
  EXPECT_TRUE(c.chassis.snapshot().switching) << "while the wheels turn";
  // The largest wheel turn is the spin angle atan2(wheelbase, track) from 0.
  const VehicleGeometry& g = c.config.geometry;
  const double d = std::atan2(g.wheelbase, g.track);
  const double expected = d / 3.26 + 0.064;
  c.advance(std::chrono::duration_cast<std::chrono::nanoseconds>(
                std::chrono::duration<double>(expected)) -
            25ms);
  EXPECT_TRUE(c.chassis.snapshot().switching);
  c.advance(10ms);
  EXPECT_FALSE(c.chassis.snapshot().switching) << "switched in d / 3.26 + 0.064 s";
  EXPECT_EQ(c.chassis.snapshot().motion_mode, MotionMode::kSpin);
  // 0x271: the fastest wheel's rate between two frames is the field's 3.26 rad/s.
  const auto a = c.angles(from);
  double fastest = 0.0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    const double dt = seconds(a[i].first - a[i - 1].first);
    for (int w = 0; w < 4; ++w) {
      fastest = std::max(fastest, std::abs(a[i].second.angles[w] - a[i - 1].second.angles[w]) / dt);
    }
  }
  EXPECT_NEAR(fastest, 3.26, 0.05);
}

TEST_P(FieldChassis, IgnoresSpeedUntilTheWheelsAreThere) {
  Chassis c(GetParam());
  c.send(MotionModeCommand{MotionMode::kOblique});
  c.advance(1ms);
  c.send(MotionModeCommand{MotionMode::kSpin});  // a new target during the switch
  for (int i = 0; i < 10; ++i) {
    MotionCommand spin;
    spin.spin_speed = 0.3;
    c.send(spin);
    c.advance(20ms);
    if (!c.chassis.snapshot().switching) break;
    EXPECT_EQ(c.chassis.snapshot().target.speed, 0.0);
    EXPECT_EQ(c.chassis.snapshot().speed, 0.0);
  }
}

TEST_P(FieldChassis, RaisesTheFlagOnAboutHalfTheSwitchesTheSameEveryRun) {
  auto count = [&] {
    Chassis c(GetParam());
    int flagged = 0;
    const MotionMode modes[] = {MotionMode::kSpin, MotionMode::kAckermann, MotionMode::kOblique};
    for (int i = 0; i < 200; ++i) {
      const std::size_t from = c.bus.sent.size();
      c.send(MotionModeCommand{modes[i % 3]});
      c.advance(700ms);
      const auto m = c.modes(from);
      flagged += std::any_of(m.begin(), m.end(), [](const auto& f) { return f.switching; });
      for (const auto& f : m)
        EXPECT_EQ(f.mode, modes[i % 3]) << "never the mode being left";
    }
    return flagged;
  };
  const int flagged = count();
  EXPECT_GT(flagged, 200 * 0.35);  // the field: 439 of 941 (47 %)
  EXPECT_LT(flagged, 200 * 0.60);
  EXPECT_EQ(count(), flagged) << "seeded: deterministic";
}

INSTANTIATE_TEST_SUITE_P(Variants, FieldChassis, ::testing::Values("mini_v3", "field_switch"));

TEST(FieldChassis, TheManualsReportStaysReachableByName) {
  for (const char* variant : {"manual", "agx_v2"}) {
    Chassis c(variant);
    const std::size_t from = c.bus.sent.size();
    c.send(MotionModeCommand{MotionMode::kSpin});
    c.advance(100ms);
    const auto m = c.modes(from);
    ASSERT_FALSE(m.empty());
    EXPECT_EQ(m.back().mode, MotionMode::kAckermann) << variant << ": the mode being left";
    EXPECT_TRUE(m.back().switching) << variant;
  }
  // The MINI 3.0 reporting the manual's way: the mode_left variant on its model.
  auto model = model_preset("ranger_mini_v3");
  ASSERT_TRUE(model.ok());
  auto config = sim::apply_variant("mode_left", sim::chassis_for_model(*model));
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->switch_model.report, sim::SwitchReport::kModeLeft);
  EXPECT_EQ(sim::chassis_for_model(*model).switch_model.report, sim::SwitchReport::kAtOnce);
}

// ---- the driver on the field's switch ----------------------------------------------------------

bool moving(const CanFrame& f) {
  return std::any_of(f.data.begin(), f.data.begin() + f.dlc, [](std::uint8_t b) { return b != 0; });
}

// The shared lock-step rig (support/driver_sim_rig.hpp), watching both sides at every step.
class SwitchRig : public test::DriverSimRig {
 public:
  explicit SwitchRig(const std::string& variant)
      : DriverSimRig(variant, test::driver_config_for(variant)) {}

  // The caller publishes `request` every 50 ms for `d`; every command accepted.
  void drive(const MotionRequest& request, std::chrono::nanoseconds d) {
    EXPECT_EQ(DriverSimRig::drive(request, d), 0) << "a command refused";
  }
  std::shared_ptr<const DriverSnapshot> snap() const { return snapshot(); }

  int switches_ = 0;
  int lost_ = 0;               // moving 0x111 the chassis ignored
  std::vector<double> added_;  // s from the chassis's switch end to the first obeyed command
  std::string implausible_;

 protected:
  void on_sent(const SentEvent& e) override {
    if (e.sent.frame.id == protocol::kMotionCommandId && moving(e.sent.frame)) moving_sent_ = true;
  }
  void chassis_stepping() override {
    moving_in_flight_ = moving_sent_;
    moving_sent_ = false;
    ignored_before_ = counters().frames_ignored;
  }
  void chassis_stepped() override {
    const sim::ChassisSnapshot s = chassis();
    const Timestamp now = clock().now();
    if (moving_in_flight_ && counters().frames_ignored > ignored_before_) {
      ++lost_;
      std::cout << "lost at " << seconds(now) << " switching " << s.switching << " mode "
                << protocol::to_string(s.motion_mode) << " -> "
                << protocol::to_string(s.switch_target) << " refused " << s.motion_refused_reason
                << "\n";
    }
    if (!was_switching_ && s.switching) switch_end_.reset();  // the next switch began
    if (was_switching_ && !s.switching) {
      switch_end_ = now;
      ++switches_;
    }
    was_switching_ = s.switching;
    const bool obeyed = s.target.speed != 0.0 || s.target.steering != 0.0;
    if (switch_end_ && obeyed) {
      added_.push_back(seconds(now - *switch_end_));
      switch_end_.reset();
    }
  }
  void driver_stepped() override {
    const auto snap = snapshot();
    if (has(snap->controller.latched_causes, StopCause::kImplausible) ||
        !snap->controller.implausible_reason.empty()) {
      implausible_ = snap->controller.implausible_reason;
    }
  }

 private:
  bool moving_sent_ = false;
  bool moving_in_flight_ = false;
  std::uint64_t ignored_before_ = 0;
  bool was_switching_ = false;
  std::optional<Timestamp> switch_end_;
};

// A twist only `mode` expresses, never zero in what the chassis obeys (speed or steering).
BodyTwist twist_for(MotionMode mode, std::mt19937& rng) {
  auto u = [&](double lo, double hi) {
    return lo + (hi - lo) * (static_cast<double>(rng()) / 4294967296.0);
  };
  const double sign = (rng() & 1u) ? 1.0 : -1.0;
  switch (mode) {
    case MotionMode::kSpin:
      return {0.0, 0.0, sign * u(0.3, 0.8)};
    case MotionMode::kOblique:
      return {u(0.1, 0.3), sign * u(0.1, 0.3), 0.0};
    default:
      return {u(0.2, 0.5), 0.0, sign * u(0.1, 0.3)};
  }
}

class FieldDriver : public ::testing::TestWithParam<const char*> {};

TEST_P(FieldDriver, HundredSwitchesAtFieldTimingLoseNothingAndKeepTheOdometry) {
  SwitchRig rig(GetParam());
  ASSERT_TRUE(rig.ready());
  std::mt19937 rng(36);
  const MotionMode modes[] = {MotionMode::kAckermann, MotionMode::kOblique, MotionMode::kSpin};
  MotionMode current = MotionMode::kAckermann;
  int requested = 0;
  while (rig.switches_ < 100 && requested < 150) {
    MotionMode next = current;
    while (next == current)
      next = modes[rng() % 3];
    current = next;
    ++requested;
    // A random moment: 0.1 s (the next request while this switch is under way) to 1.5 s.
    const auto hold = std::chrono::milliseconds(100 + rng() % 1400);
    rig.drive(MotionRequest{twist_for(current, rng), current}, hold);
  }
  rig.drive(MotionRequest{BodyTwist{}, std::nullopt}, 1s);
  EXPECT_GE(rig.switches_, 100);
  EXPECT_EQ(rig.implausible_, "") << "no plausibility stop";
  EXPECT_EQ(rig.lost_, 0) << "moving 0x111 the chassis ignored";
  EXPECT_EQ(rig.snap()->controller.latched_causes, 0u);
  // Odometry within 1 % of the path + 2 cm of the ground truth.
  const sim::ChassisSnapshot truth = rig.chassis();
  const Pose2D odom = rig.snap()->odometry.pose;
  const double error = std::hypot(odom.x - truth.pose.x, odom.y - truth.pose.y);
  EXPECT_LT(error, 0.01 * truth.distance_travelled + 0.02)
      << "path " << truth.distance_travelled << " m";
  EXPECT_LT(std::abs(wrap_angle(odom.yaw - truth.pose.yaw)), 0.01 * truth.yaw_travelled + 0.02);
  // The time the driver adds to the chassis's own switch: from the chassis's switch end to the
  // first command it obeys (ones cut short by the next request do not count).
  ASSERT_FALSE(rig.added_.empty());
  std::vector<double> added = rig.added_;
  std::sort(added.begin(), added.end());
  const double median = added[added.size() / 2];
  const double worst = added.back();
  std::cout << "[ figures  ] " << GetParam() << ": " << rig.switches_ << " switches, path "
            << truth.distance_travelled << " m, odometry error " << error * 1000.0
            << " mm; driver's time beyond the chassis's switch: median " << median * 1000.0
            << " ms, max " << worst * 1000.0 << " ms over " << added.size() << "\n";
  EXPECT_LE(worst, 0.1) << "goal: at most 0.1 s beyond the chassis's switch";
}

INSTANTIATE_TEST_SUITE_P(Reports, FieldDriver,
                         ::testing::Values("mini_v3", "field_switch", "manual"));

// ---- the run as a record: ranger_can scenario --candump FILE -----------------------------------

double json_number(const std::string& line, const std::string& key) {
  const auto at = line.find("\"" + key + "\":");
  if (at == std::string::npos) return NAN;
  return std::strtod(line.c_str() + at + key.size() + 3, nullptr);
}

TEST(FieldSwitchRecord, TheCandumpOfARunDecodesWithTheTargetModeAtOnce) {
  const std::string dir = ::testing::TempDir();
  const std::string script = dir + "/field_switch_route.scn";
  const std::string log = dir + "/field_switch_route.log";
  {
    std::ofstream out(script);
    out << "wait 1\ncmd 0.5 0 0.2\nwait 2\ncmd 0 0.3 0\nwait 2\ncmd 0 0 0.8\nwait 2\n"
           "cmd 0 0 0\nwait 1\nexpect still\n";
  }
  const auto run = test::run_cli(
      cli::run_scenario, {script, "--model", "ranger_mini_v3", "--chassis-variant", "mini_v3",
                          "--protocol", "mini_v3", "--every", "1", "--candump", log});
  ASSERT_EQ(run.rc, 0) << run.err;
  const auto decoded = test::run_cli(cli::run_decode, {log, "--protocol", "mini_v3", "--json"});
  ASSERT_EQ(decoded.rc, 0) << decoded.err;
  const auto lines = test::lines_of(decoded.out);
  ASSERT_GT(lines.size(), 1000u);
  // Both ways: the driver's commands and the chassis's feedback, in simulated time from t = 0.
  const auto has = [&](const std::string& part) {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.find(part) != std::string::npos; });
  };
  EXPECT_TRUE(has("\"name\":\"motion_command\""));
  EXPECT_TRUE(has("\"name\":\"system_status\""));
  EXPECT_LT(json_number(lines.front(), "t"), 1.0);
  // Every 0x141 is answered by the next 0x291 with the target mode (at once: within 20 ms).
  int switches = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].find("\"id\":321,") == std::string::npos) continue;  // 0x141
    const auto name_at = lines[i].find("\"mode_name\":\"");
    ASSERT_NE(name_at, std::string::npos) << lines[i];
    const std::string target = lines[i].substr(name_at, lines[i].find('"', name_at + 13) - name_at);
    for (std::size_t j = i + 1; j < lines.size(); ++j) {
      if (lines[j].find("\"id\":657,") == std::string::npos) continue;  // 0x291
      EXPECT_NE(lines[j].find(target), std::string::npos) << lines[i] << "\n" << lines[j];
      EXPECT_LE(json_number(lines[j], "t") - json_number(lines[i], "t"), 0.021);
      ++switches;
      break;
    }
  }
  EXPECT_GE(switches, 2) << "oblique and spin at least";
  // 0x271 in the log: the fastest wheel turns at the field's 3.26 rad/s (during the switches).
  double fastest = 0.0, last_t = NAN;
  std::vector<double> last_angles;
  for (const std::string& l : lines) {
    if (l.find("\"id\":625,") == std::string::npos) continue;  // 0x271
    const auto at = l.find("\"angles\":[");
    ASSERT_NE(at, std::string::npos) << l;
    std::vector<double> angles;
    const char* p = l.c_str() + at + 10;
    for (int w = 0; w < 4; ++w) {
      char* end = nullptr;
      angles.push_back(std::strtod(p, &end));
      p = end + 1;
    }
    const double t = json_number(l, "t");
    if (!last_angles.empty() && t > last_t) {
      for (int w = 0; w < 4; ++w)
        // Modulo pi: a wheel at +90 deg stands as one at -90 deg.
        fastest = std::max(
            fastest, std::abs(std::remainder(angles[w] - last_angles[w], M_PI)) / (t - last_t));
    }
    last_angles = angles;
    last_t = t;
  }
  EXPECT_NEAR(fastest, 3.26, 0.05) << "the measured steering rate";
  std::remove(script.c_str());
  std::remove(log.c_str());
}

// ---- the other facts of the table ---------------------------------------------------------------

CanFrame last_frame(const test::FakeBus& bus, std::uint32_t id) {
  for (auto it = bus.sent.rbegin(); it != bus.sent.rend(); ++it) {
    if (it->id == id) return *it;
  }
  ADD_FAILURE() << "no frame " << id;
  return CanFrame{};
}

std::vector<int> bytes(const CanFrame& f, int from, int to) {
  return std::vector<int>(f.data.begin() + from, f.data.begin() + to);
}

TEST(FieldFacts, ControlModeIsZeroStandbyOneCanThreeRemote) {
  auto model = model_preset("ranger_mini_v3");
  ASSERT_TRUE(model.ok());
  test::FakeBus bus;
  sim::VirtualChassis chassis(bus, sim::chassis_for_model(*model), Timestamp{0});
  chassis.step(Timestamp{20ms});
  EXPECT_EQ(last_frame(bus, protocol::kSystemStatusId).data[1], 0) << "standby at power-on";
  Chassis c("mini_v3");  // after 0x421
  EXPECT_EQ(last_frame(c.bus, protocol::kSystemStatusId).data[1], 1);
  c.chassis.remote_takeover();
  c.advance(40ms);
  EXPECT_EQ(last_frame(c.bus, protocol::kSystemStatusId).data[1], 3);
}

TEST(FieldFacts, EstopIsFaultBit7AndBodyStatusTwoAsTheFieldReportsIt) {
  // The field's body status, the MINI 3.0's default (vehicle_status_1_is_estop = false: 0 normal,
  // 2 abnormal).
  auto model = model_preset("ranger_mini_v3");
  ASSERT_TRUE(model.ok());
  const sim::VirtualChassisConfig field = sim::chassis_for_model(*model);
  EXPECT_FALSE(field.profile.vehicle_status_1_is_estop);
  test::FakeBus bus;
  sim::VirtualChassis chassis(bus, field, Timestamp{0});
  chassis.step(Timestamp{40ms});
  EXPECT_EQ(last_frame(bus, protocol::kSystemStatusId).data[0], 0);
  chassis.set_emergency_stop(true);
  chassis.step(Timestamp{80ms});
  const CanFrame f = last_frame(bus, protocol::kSystemStatusId);
  EXPECT_EQ(f.data[0], 2) << "0 normal / 2 abnormal: 1 does not exist on this model";
  EXPECT_EQ(bytes(f, 4, 8), (std::vector<int>{0, 0, 0, 0x80})) << "error_code_full 0x00000080";
  // The vendor SDK's reading (`--set vehicle_status_1_is_estop=true`) reports 1 with the same bit.
  sim::VirtualChassisConfig sdk = field;
  sdk.profile.vehicle_status_1_is_estop = true;
  test::FakeBus sdk_bus;
  sim::VirtualChassis sdk_chassis(sdk_bus, sdk, Timestamp{0});
  sdk_chassis.set_emergency_stop(true);
  sdk_chassis.step(Timestamp{40ms});
  EXPECT_EQ(last_frame(sdk_bus, protocol::kSystemStatusId).data[0], 1);
  EXPECT_EQ(bytes(last_frame(sdk_bus, protocol::kSystemStatusId), 4, 8),
            (std::vector<int>{0, 0, 0, 0x80}));
}

TEST(FieldFacts, TheDriverStopsOnTheEstopBitWhicheverTheBodyStatus) {
  for (const bool status_1_is_estop : {true, false}) {
    SCOPED_TRACE(status_1_is_estop ? "status 1 = e-stop" : "status 2 (the field's)");
    ManualClock clock{Timestamp(1000s)};
    sim::SimSourceOptions options;
    options.lock_step = true;
    options.chassis = sim::chassis_for_model(*model_preset("ranger_mini_v3"));
    options.chassis.profile.vehicle_status_1_is_estop = status_1_is_estop;
    auto source = sim::open_bus_source("sim", clock, options);
    ASSERT_TRUE(source.ok());
    auto sim = std::static_pointer_cast<sim::SimBusSource>(*source);
    // The driver reads the preset (the field's: status 2, no 1) either way.
    Driver driver(test::driver_config_for("mini_v3"), *source, clock);
    // The commander publishes 0.3 m/s every 50 ms.
    auto step = [&](std::chrono::nanoseconds d) {
      for (auto e = 0ns; e < d; e += 1ms) {
        // (refused before the driver's first step: nothing to command yet)
        if (e % 50ms == 0ns)
          (void)driver.command(MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt});
        clock.advance(1ms);
        sim->step(clock.now());
        driver.step(clock.now());
      }
    };
    step(1500ms);
    ASSERT_EQ(driver.snapshot()->controller.refusal, MotionRefusal::kNone);
    sim->with_chassis([](sim::VirtualChassis& c) {
      c.set_emergency_stop(true);
      return 0;
    });
    step(100ms);
    EXPECT_EQ(driver.snapshot()->controller.refusal, MotionRefusal::kEstop);
    EXPECT_TRUE(has(driver.snapshot()->controller.latched_causes, StopCause::kEstop));
  }
}

TEST(FieldFacts, RemoteOffRaisesRemoteLost) {
  Chassis c("mini_v3");
  c.chassis.remote_takeover();  // the remote has the chassis, then is lost
  c.chassis.remote_signal_lost();
  c.advance(40ms);
  const CanFrame f = last_frame(c.bus, protocol::kSystemStatusId);
  EXPECT_EQ(bytes(f, 4, 8), (std::vector<int>{0, 0, 0, 0x04})) << "the notes' 0x4";
  EXPECT_EQ(f.data[1], 0) << "standby";
  EXPECT_EQ(f.data[0], 2) << "abnormal";
}

TEST(FieldFacts, BmsPayloadOfTheNotesDecodesUnderTheFieldsScale) {
  CanFrame f;
  f.id = protocol::kBmsBaseId;
  f.dlc = 8;
  f.data = {0x64, 0x64, 0x14, 0xB4, 0x00, 0x00, 0x01, 0x24};
  // The field's reading, the MINI 3.0's preset: 0.01 V.
  const ProtocolProfile field = *protocol_preset("mini_v3");
  EXPECT_EQ(field.bms_voltage_scale, 0.01);
  auto m = decode(f, field);
  ASSERT_TRUE(m.ok());
  const auto& b = std::get<BmsData>(*m);
  EXPECT_DOUBLE_EQ(b.soc, 100.0);
  EXPECT_DOUBLE_EQ(b.soh, 100.0);
  EXPECT_NEAR(b.voltage, 53.0, 1e-9) << "0.01 V";
  EXPECT_DOUBLE_EQ(b.current, 0.0);
  EXPECT_NEAR(b.temperature, 29.2, 1e-9);
  // Our transcription of the manual (`--set bms_voltage_scale=0.1`, sim:mini_v3_manual) reads
  // 530 V: the disagreement, kept selectable.
  ProtocolProfile transcribed = field;
  transcribed.bms_voltage_scale = 0.1;
  auto manual = decode(f, transcribed);
  ASSERT_TRUE(manual.ok());
  EXPECT_NEAR(std::get<BmsData>(*manual).voltage, 530.0, 1e-9);
  // Charging is positive on the wire (+19 A while the SOC rose): a negative discharge.
  EXPECT_LT(interpretation::bms_discharge_current(19.0, field), 0.0);
}

// ---- the facts the virtual MINI 3.0 carries by default -----------------------------------------

// The time the model's steering takes from 0 to `d` (rad) while driving slowly (Ackermann).
double steering_time(const sim::MotionLimits& limits, const VehicleGeometry& geometry, double d) {
  sim::ChassisModel model(geometry, limits);
  model.set_target(sim::MotionTarget{0.1, d});
  double t = 0.0;
  while (std::fabs(model.steering() - d) > 1e-9 && t < 5.0) {
    model.advance(0.001);
    t += 0.001;
  }
  return t;
}

TEST(FieldFacts, SteeringWhileDrivingFollowsTheFieldFit) {
  const auto model = model_preset("ranger_mini_v3");
  ASSERT_TRUE(model.ok());
  const sim::VirtualChassisConfig mini = sim::chassis_for_model(*model);
  EXPECT_DOUBLE_EQ(mini.limits.steering_rate, sim::kFieldSlewRate);
  // t = d / 3.26 + 0.064 s beyond 0.21 rad, t = 2 sqrt(d / a) below (a = 3.26 / 0.064).
  const double a = sim::kFieldSlewRate / sim::kFieldSlewLag;
  for (const double d : {0.3, 0.5}) {
    SCOPED_TRACE(d);
    EXPECT_NEAR(steering_time(mini.limits, mini.geometry, d),
                d / sim::kFieldSlewRate + sim::kFieldSlewLag, 0.003);
  }
  EXPECT_NEAR(steering_time(mini.limits, mini.geometry, 0.1), 2 * std::sqrt(0.1 / a), 0.003);
  // The RANGER keeps our first reading, a pure 90 deg/s.
  const sim::VirtualChassisConfig ranger = chassis_of("manual");
  EXPECT_NEAR(steering_time(ranger.limits, ranger.geometry, 0.5), 0.5 / deg_to_rad(90.0), 0.003);
}

TEST(FieldFacts, SteeringStartsAtTheCommandWithoutTheNotesFixedDelay) {
  // The notes' 1.23-1.29 s from command to steering includes their ROS path: not modelled, the
  // wheels start within one period of the 0x111 that asks for them.
  Chassis c("mini_v3");
  MotionCommand turn;
  turn.linear_speed = 0.1;
  turn.steering_angle = interpretation::manual_from_rep103_command_steering(0.3);
  c.send(turn);
  c.advance(20ms);
  EXPECT_GT(std::fabs(c.chassis.motion().steering()), 0.005);
}

TEST(FieldFacts, BmsEvery250MillisecondsInHundredthsOfAVoltWithSohHundred) {
  for (const auto& [variant, period, scale] :
       {std::tuple{"mini_v3", 250ms, 0.01}, std::tuple{"mini_v3_manual", 500ms, 0.1}}) {
    SCOPED_TRACE(variant);
    Chassis c(variant);
    EXPECT_EQ(c.config.frame_rates.of(sim::FrameGroup::kBms), period);
    EXPECT_EQ(c.config.profile.bms_voltage_scale, scale);
    const std::size_t from = c.bus.sent.size();
    c.advance(2s);
    std::vector<BmsData> bms;
    int status = 0;
    for (std::size_t i = from; i < c.bus.sent.size(); ++i) {
      const CanFrame& f = c.bus.sent[i];
      if (f.id == protocol::kSystemStatusId) ++status;
      if (f.id != protocol::kBmsBaseId) continue;
      auto m = decode(f, c.config.profile);
      ASSERT_TRUE(m.ok());
      bms.push_back(std::get<BmsData>(*m));
    }
    EXPECT_EQ(bms.size(), static_cast<std::size_t>(2s / period));
    EXPECT_NEAR(status, 100, 2) << "0x211 every 20 ms, as the field measured (20.9 ms)";
    ASSERT_FALSE(bms.empty());
    EXPECT_EQ(bms.back().soh, 100.0) << "SOH 100 throughout, as the field saw";
    EXPECT_GE(bms.back().voltage, 45.0) << "the notes' normal pack: 45-54 V";
    EXPECT_LE(bms.back().voltage, 54.0);
  }
  // The frame-rate schedule's table holds both columns.
  EXPECT_EQ(sim::manual_frame_rates().of(sim::FrameGroup::kBms), 500ms);
  EXPECT_EQ(sim::field_frame_rates().of(sim::FrameGroup::kBms), 250ms);
  EXPECT_EQ(sim::field_frame_rates().of(sim::FrameGroup::kFast), 20ms);
}

TEST(FieldFacts, OneMeterPerSecondBeyondTwentyDegreesOfSteering) {
  const auto model = model_preset("ranger_mini_v3");
  ASSERT_TRUE(model.ok());
  EXPECT_DOUBLE_EQ(model->limits.max_speed_at_large_steering, 1.0);
  // The chassis: 1.5 m/s asked at 0.5 rad (inner) is driven at 1.0 m/s.
  Chassis c("mini_v3");
  MotionCommand turn;
  turn.linear_speed = 1.5;
  turn.steering_angle = interpretation::manual_from_rep103_command_steering(0.5);
  for (int i = 0; i < 100; ++i) {
    c.send(turn);
    c.advance(20ms);
  }
  EXPECT_NEAR(c.chassis.snapshot().target.speed, 1.0, 1e-9);
  // The driver's kinematics, the same model: 1.0 m/s beyond 20 deg; our transcription's 0.7 is the
  // node parameter max_speed_at_large_steering away.
  KinematicsLimits limits = model->limits;
  const BodyTwist sharp_turn{1.5, 0.0, 1.5 * 2.0};  // curvature 2/m: 0.66 rad inner
  const auto sharp = solve_kinematics(sharp_turn, MotionMode::kAckermann, model->geometry, limits,
                                      {}, model->profile);
  ASSERT_TRUE(sharp.ok());
  EXPECT_NEAR(sharp->achieved.vx, 1.0, 1e-9);
  limits.max_speed_at_large_steering = 0.7;
  const auto transcribed = solve_kinematics(sharp_turn, MotionMode::kAckermann, model->geometry,
                                            limits, {}, model->profile);
  ASSERT_TRUE(transcribed.ok());
  EXPECT_NEAR(transcribed->achieved.vx, 0.7, 1e-9);
}

TEST(FieldFacts, AReleasedEstopClearsItsBitWithout0x441) {
  // The manual (quoted by the notes) wants 0x441 after an e-stop in command mode; the notes could
  // not try it. Ours: the bit follows the button, and the driver's resume re-arms.
  Chassis c("mini_v3");
  c.chassis.set_emergency_stop(true);
  c.advance(40ms);
  EXPECT_EQ(bytes(last_frame(c.bus, protocol::kSystemStatusId), 4, 8),
            (std::vector<int>{0, 0, 0, 0x80}));
  c.chassis.set_emergency_stop(false);
  c.advance(40ms);
  EXPECT_EQ(bytes(last_frame(c.bus, protocol::kSystemStatusId), 4, 8),
            (std::vector<int>{0, 0, 0, 0}));
  EXPECT_EQ(last_frame(c.bus, protocol::kSystemStatusId).data[0], 0);
}

// ---- the table itself ---------------------------------------------------------------------------

// Every row of docs/FIELD_FACTS.md names at least one test, and every test it names exists in the
// library's tests (TEST, TEST_P or TEST_F of that suite and name; a bare suite name: the suite).
TEST(FieldFactsTable, EveryRowNamesTestsThatExist) {
  std::ifstream doc(std::string(RANGER_SOURCE_DIR) + "/../docs/FIELD_FACTS.md");
  ASSERT_TRUE(doc.good());
  std::string sources;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(RANGER_SOURCE_DIR) + "/test")) {
    if (entry.path().extension() != ".cpp") continue;
    std::ifstream in(entry.path());
    sources += std::string(std::istreambuf_iterator<char>(in), {});
  }
  int rows = 0;
  for (std::string line; std::getline(doc, line);) {
    if (line.rfind("| ", 0) != 0 || line.rfind("| fact ", 0) == 0) continue;
    ++rows;
    SCOPED_TRACE(line.substr(0, 80));
    const std::size_t last = line.rfind('|', line.size() - 2);
    ASSERT_NE(last, std::string::npos);
    const std::string cell = line.substr(last);
    int named = 0;
    for (std::size_t b = cell.find('`'); b != std::string::npos; b = cell.find('`', b + 1)) {
      const std::size_t e = cell.find('`', b + 1);
      if (e == std::string::npos) break;
      const std::string name = cell.substr(b + 1, e - b - 1);
      b = e;
      const std::size_t dot = name.find('.');
      // A file named beside its tests, or a pattern (`Field*`).
      if (name.rfind("test_", 0) == 0 || name.find('*') != std::string::npos) continue;
      ++named;
      const std::string wanted =
          dot == std::string::npos ? "(" + name + ", "
                                   : "(" + name.substr(0, dot) + ", " + name.substr(dot + 1) + ")";
      EXPECT_NE(sources.find(wanted), std::string::npos) << name << " is no test";
    }
    EXPECT_GT(named, 0) << "a row without a test";
  }
  EXPECT_GE(rows, 20);
}

}  // namespace
}  // namespace ranger
