// Driving by the remote control (user manual section 2.3): the virtual chassis boots under its
// remote and the operator drives every motion mode with SWD and the sticks, while the driver only
// listens. The driver's odometry follows what the chassis reports (the mode from 0x291, the wheels
// from 0x271/0x281; it commands nothing), checked per segment against the chassis's ground truth
// with the budget of tests/e2e (<= 1 % of the distance, <= 1 deg per turn), in both revisions and
// on the MINI V1, from the wheels and from 0x221. With `protocol auto` the identification has to
// complete from the remote's own driving. Lock-step under a ManualClock (1 ms: the chassis, then
// the driver); no threads, no sleeping. Prints "[remote-odometry] ..." per segment and
// "[remote-identification] ..." with the simulated time the identification took.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "variant_route.hpp"

namespace ranger::variants {
namespace {

class RemoteRig {
 public:
  RemoteRig(const std::string& variant, const DriverConfig& config)
      : clock_(Timestamp{std::chrono::seconds(1000)}),
        wheel_radius_(config.controller.geometry.wheel_radius) {
    sim::SimSourceOptions options;
    options.lock_step = true;
    options.chassis.boot_in_remote_mode = true;  // under the remote from the first frame
    if (variant == "mini_v1") {
      auto model = model_preset("ranger_mini_v1");
      EXPECT_TRUE(model.ok());
      options.chassis = sim::chassis_for_model(*model, options.chassis);
    }
    auto source = sim::open_bus_source("sim:" + variant, clock_, options);
    EXPECT_TRUE(source.ok()) << (source ? "" : source.error().message);
    sim_ = std::static_pointer_cast<sim::SimBusSource>(*source);
    driver_ = std::make_unique<Driver>(config, *source, clock_);
  }
  ~RemoteRig() { driver_.reset(); }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    const Timestamp end = clock_.now() + timeout;
    while (!done()) {
      if (clock_.now() >= end) return false;
      clock_.advance(1ms);
      sim_->step(clock_.now());
      driver_->step(clock_.now());
      observe();
    }
    return true;
  }
  void run_for(std::chrono::nanoseconds d) {
    const Timestamp end = clock_.now() + d;
    run_until([&] { return clock_.now() >= end; }, d + 1s);
  }
  void remote(const std::string& line) {
    auto r = sim_->with_chassis(
        [&](sim::VirtualChassis& c) { return sim::apply_chassis_command(line, c); });
    ASSERT_TRUE(r.ok()) << line << ": " << (r ? "" : r.error().message);
  }
  sim::ChassisSnapshot chassis() { return sim_->snapshot(); }
  std::shared_ptr<const DriverSnapshot> driver() { return driver_->snapshot(); }
  Timestamp now() const { return clock_.now(); }
  double wheel_radius() const { return wheel_radius_; }
  void rearm() { driver_->resume(); }
  // While the driver has not decided its settings: did it publish an odometry step?
  std::uint64_t steps_before_decision() const { return steps_before_decision_; }

 private:
  void observe() {
    const auto s = driver_->snapshot();
    if (s->identification && !s->identification->decided_ok()) {
      steps_before_decision_ = s->odometry.steps;
    }
  }

  ManualClock clock_;
  double wheel_radius_;
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  std::uint64_t steps_before_decision_ = 0;
};

struct RemoteSegment {
  const char* name;
  const char* swd;  // top | bottom
  double left, right;
  MotionMode mode;  // what the chassis drives in
  double seconds;
};

// Every mode and the switches between them, with the sticks at fractions of full deflection (the
// chassis's own limits, so the same route fits every model).
std::vector<RemoteSegment> remote_route() {
  return {
      {"ackermann", "top", 0.25, -0.3, MotionMode::kAckermann, 8},  // a left arc
      {"ackermann_reverse", "top", -0.2, 0.3, MotionMode::kAckermann, 5},
      {"spin", "top", 0.0, -0.5, MotionMode::kSpin, 6},  // counter-clockwise
      {"spin_back", "top", 0.0, 0.5, MotionMode::kSpin, 2},
      {"oblique", "bottom", 0.25, -0.4, MotionMode::kOblique, 6},
      {"lateral", "bottom", 0.2, 1.0, MotionMode::kOblique, 4},  // full right: the oblique limit
      {"ackermann_again", "top", 0.2, 0.2, MotionMode::kAckermann, 5},
  };
}

struct Figures {
  double distance = 0, turns = 0, position_error = 0, yaw_error = 0;
};

Figures drive_segment(RemoteRig& rig, const std::string& label, const RemoteSegment& seg) {
  SCOPED_TRACE(label + " " + seg.name);
  Figures f;
  const sim::ChassisSnapshot start = rig.chassis();
  const Pose2D odom_start = rig.driver()->odometry.pose;
  rig.remote(std::string("remote swd ") + seg.swd);
  rig.remote("remote sticks " + std::to_string(seg.left) + " " + std::to_string(seg.right));
  EXPECT_TRUE(rig.run_until(
      [&] {
        const auto s = rig.chassis();
        return s.motion_mode == seg.mode && !s.switching && s.speed != 0.0;
      },
      10s))
      << label << " " << seg.name << ": the chassis is in "
      << protocol::to_string(rig.chassis().motion_mode);
  rig.run_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(seg.seconds)));
  // The mode the driver reports is the chassis's own (0x291), never one it commanded.
  const auto during = rig.driver();
  EXPECT_EQ(during->controller.motion_mode, seg.mode);
  EXPECT_EQ(during->controller.control_mode, protocol::ControlMode::kRemote);
  // The joint states are the wheels the chassis reports: angles within the wire's resolution
  // (0.001 rad), speeds within 1 mm/s.
  const sim::ChassisSnapshot moving = rig.chassis();
  EXPECT_TRUE(during->joints.has_steering && during->joints.has_wheels);
  for (std::size_t i = 0; i < kWheelCount; ++i) {
    EXPECT_NEAR(during->joints.steering_position[i], moving.wheels[i].angle, 1.5e-3)
        << "wheel " << i;
    EXPECT_NEAR(during->joints.wheel_velocity[i] * rig.wheel_radius(), moving.wheels[i].speed, 2e-3)
        << "wheel " << i;
  }
  rig.remote("remote sticks 0 0");
  EXPECT_TRUE(rig.run_until([&] { return rig.chassis().speed == 0.0; }, 5s));
  rig.run_for(300ms);  // the last feedback integrated

  const sim::ChassisSnapshot end = rig.chassis();
  const Pose2D truth = relative(start.pose, end.pose);
  const Pose2D odom = relative(odom_start, rig.driver()->odometry.pose);
  f.distance = end.distance_travelled - start.distance_travelled;
  f.turns = (end.yaw_travelled - start.yaw_travelled) / (2 * M_PI);
  f.position_error = std::hypot(odom.x - truth.x, odom.y - truth.y);
  f.yaw_error = std::abs(std::remainder(odom.yaw - truth.yaw, 2 * M_PI)) * 180 / M_PI;
  std::printf(
      "[remote-odometry] %s mode=%s distance=%.3f m turns=%.3f position_error=%.4f m (%.3f %% of "
      "distance) yaw_error=%.4f deg (%.4f deg/turn)\n",
      label.c_str(), seg.name, f.distance, f.turns, f.position_error,
      f.distance > 0 ? 100 * f.position_error / f.distance : 0.0, f.yaw_error,
      f.turns > 0 ? f.yaw_error / f.turns : 0.0);
  std::fflush(stdout);
  EXPECT_GT(f.distance + 2 * M_PI * f.turns, 0.2) << "the segment must actually move";
  EXPECT_LE(f.position_error, 0.01 * f.distance + 1e-3)
      << label << " " << seg.name << ": position error " << f.position_error << " m over "
      << f.distance << " m";
  EXPECT_LE(f.yaw_error, 1.0 * std::max(1.0, f.turns))
      << label << " " << seg.name << ": yaw error " << f.yaw_error << " deg over " << f.turns
      << " turns";
  return f;
}

struct Case {
  std::string variant;
  OdometrySource source;
};
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.variant << " (" << to_string(c.source) << " odometry)";
}

class RemoteDriving : public ::testing::TestWithParam<Case> {};

// The driver set to match the chassis (its revision and model given): it hears the remote drive.
TEST_P(RemoteDriving, OdometryFollowsEveryModeWithinBudget) {
  const Case& c = GetParam();
  const DriverConfig config = driver_config_for(c.variant, c.source);
  ASSERT_TRUE(config.validate().ok()) << config.validate().error().message;
  RemoteRig rig(c.variant, config);
  ASSERT_TRUE(rig.run_until(
      [&] {
        const auto s = rig.driver();
        return s->controller.control_mode == protocol::ControlMode::kRemote &&
               s->controller.motion_mode;
      },
      2s));
  const std::string label = "variant=" + c.variant + " source=" + std::string(to_string(c.source));
  for (const RemoteSegment& seg : remote_route())
    drive_segment(rig, label, seg);
  // The driver never took control: it sent no motion command and requested nothing.
  EXPECT_EQ(rig.chassis().control_mode, protocol::ControlMode::kRemote);
}

INSTANTIATE_TEST_SUITE_P(LockStep, RemoteDriving,
                         ::testing::Values(Case{"manual", OdometrySource::kWheels},
                                           Case{"manual", OdometrySource::kMotion},
                                           Case{"agx_v2", OdometrySource::kWheels},
                                           Case{"agx_v2", OdometrySource::kMotion},
                                           Case{"mini_v1", OdometrySource::kWheels},
                                           Case{"mini_v1", OdometrySource::kMotion},
                                           Case{"mini_v3", OdometrySource::kWheels},
                                           Case{"mini_v3", OdometrySource::kMotion}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           return p.param.variant + "_" + std::string(to_string(p.param.source));
                         });

}  // namespace
}  // namespace ranger::variants

namespace ranger::variants {
namespace {

// Under `protocol auto`, a chassis under its remote from the first frame: the identification
// listens, then learns the 0x271 reading from the remote's own driving (the rigid-body fit of
// steered rolling wheels, or the spin position) and says what it still lacks for commanding (the
// 0x111 readings, probed at standstill once CAN command mode is granted). Until the wheels'
// reading is decided nothing is published; from then on the odometry holds the budget. When the
// operator hands back (SWB up), the probe runs at standstill and the identification decides,
// the pose kept.
struct AutoCase {
  std::string variant;
  // What the operator drives first: "arc" (Ackermann, steered) or "spin" at once, "idle_arc"
  // (the arc after 15 s at rest), or "spin_at_rest" (a switch to spin mode, nothing rolling).
  const char* first;
};
void PrintTo(const AutoCase& c, std::ostream* os) {
  *os << c.variant << " (" << c.first << ")";
}

class RemoteIdentification : public ::testing::TestWithParam<AutoCase> {};

TEST_P(RemoteIdentification, CompletesFromTheRemotesDrivingAndTheOdometryHolds) {
  const AutoCase& c = GetParam();
  DriverConfig config = driver_config_for(c.variant, OdometrySource::kWheels);
  config.protocol = ProtocolChoice::kAuto;
  ASSERT_TRUE(config.validate().ok()) << config.validate().error().message;
  RemoteRig rig(c.variant, config);
  const Timestamp boot = rig.now();
  if (std::string(c.first) == "idle_arc") {
    // The operator waits: the wheels stand straight, nothing tells their reading; nothing is
    // published, and the identification says what it lacks (and does not time out).
    rig.run_for(15s);
    const auto idle = rig.driver();
    EXPECT_EQ(idle->odometry.steps, 0u);
    EXPECT_FALSE(idle->joints.has_steering);
    EXPECT_EQ(idle->identification->phase, IdentificationPhase::kAwaitingControl);
    EXPECT_NE(idle->identification->message.find("not known yet"), std::string::npos)
        << idle->identification->message;
  }
  Timestamp driving = rig.now();
  // The operator drives.
  const RemoteSegment first =
      std::string(c.first) == "spin"
          ? RemoteSegment{"spin", "top", 0.0, -0.5, MotionMode::kSpin, 3}
          : RemoteSegment{"arc", "top", 0.2, -0.3, MotionMode::kAckermann, 3};
  const bool spin_at_rest = std::string(c.first) == "spin_at_rest";
  if (spin_at_rest) {
    // Past the listening, the operator pushes the right stick only long enough for the switch
    // to spin mode to begin, then lets go: the wheels turn to the spin position and stand there,
    // nothing rolls. The spin position alone tells the reading.
    rig.run_for(2s);
    driving = rig.now();
    rig.remote("remote sticks 0 0.5");
    rig.run_for(300ms);
    rig.remote("remote sticks 0 0");
  } else {
    rig.remote(std::string("remote swd ") + first.swd);
    rig.remote("remote sticks " + std::to_string(first.left) + " " + std::to_string(first.right));
  }
  std::optional<Timestamp> wheels_known;
  ASSERT_TRUE(rig.run_until(
      [&] {
        const auto s = rig.driver();
        if (s->odometry.steps > 0 && !wheels_known) wheels_known = rig.now();
        return wheels_known.has_value();
      },
      30s))
      << c.variant << ": the identification never learned the wheels' reading under the remote: "
      << rig.driver()->identification->message;
  const auto s = rig.driver();
  ASSERT_TRUE(s->identification);
  // Not decided (nothing was probed), and it says what it lacks.
  EXPECT_EQ(s->identification->phase, IdentificationPhase::kAwaitingControl);
  EXPECT_NE(s->identification->message.find("remote"), std::string::npos)
      << s->identification->message;
  EXPECT_NE(s->identification->message.find("steering_unit_111"), std::string::npos)
      << s->identification->message;
  EXPECT_EQ(s->profile.steering_unit_271, s->identification->profile.steering_unit_271);
  if (spin_at_rest) {
    EXPECT_EQ(rig.chassis().distance_travelled + rig.chassis().yaw_travelled, 0.0);
    const auto& evidence = s->identification->evidence;
    EXPECT_TRUE(std::any_of(evidence.begin(), evidence.end(), [](const std::string& e) {
      return e.find("spin position while the remote control spins") != std::string::npos;
    })) << ::testing::PrintToString(evidence);
  }
  std::printf(
      "[remote-identification] variant=%s first=%s wheels_known_after=%.3f s from boot, %.3f s "
      "of driving (simulated)\n",
      c.variant.c_str(), c.first, seconds(*wheels_known - boot), seconds(*wheels_known - driving));
  std::fflush(stdout);
  rig.remote("remote sticks 0 0");
  ASSERT_TRUE(rig.run_until([&] { return rig.chassis().speed == 0.0; }, 5s));
  // From here on the odometry holds the budget in every mode.
  const std::string label = "variant=" + c.variant + " source=wheels protocol=auto";
  for (const RemoteSegment& seg : remote_route())
    drive_segment(rig, label, seg);
  // Still not decided, still refusing nothing it would have to guess; no failure either (the
  // remote in charge is not a timeout).
  EXPECT_EQ(rig.driver()->identification->phase, IdentificationPhase::kAwaitingControl);
  // SWB up: CAN command mode. The probe waits for the commander's re-arm (the remote's stop is
  // latched), then runs at standstill and decides, the pose kept.
  const Pose2D before = rig.driver()->odometry.pose;
  rig.remote("remote can");
  rig.run_for(3s);
  EXPECT_EQ(rig.driver()->identification->phase, IdentificationPhase::kAwaitingControl);
  EXPECT_NE(rig.driver()->identification->message.find("re-arm"), std::string::npos)
      << rig.driver()->identification->message;
  rig.rearm();
  const Timestamp rearmed = rig.now();
  ASSERT_TRUE(rig.run_until([&] { return rig.driver()->identification->decided_ok(); }, 15s))
      << "phase " << to_string(rig.driver()->identification->phase) << ": "
      << rig.driver()->identification->message << "; chassis control mode "
      << protocol::to_string(rig.chassis().control_mode) << ", refusal "
      << to_string(rig.driver()->controller.refusal);
  std::printf("[remote-identification] variant=%s decided %.3f s after the re-arm (simulated)\n",
              c.variant.c_str(), seconds(rig.now() - rearmed));
  const Pose2D after = rig.driver()->odometry.pose;
  EXPECT_NEAR(after.x, before.x, 1e-3);
  EXPECT_NEAR(after.y, before.y, 1e-3);
  // What the probe decides is the chassis's (the rest keeps the revision's preset, as ever).
  const ProtocolProfile& got = rig.driver()->profile;
  const ProtocolProfile want =
      driver_config_for(c.variant, OdometrySource::kWheels).controller.profile;
  EXPECT_EQ(got.steering_unit_111, want.steering_unit_111);
  EXPECT_EQ(got.steering_sign_111, want.steering_sign_111);
  EXPECT_EQ(got.steering_unit_221, want.steering_unit_221);
  EXPECT_EQ(got.steering_sign_221, want.steering_sign_221);
  EXPECT_EQ(got.steering_unit_271, want.steering_unit_271);
  EXPECT_EQ(got.steering_sign_271, want.steering_sign_271);
  EXPECT_EQ(got.steering_reference, want.steering_reference);
}

INSTANTIATE_TEST_SUITE_P(
    LockStep, RemoteIdentification,
    ::testing::Values(AutoCase{"manual", "arc"}, AutoCase{"manual", "spin"},
                      AutoCase{"agx_v2", "arc"}, AutoCase{"agx_v2", "spin"},
                      AutoCase{"mini_v1", "arc"}, AutoCase{"mini_v1", "spin"},
                      AutoCase{"steer_left_positive", "arc"}, AutoCase{"inner_angle", "spin"},
                      AutoCase{"manual", "idle_arc"}, AutoCase{"agx_v2", "idle_arc"},
                      AutoCase{"mini_v1", "idle_arc"}, AutoCase{"manual", "spin_at_rest"},
                      AutoCase{"agx_v2", "spin_at_rest"}, AutoCase{"mini_v1", "spin_at_rest"},
                      AutoCase{"mini_v3", "arc"}, AutoCase{"mini_v3", "spin"},
                      AutoCase{"mini_v3", "idle_arc"}, AutoCase{"mini_v3", "spin_at_rest"}),
    [](const ::testing::TestParamInfo<AutoCase>& p) {
      return p.param.variant + "_" + p.param.first;
    });

}  // namespace
}  // namespace ranger::variants
