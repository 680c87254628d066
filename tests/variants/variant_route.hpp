// The route every variant drives (Ackermann arc, oblique crab, spin), with the driver configured
// from the variant's own driver options, and the odometry budget of tests/e2e (e2e_suite.hpp):
// per segment, the driver's odometry against the chassis's ground truth, relative to where the
// segment began, <= 1 % of the distance travelled and <= 1 deg of heading per full turn.
//
// Two rigs: lock-step on the in-process bus (test_variants_loopback.cpp) and real SocketCAN on
// vcan0 with the chassis and the driver on their own threads (test_variants_vcan.cpp). Each prints
// "[variant-odometry] bus=... variant=... source=... mode=... distance=... position_error=...
// yaw_error=..." per segment.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"

namespace ranger::variants {

using namespace std::chrono_literals;
using protocol::MotionMode;

inline const sim::VariantInfo& variant_info(const std::string& name) {
  for (const auto& v : sim::variants())
    if (v.name == name) return v;
  ADD_FAILURE() << "no variant " << name;
  return sim::variants().front();
}

// The driver for a variant: its `driver` options ("--model M --protocol R --set N=V ...") over
// the RANGER model's geometry and limits (the library's defaults are the RANGER's too).
inline DriverConfig driver_config_for(const std::string& variant, OdometrySource source) {
  const sim::VariantInfo& info = variant_info(variant);
  std::istringstream words(info.driver);
  std::string model_name = "ranger";
  std::optional<std::string> revision;
  std::vector<std::string> sets;
  for (std::string w, value; words >> w;) {
    EXPECT_TRUE(static_cast<bool>(words >> value)) << info.driver;
    if (w == "--model") {
      model_name = value;
    } else if (w == "--protocol") {
      revision = value;
    } else if (w == "--set") {
      sets.push_back(value);
    } else {
      ADD_FAILURE() << "unknown option " << w << " in " << info.driver;
    }
  }
  auto model = model_preset(model_name);
  EXPECT_TRUE(model.ok());
  DriverConfig c;
  c.controller.geometry = model->geometry;
  c.controller.limits = model->limits;
  auto profile = model_profile(*model, revision.value_or(model->protocol));
  EXPECT_TRUE(profile.ok()) << (profile ? "" : profile.error().message);
  c.controller.profile = *profile;
  for (const auto& s : sets)
    EXPECT_TRUE(apply_setting(c.controller.profile, s).ok()) << s;
  c.odometry.geometry = model->geometry;
  c.odometry.source = source;
  // As tests/e2e: a VM stalls now and then; integrating a gap is right (the chassis moves on).
  c.odometry.max_step = 2s;
  return c;
}

class Rig {
 public:
  virtual ~Rig() = default;
  // Runs until `done()` or `timeout` of the rig's time (times timing_slack()); returns done().
  virtual bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) = 0;
  virtual sim::ChassisSnapshot chassis() = 0;
  virtual std::shared_ptr<const DriverSnapshot> driver() = 0;
  // The caller wants `request` from now on (re-issued every 100 ms by the rig).
  virtual void command(const MotionRequest& request) = 0;
  virtual std::string name() const = 0;
  virtual double timing_slack() const { return 1.0; }

  void run_for(std::chrono::nanoseconds d) {
    bool never = false;
    run_until([&] { return never; }, d);
  }
};

inline Pose2D relative(const Pose2D& from, const Pose2D& to) {
  const double dx = to.x - from.x, dy = to.y - from.y;
  const double c = std::cos(from.yaw), s = std::sin(from.yaw);
  return {c * dx + s * dy, -s * dx + c * dy, std::remainder(to.yaw - from.yaw, 2 * M_PI)};
}

struct Segment {
  const char* name;
  MotionMode mode;
  BodyTwist twist;
  std::chrono::nanoseconds duration;
};

// Within every model's limits (the MINI V1 steers 40 deg at most in oblique mode). The spin rate
// is 0.5 rad/s, or 80 % of what the model can (the MINI V1: 0.3 rad/s): at low wheel speeds the
// 1 mm/s resolution of 0x281 shows in the wheel odometry of a chassis whose spin is a yaw rate
// (its wheel speeds are not on the wire's grid: 0.25 rad/s on a RANGER reads 0.34 % slow,
// 1.2 deg per turn; 0.5 rad/s 0.16 deg per turn).
inline std::vector<Segment> route(const KinematicsLimits& limits, const VehicleGeometry& geometry,
                                  double time_scale = 1.0) {
  auto d = [&](double s) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(s * time_scale));
  };
  const double spin =
      std::min(0.5, 0.8 * limits.max_spin_wheel_speed / geometry.wheel_radius_from_centre());
  return {
      {"ackermann", MotionMode::kAckermann, {0.6, 0.0, 0.25}, d(10)},  // a left arc, r = 2.4 m
      {"ackermann_reverse", MotionMode::kAckermann, {-0.4, 0.0, 0.2}, d(5)},
      {"oblique", MotionMode::kOblique, {0.4, 0.25, 0.0}, d(8)},     // crab, 32 deg
      {"spin", MotionMode::kSpin, {0.0, 0.0, spin}, d(3.0 / spin)},  // 3 rad counter-clockwise
      {"spin_back", MotionMode::kSpin, {0.0, 0.0, -spin}, d(1.0 / spin)},
  };
}

inline bool ready(const DriverSnapshot& s) {
  return s.controller.control_mode == protocol::ControlMode::kCan && s.controller.motion_mode &&
         s.controller.refusal == MotionRefusal::kNone;
}

// Drives the route; checks every segment against the budget, naming the variant, the mode and the
// figures on failure.
inline void drive_route(Rig& rig, const std::string& variant, const std::string& source,
                        const std::vector<Segment>& segments) {
  const auto slack = [&](std::chrono::nanoseconds t) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(t * rig.timing_slack());
  };
  ASSERT_TRUE(rig.run_until([&] { return ready(*rig.driver()); }, slack(5s)))
      << variant << ": the driver never got the chassis into CAN mode; refusal "
      << to_string(rig.driver()->controller.refusal);
  for (const Segment& seg : segments) {
    SCOPED_TRACE(variant + " " + seg.name);
    const sim::ChassisSnapshot start = rig.chassis();
    const Pose2D odom_start = rig.driver()->odometry.pose;
    rig.command({seg.twist, seg.mode});
    ASSERT_TRUE(rig.run_until(
        [&] {
          const auto s = rig.chassis();
          return s.motion_mode == seg.mode && !s.switching && s.speed != 0.0;
        },
        slack(10s)))
        << variant << " " << seg.name << ": the chassis is in "
        << protocol::to_string(rig.chassis().motion_mode) << ", refusal "
        << to_string(rig.driver()->controller.refusal);
    rig.run_for(seg.duration);
    rig.command({BodyTwist{}, seg.mode});
    ASSERT_TRUE(rig.run_until([&] { return rig.chassis().speed == 0.0; }, slack(5s)));
    rig.run_for(300ms);  // the last feedback integrated

    const sim::ChassisSnapshot end = rig.chassis();
    const Pose2D truth = relative(start.pose, end.pose);
    const Pose2D odom = relative(odom_start, rig.driver()->odometry.pose);
    const double distance = end.distance_travelled - start.distance_travelled;
    const double turns = (end.yaw_travelled - start.yaw_travelled) / (2 * M_PI);
    const double position_error = std::hypot(odom.x - truth.x, odom.y - truth.y);
    const double yaw_error = std::abs(std::remainder(odom.yaw - truth.yaw, 2 * M_PI)) * 180 / M_PI;
    std::printf(
        "[variant-odometry] bus=%s variant=%s source=%s mode=%s distance=%.3f m turns=%.3f "
        "position_error=%.4f m (%.3f %% of distance) yaw_error=%.4f deg (%.4f deg/turn)\n",
        rig.name().c_str(), variant.c_str(), source.c_str(), seg.name, distance, turns,
        position_error, distance > 0 ? 100 * position_error / distance : 0.0, yaw_error,
        turns > 0 ? yaw_error / turns : 0.0);
    std::fflush(stdout);
    EXPECT_GT(distance + 2 * M_PI * turns, 0.2) << "the segment must actually move";
    EXPECT_LE(position_error, 0.01 * distance + 1e-3)
        << variant << " " << seg.name << ": position error " << position_error << " m over "
        << distance << " m";
    EXPECT_LE(yaw_error, 1.0 * std::max(1.0, turns))
        << variant << " " << seg.name << ": yaw error " << yaw_error << " deg over " << turns
        << " turns";
    EXPECT_EQ(rig.driver()->controller.counters.mode_switch_timeouts, 0u);
  }
}

}  // namespace ranger::variants
