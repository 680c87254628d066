// Cost of the driver's brain per 20 ms cycle: the controller consuming one feedback cycle
// (13 frames) plus its tick, the odometry consuming its 4 frames, and the kinematics / per-wheel
// fit alone. Wall-clock and noisy on a shared machine: use --benchmark_repetitions=5 and the
// median.
//   bench_control --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/mode_selector.hpp"
#include "ranger_can/control/odometry.hpp"

namespace {

using namespace std::chrono_literals;
using ranger::BodyTwist;
using ranger::CanFrame;
using ranger::Message;
using ranger::protocol::MotionMode;

// Accepts and forgets every frame.
class NullBus final : public ranger::Bus {
 public:
  ranger::Status send(const CanFrame&) override {
    ++sent;
    return ranger::ok_status();
  }
  ranger::Result<CanFrame> receive(std::chrono::nanoseconds) override {
    return ranger::Error{ranger::Errc::kTimeout, "null bus"};
  }
  int fd() const override { return -1; }
  ranger::BusStatus status() const override { return {}; }
  void set_filter(const std::vector<std::uint32_t>&) override {}
  std::string name() const override { return "null"; }
  std::uint64_t sent = 0;
};

CanFrame frame_of(const Message& m) {
  ranger::Result<CanFrame> f = ranger::encode(m);
  return f.ok() ? *f : CanFrame{};
}

// One 20 ms feedback cycle of a chassis in CAN mode driving a left turn.
std::vector<CanFrame> feedback_cycle() {
  std::vector<CanFrame> frames;
  ranger::SystemStatus st;
  st.control_mode = ranger::protocol::ControlMode::kCan;
  st.control_mode_raw = 0x01;
  st.battery_voltage = 50;
  frames.push_back(frame_of(st));
  frames.push_back(frame_of(ranger::MotionFeedback{0.8, -0.2}));
  for (int m = 1; m <= 8; ++m) {
    frames.push_back(frame_of(ranger::MotorHighSpeedFeedback{m, 300.0, 2.0, 1000 * m}));
  }
  const ranger::WheelStates w =
      ranger::wheel_states_from_twist({0.8, 0, 0.4}, ranger::VehicleGeometry{});
  ranger::SteeringAnglesFeedback angles;
  ranger::WheelSpeedsFeedback speeds;
  for (std::size_t i = 0; i < 4; ++i) {
    angles.angles[i] = -w[i].angle;
    speeds.speeds[i] = w[i].speed;
  }
  frames.push_back(frame_of(angles));
  frames.push_back(frame_of(speeds));
  ranger::MotionModeFeedback mm;
  frames.push_back(frame_of(mm));
  return frames;
}

void BM_ControllerFeedbackCycleAndTick(benchmark::State& state) {
  NullBus bus;
  ranger::ChassisController ctl(bus);
  const std::vector<CanFrame> cycle = feedback_cycle();
  ranger::Timestamp now{1s};
  for (auto _ : state) {
    for (const CanFrame& f : cycle)
      ctl.on_frame(f, now);
    (void)ctl.set_command(BodyTwist{0.8, 0, 0.4}, now);
    ctl.tick(now);
    now += 20ms;
  }
  benchmark::DoNotOptimize(bus.sent);
  state.counters["frames_per_cycle"] = static_cast<double>(cycle.size());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_ControllerFeedbackCycleAndTick);

void BM_OdometryFeedbackCycle(benchmark::State& state) {
  ranger::Odometry odom;
  const std::vector<CanFrame> all = feedback_cycle();
  std::vector<CanFrame> cycle;
  for (const CanFrame& f : all) {
    if (f.id == 0x221 || f.id == 0x271 || f.id == 0x281 || f.id == 0x291) cycle.push_back(f);
  }
  ranger::Timestamp now{1s};
  for (auto _ : state) {
    for (CanFrame f : cycle) {
      f.stamp = now;
      odom.on_frame(f);
    }
    now += 20ms;
  }
  benchmark::DoNotOptimize(odom.state().pose);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_OdometryFeedbackCycle);

void BM_SolveKinematics(benchmark::State& state) {
  const auto mode = static_cast<MotionMode>(state.range(0));
  const ranger::VehicleGeometry g;
  const ranger::KinematicsLimits limits;
  double wz = 0.1;
  for (auto _ : state) {
    auto r = ranger::solve_kinematics({0.8, mode == MotionMode::kOblique ? 0.3 : 0.0, wz}, mode, g,
                                      limits);
    benchmark::DoNotOptimize(r);
    wz = wz > 1.0 ? 0.1 : wz + 1e-3;
  }
}
BENCHMARK(BM_SolveKinematics)->Arg(0)->Arg(1)->Arg(2);

void BM_FitBodyTwist(benchmark::State& state) {
  const ranger::VehicleGeometry g;
  const ranger::WheelStates w = ranger::wheel_states_from_twist({0.8, 0.1, 0.4}, g);
  for (auto _ : state) {
    BodyTwist t = ranger::fit_body_twist(w, g);
    benchmark::DoNotOptimize(t);
  }
}
BENCHMARK(BM_FitBodyTwist);

}  // namespace
