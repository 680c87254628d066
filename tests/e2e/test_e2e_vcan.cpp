// The end-to-end suite (e2e_suite.hpp) over real SocketCAN on vcan0: the virtual chassis on its
// own thread (VirtualChassisRunner), the driver loop on the test's thread, both on the real
// clock, two kernel sockets between them. Needs vcan0 (fails, never skips, without it); run by
// scripts/run_vcan_tests.sh natively or inside the throwaway VM. Assertions are on outcomes;
// time limits are generous (timing_slack) because the VM runs several times slower.
#include <thread>

#include "e2e_suite.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"
#include "ranger_can/sim/virtual_chassis_runner.hpp"

namespace ranger::e2e {
namespace {

constexpr const char* kInterface = "vcan0";

std::unique_ptr<SocketCanBus> open_or_fail() {
  auto bus = SocketCanBus::open(kInterface);
  if (!bus) {
    ADD_FAILURE() << "cannot open " << kInterface << ": " << bus.error().message;
    return nullptr;
  }
  return std::move(*bus);
}

class VcanRig final : public Rig {
 public:
  // Under qemu's emulation the chassis's sending thread stalls for up to half a second now and
  // then; with the default 100 ms link timeout each stall would be a link loss, and link loss is
  // an involuntary stop that latches. The link-loss cases silence the chassis for seconds, so a
  // timeout above the VM's stalls keeps them meaningful (the exact 100 ms is tested in lock-step).
  static ControllerConfig controller_config() {
    ControllerConfig c;
    c.link_timeout = std::chrono::milliseconds(800);
    return c;
  }

  VcanRig() : chassis_bus_(open_or_fail()), driver_bus_(open_or_fail()) {
    if (!chassis_bus_ || !driver_bus_) return;
    runner_ = std::make_unique<sim::VirtualChassisRunner>(*chassis_bus_,
                                                          sim::VirtualChassisConfig{}, clock_);
    attach_driver(*driver_bus_, controller_config());
  }
  ~VcanRig() override {
    release_driver();
    if (runner_) runner_->stop();
  }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) override {
    if (!runner_) return false;
    const Timestamp end = clock_.now() + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                             timeout * timing_slack());
    while (clock_.now() < end) {
      if (driver_dead()) {
        std::this_thread::sleep_for(2ms);
      } else {
        const auto wait = std::clamp<std::chrono::nanoseconds>(
            controller().next_tick_due() - clock_.now(), 0ns, 5ms);
        driver_step(clock_.now(), wait);
      }
      EXPECT_TRUE(runner_->running()) << runner_->failure();
      if (done()) return true;
    }
    return done();
  }
  void with_chassis(const std::function<void(sim::VirtualChassis&)>& f) override {
    if (runner_) runner_->with_chassis(f);
  }
  Timestamp now() const override { return clock_.now(); }
  bool deterministic() const override { return false; }
  double timing_slack() const override { return 5.0; }
  std::string name() const override { return "vcan"; }

 private:
  SteadyClock clock_;
  std::unique_ptr<SocketCanBus> chassis_bus_;
  std::unique_ptr<SocketCanBus> driver_bus_;
  std::unique_ptr<sim::VirtualChassisRunner> runner_;
};

INSTANTIATE_TYPED_TEST_SUITE_P(Vcan, E2e, VcanRig);

}  // namespace
}  // namespace ranger::e2e
