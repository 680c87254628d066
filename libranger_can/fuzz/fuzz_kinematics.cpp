// Fuzzes the path from a requested body twist to the bytes of a 0x111 motion command with
// arbitrary doubles (NaN, infinities, 1e300, denormals), and the speed limiter in front of it.
//
// Properties (each a FUZZ_CHECK):
//  * solve_kinematics refuses a non-finite twist with kNotFinite and solves every finite one;
//  * the command it produces is finite and within the limits it was given (speed, the lower
//    speed at large steering, steering per mode, spin), and so is the twist it says it achieves;
//  * encoding that command gives a 0x111 whose int16 fields are the command's values rounded
//    (never wrapped: the sign and the magnitude on the wire match the command);
//  * encoding any MotionCommand directly saturates instead of wrapping and refuses NaN/inf;
//  * the speed limiter never returns NaN/inf for finite input, holds on a non-finite target and
//    keeps its velocity limits.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_input.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/mode_selector.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/control/speed_limiter.hpp"

namespace {

using ranger::fuzz::consume_double;
using ranger::fuzz::sign_of;
using ranger::protocol::MotionMode;

constexpr double kRadToCentiDeg = 18000.0 / M_PI;
// RANGER_FUZZ_TRACE=1 prints the speed limiter's steps (for reading a reproducer).
const bool kTrace = std::getenv("RANGER_FUZZ_TRACE") != nullptr;
// 0x111 limits on the wire (manual 3.2 and interpretation.hpp open point 1).
constexpr int kWireMaxLinear = 2600;    // mm/s
constexpr int kWireMaxSpin = 1000;      // mm/s
constexpr int kWireMaxSteering = 9000;  // 0.01 deg (oblique; Ackermann is +-4000)

struct Wire111 {
  int linear, spin, steering;
};
Wire111 wire_fields(const ranger::CanFrame& f) {
  auto i16 = [&](int at) {
    return static_cast<int>(static_cast<std::int16_t>((f.data[at] << 8) | f.data[at + 1]));
  };
  return {i16(0), i16(4), i16(6)};
}

// The value the wire must carry for `value` * `scale` saturated at +-limit.
int expected_wire(double value, double scale, int limit) {
  const double scaled =
      std::clamp(value * scale, -static_cast<double>(limit), static_cast<double>(limit));
  return static_cast<int>(std::lround(scaled));
}

// Encodes `cmd` and checks the frame: id/dlc, reserved bytes, each field = the value rounded and
// saturated (tolerance one count for values exactly on a rounding boundary).
void check_encoding(const ranger::MotionCommand& cmd) {
  const bool finite = std::isfinite(cmd.linear_speed) && std::isfinite(cmd.spin_speed) &&
                      std::isfinite(cmd.steering_angle);
  const auto frame = ranger::encode(cmd);
  if (!finite) {
    FUZZ_CHECK(!frame.ok());
    FUZZ_CHECK(frame.error().code == ranger::Errc::kNotFinite);
    FUZZ_CHECK(!frame.error().message.empty());
    return;
  }
  FUZZ_CHECK(frame.ok());
  FUZZ_CHECK(frame->id == ranger::protocol::kMotionCommandId);
  FUZZ_CHECK(frame->dlc == 8);
  FUZZ_CHECK(frame->data[2] == 0 && frame->data[3] == 0);
  const Wire111 w = wire_fields(*frame);
  FUZZ_CHECK(std::abs(w.linear) <= kWireMaxLinear);
  FUZZ_CHECK(std::abs(w.spin) <= kWireMaxSpin);
  FUZZ_CHECK(std::abs(w.steering) <= kWireMaxSteering);
  // Never wrapped: a wire value of the opposite sign is impossible.
  FUZZ_CHECK(sign_of(w.linear) * sign_of(cmd.linear_speed) >= 0);
  FUZZ_CHECK(sign_of(w.spin) * sign_of(cmd.spin_speed) >= 0);
  FUZZ_CHECK(sign_of(w.steering) * sign_of(cmd.steering_angle) >= 0);
  FUZZ_CHECK(std::abs(w.linear - expected_wire(cmd.linear_speed, 1000.0, kWireMaxLinear)) <= 1);
  FUZZ_CHECK(std::abs(w.spin - expected_wire(cmd.spin_speed, 1000.0, kWireMaxSpin)) <= 1);
  FUZZ_CHECK(std::abs(w.steering -
                      expected_wire(cmd.steering_angle, kRadToCentiDeg, kWireMaxSteering)) <= 1);
  // And the decoder reads back what was meant (within one count).
  const auto back = ranger::decode(*frame);
  FUZZ_CHECK(back.ok());
  const auto* m = std::get_if<ranger::MotionCommand>(&*back);
  FUZZ_CHECK(m != nullptr);
  FUZZ_CHECK(std::abs(m->linear_speed * 1000.0 - w.linear) < 1e-6);
  FUZZ_CHECK(std::abs(m->spin_speed * 1000.0 - w.spin) < 1e-6);
  FUZZ_CHECK(std::abs(m->steering_angle * kRadToCentiDeg - w.steering) < 1e-6);
}

ranger::KinematicsLimits consume_limits(FuzzedDataProvider& in) {
  ranger::KinematicsLimits limits;
  if (!in.ConsumeBool()) return limits;  // defaults half of the time
  ranger::KinematicsLimits fuzzed;
  fuzzed.max_linear_speed = consume_double(in);
  fuzzed.max_speed_at_large_steering = consume_double(in);
  fuzzed.max_ackermann_steering = consume_double(in);
  fuzzed.max_oblique_steering = consume_double(in);
  fuzzed.max_spin_wheel_speed = consume_double(in);
  // Limits validate() refuses are never used by the driver (the node and CLI validate first).
  return fuzzed.validate().ok() ? fuzzed : limits;
}

bool finite(const ranger::BodyTwist& t) {
  return std::isfinite(t.vx) && std::isfinite(t.vy) && std::isfinite(t.wz);
}

void fuzz_solve(FuzzedDataProvider& in) {
  const ranger::BodyTwist twist{consume_double(in), consume_double(in), consume_double(in)};
  const auto mode = static_cast<MotionMode>(in.ConsumeIntegralInRange<int>(0, 2));
  const ranger::KinematicsLimits limits = consume_limits(in);
  const ranger::VehicleGeometry geometry;

  const auto solution = ranger::solve_kinematics(twist, mode, geometry, limits);
  if (!finite(twist)) {
    FUZZ_CHECK(!solution.ok());
    FUZZ_CHECK(solution.error().code == ranger::Errc::kNotFinite);
    return;
  }
  FUZZ_CHECK(solution.ok());
  const ranger::MotionCommand& cmd = solution->command;
  FUZZ_CHECK(solution->mode == mode);
  FUZZ_CHECK(std::isfinite(cmd.linear_speed) && std::isfinite(cmd.spin_speed) &&
             std::isfinite(cmd.steering_angle));
  FUZZ_CHECK(finite(solution->achieved));

  constexpr double kEps = 1e-9;
  const double max_speed =
      std::min(limits.max_linear_speed, ranger::interpretation::kMaxLinearSpeedMps);
  FUZZ_CHECK(std::abs(cmd.linear_speed) <= max_speed + kEps);
  if (std::abs(cmd.steering_angle) > ranger::interpretation::kLargeSteeringThresholdRad + kEps) {
    FUZZ_CHECK(std::abs(cmd.linear_speed) <= limits.max_speed_at_large_steering + kEps);
  }
  FUZZ_CHECK(std::abs(cmd.spin_speed) <= limits.max_spin_wheel_speed + kEps);
  const double max_steering =
      mode == MotionMode::kOblique ? limits.max_oblique_steering : limits.max_ackermann_steering;
  FUZZ_CHECK(std::abs(cmd.steering_angle) <= max_steering + kEps);

  check_encoding(cmd);

  // The simulator's direction of the same relations stays finite for any command it can get.
  FUZZ_CHECK(finite(ranger::twist_from_command(cmd, mode, geometry)));
  const auto wheels = ranger::wheel_states_from_twist(solution->achieved, geometry);
  for (const auto& w : wheels) {
    FUZZ_CHECK(std::isfinite(w.angle) && std::isfinite(w.speed));
    FUZZ_CHECK(std::abs(w.angle) <= M_PI / 2 + kEps);
  }
}

void fuzz_encode(FuzzedDataProvider& in) {
  ranger::MotionCommand cmd;
  cmd.linear_speed = consume_double(in);
  cmd.spin_speed = consume_double(in);
  cmd.steering_angle = consume_double(in);
  check_encoding(cmd);
}

void fuzz_speed_limiter(FuzzedDataProvider& in) {
  ranger::SpeedLimits limits;
  limits.has_velocity_limits = in.ConsumeBool();
  limits.has_acceleration_limits = in.ConsumeBool();
  limits.min_velocity = consume_double(in);
  limits.max_velocity = consume_double(in);
  limits.min_acceleration = consume_double(in);
  limits.max_acceleration = consume_double(in);
  if (!limits.validate().ok()) return;
  const ranger::SpeedLimiter limiter(limits);
  double previous = limiter.limit_velocity(in.ConsumeFloatingPointInRange<double>(-10.0, 10.0));
  // A short sequence, as a control loop would run it.
  for (int i = 0; i < 8 && in.remaining_bytes() > 0; ++i) {
    const double target = consume_double(in);
    const double dt = consume_double(in);
    const double out = limiter.limit(target, previous, dt);
    if (kTrace) {
      std::fprintf(stderr, "limits v[%g, %g]%s a[%g, %g]%s: limit(%g, %g, %g) = %g\n",
                   limits.min_velocity, limits.max_velocity,
                   limits.has_velocity_limits ? "" : " off", limits.min_acceleration,
                   limits.max_acceleration, limits.has_acceleration_limits ? "" : " off", target,
                   previous, dt, out);
    }
    // Targets near DBL_MAX may legitimately overflow `target - previous` (not a driver input);
    // such a step ends the sequence.
    if (std::abs(target) >= 1e150 && !std::isfinite(out)) break;
    FUZZ_CHECK(std::isfinite(out));
    if (limits.has_velocity_limits) {
      FUZZ_CHECK(out >= limits.min_velocity && out <= limits.max_velocity);
    }
    if (!std::isfinite(target)) FUZZ_CHECK(out == limiter.limit_velocity(previous));
    previous = out;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0:
      fuzz_solve(in);
      break;
    case 1:
      fuzz_encode(in);
      break;
    default:
      fuzz_speed_limiter(in);
      break;
  }
  return 0;
}
