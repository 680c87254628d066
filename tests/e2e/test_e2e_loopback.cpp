// The end-to-end suite (e2e_suite.hpp) on the in-process loopback bus, in lock-step: a ManualClock
// advances 1 ms at a time; each step the chassis handles what arrived and sends what fell due,
// then the driver reads, decides and sends. Deterministic, no threads, no sleeping.
#include "e2e_suite.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/transport/loopback_bus.hpp"

namespace ranger::e2e {
namespace {

constexpr std::chrono::nanoseconds kStep = 1ms;

LoopbackOptions options_for(const Clock& clock) {
  LoopbackOptions o;
  o.interface = "e2e0";
  o.clock = &clock;
  return o;
}

class LoopbackRig final : public Rig {
 public:
  LoopbackRig()
      : clock_(Timestamp{std::chrono::seconds(1000)}),
        network_(options_for(clock_)),
        chassis_bus_(network_.connect()),
        driver_bus_(network_.connect()),
        chassis_(*chassis_bus_, sim::VirtualChassisConfig{}, clock_.now()) {
    attach_driver(*driver_bus_);
  }
  ~LoopbackRig() override { release_driver(); }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) override {
    const Timestamp end = clock_.now() + timeout;
    while (clock_.now() < end) {
      clock_.advance(kStep);
      chassis_.poll(clock_.now());
      driver_step(clock_.now(), 0ns);
      if (done()) return true;
    }
    return done();
  }
  void with_chassis(const std::function<void(sim::VirtualChassis&)>& f) override { f(chassis_); }
  Timestamp now() const override { return clock_.now(); }
  bool deterministic() const override { return true; }
  double timing_slack() const override { return 1.0; }
  std::string name() const override { return "loopback"; }

 private:
  ManualClock clock_;
  LoopbackNetwork network_;
  std::unique_ptr<LoopbackBus> chassis_bus_;
  std::unique_ptr<LoopbackBus> driver_bus_;
  sim::VirtualChassis chassis_;
};

INSTANTIATE_TYPED_TEST_SUITE_P(Loopback, E2e, LoopbackRig);

}  // namespace
}  // namespace ranger::e2e
