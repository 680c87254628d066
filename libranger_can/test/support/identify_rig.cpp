#include "support/identify_rig.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace ranger::test {

using namespace std::chrono_literals;
using protocol::MotionMode;

DriverConfig auto_config() {
  DriverConfig c;
  c.protocol = ProtocolChoice::kAuto;
  return c;
}

DriverConfig forced_config(const ProtocolProfile& profile) {
  DriverConfig c;
  c.controller.profile = profile;
  return c;
}

ProtocolProfile preset(const char* name) {
  return *protocol_preset(name);
}

namespace {

DriverConfig validated(DriverConfig config) {
  EXPECT_TRUE(config.validate().ok());
  return config;
}

}  // namespace

IdentifyRig::IdentifyRig(const std::string& spec, DriverConfig config,
                         sim::SimSourceOptions options)
    : DriverSimRig(SimBus{spec, std::move(options)}, validated(std::move(config))),
      start_(clock().now()) {}

void IdentifyRig::chassis_stepping() {
  const Timestamp now = clock().now();
  const MotionRefusal before = snapshot()->controller.refusal;
  if (rearm_ && before == MotionRefusal::kRearmRequired && !rearming_) {
    (void)driver().resume();  // the operator has seen the stop
    rearming_ = true;
    ++rearms_;
    next_publish_ = now + 50ms;
  } else if (request_ && now >= next_publish_) {
    (void)driver().command(*request_);
    next_publish_ = now + 50ms;
    rearming_ = false;
  }
}

void IdentifyRig::driver_stepped() {
  const MotionRefusal r = snapshot()->controller.refusal;
  if (refusals_.empty() || refusals_.back() != r) refusals_.push_back(r);
}

void IdentifyRig::command(const BodyTwist& twist, std::optional<MotionMode> mode) {
  command(MotionRequest{twist, mode});
}

void IdentifyRig::command(const MotionRequest& request) {
  request_ = request;
  next_publish_ = clock().now();
}

bool IdentifyRig::wait_ready(bool allow_any_refusal) {
  return run_until(
      [&] {
        const auto s = snapshot();
        const bool identified = !s->identification || s->identification->decided_ok();
        const bool refusal_ok = allow_any_refusal || s->controller.refusal == MotionRefusal::kNone;
        return s->controller.control_mode == protocol::ControlMode::kCan &&
               s->controller.motion_mode.has_value() && identified && refusal_ok;
      },
      15s);
}

void IdentifyRig::drive(const BodyTwist& twist, std::optional<MotionMode> mode,
                        std::chrono::nanoseconds d, const std::function<void()>& each_step) {
  command(twist, mode);
  const Timestamp end = clock().now() + d;
  while (clock().now() < end) {
    step();
    if (each_step) each_step();
  }
}

bool IdentifyRig::drive_until_stopped(const BodyTwist& twist, std::optional<MotionMode> mode,
                                      std::chrono::nanoseconds timeout) {
  command(twist, mode);
  const Timestamp began = clock().now();
  const bool stopped = run_until(
      [&] { return snapshot()->controller.refusal == MotionRefusal::kImplausible; }, timeout);
  stopped_after_ = clock().now() - began;
  return stopped;
}

void IdentifyRig::expect_route(const std::string& label, double min_turns) {
  ASSERT_TRUE(wait_ready()) << to_string(snapshot()->controller.refusal) << ": "
                            << (snapshot()->identification ? snapshot()->identification->message
                                                           : std::string());
  const Pose2D start_truth = chassis().pose;
  const Pose2D start_odo = snapshot()->odometry.pose;
  drive({0.8, 0.0, 0.3}, MotionMode::kAckermann, 10s);  // a left arc, r = 2.7 m
  drive({0.3, 0.4, 0.0}, MotionMode::kOblique, 8s);     // crab
  drive({0.0, 0.0, 0.9}, MotionMode::kSpin, 8s);        // more than a full turn
  drive({0.0, 0.0, 0.0}, std::nullopt, 2s);
  const auto s = snapshot();
  const auto t = chassis();
  EXPECT_FALSE(s->plausibility.stop) << s->plausibility.stop->text();
  EXPECT_TRUE(s->plausibility.warnings.empty()) << s->plausibility.warnings.front().text();
  EXPECT_EQ(s->controller.refusal, MotionRefusal::kNone) << to_string(s->controller.refusal);
  // Both poses relative to where the route began, in the frame of that moment.
  auto relative = [](const Pose2D& p, const Pose2D& o) {
    const double dx = p.x - o.x, dy = p.y - o.y;
    const double c = std::cos(o.yaw), sn = std::sin(o.yaw);
    return Pose2D{c * dx + sn * dy, -sn * dx + c * dy, std::remainder(p.yaw - o.yaw, 2 * M_PI)};
  };
  const Pose2D truth_rel = relative(t.pose, start_truth);
  const Pose2D odo_rel = relative(s->odometry.pose, start_odo);
  const double distance = t.distance_travelled;
  const double turns = t.yaw_travelled / (2 * M_PI);
  const double position_error = std::hypot(odo_rel.x - truth_rel.x, odo_rel.y - truth_rel.y);
  const double yaw_error =
      std::fabs(std::remainder(odo_rel.yaw - truth_rel.yaw, 2 * M_PI)) * 180 / M_PI;
  std::printf(
      "[route] %s distance=%.3f m turns=%.2f position_error=%.4f m (%.3f %%) "
      "yaw_error=%.4f deg rearms=%d\n",
      label.c_str(), distance, turns, position_error, 100.0 * position_error / distance, yaw_error,
      rearms_);
  EXPECT_GT(distance, 5.0) << "the route moved";
  EXPECT_GT(turns, min_turns);
  EXPECT_LE(position_error, 0.01 * distance + 1e-3);
  EXPECT_LE(yaw_error, 1.0 * std::max(1.0, turns));
  EXPECT_EQ(t.motion_mode, MotionMode::kSpin);
}

bool IdentifyRig::saw_refusal(MotionRefusal r) const {
  return std::find(refusals_.begin(), refusals_.end(), r) != refusals_.end();
}

Timestamp IdentifyRig::first_send() const {
  return sent().empty() ? Timestamp::max() : sent().front().sent.frame.stamp;
}

}  // namespace ranger::test
