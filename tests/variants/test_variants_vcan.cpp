// The variants whose difference is on the wire itself (manual, agx_v2, padded, mini_v3) over real
// SocketCAN on vcan0: the virtual chassis on its own thread (VirtualChassisRunner), the driver
// runtime on its own (Driver::start), both on the real clock; the route of variant_route.hpp,
// shortened, with the wheel odometry. Needs vcan0 (fails, never skips, without it); run by
// scripts/run_vcan_tests.sh natively or inside the throwaway VM. Time limits are generous
// (timing_slack); the test's thread only re-issues the command and looks.
#include <thread>

#include "ranger_can/clock.hpp"
#include "ranger_can/sim/virtual_chassis_runner.hpp"
#include "ranger_can/transport/bus_source.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"
#include "variant_route.hpp"

namespace ranger::variants {
namespace {

constexpr const char* kInterface = "vcan0";

class VcanRig final : public Rig {
 public:
  VcanRig(const std::string& variant, DriverConfig config) {
    auto bus = SocketCanBus::open(kInterface);
    if (!bus) {
      ADD_FAILURE() << "cannot open " << kInterface << ": " << bus.error().message;
      return;
    }
    chassis_bus_ = std::move(*bus);
    auto chassis = sim::apply_variant(variant, sim::VirtualChassisConfig{});
    EXPECT_TRUE(chassis.ok());
    runner_ = std::make_unique<sim::VirtualChassisRunner>(*chassis_bus_, *chassis, clock_);
    auto source = ranger::open_bus_source(kInterface, clock_);
    if (!source) {
      ADD_FAILURE() << source.error().message;
      return;
    }
    // As tests/e2e's VcanRig: a link timeout above the VM's stalls.
    config.controller.link_timeout = 800ms;
    driver_ =
        std::make_unique<Driver>(config, std::shared_ptr<BusSource>(std::move(*source)), clock_);
    driver_->start();
  }
  ~VcanRig() override {
    if (driver_) driver_->stop();
    driver_.reset();
    if (runner_) runner_->stop();
  }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) override {
    if (!driver_ || !runner_) return false;
    const Timestamp end = clock_.now() + timeout;  // drive_route stretches its waits itself
    while (!done()) {
      if (clock_.now() >= end) return false;
      if (request_ && clock_.now() >= next_request_) {
        EXPECT_TRUE(driver_->command(*request_).ok());
        next_request_ = clock_.now() + 100ms;
      }
      EXPECT_TRUE(runner_->running()) << runner_->failure();
      std::this_thread::sleep_for(5ms);  // the driver and the chassis run on their own threads
    }
    return true;
  }
  sim::ChassisSnapshot chassis() override {
    if (!runner_) return {};
    return runner_->with_chassis([](sim::VirtualChassis& c) { return c.snapshot(); });
  }
  std::shared_ptr<const DriverSnapshot> driver() override {
    return driver_ ? driver_->snapshot() : std::make_shared<const DriverSnapshot>();
  }
  void command(const MotionRequest& request) override {
    request_ = request;
    next_request_ = clock_.now();
  }
  std::string name() const override { return "vcan"; }
  double timing_slack() const override { return 5.0; }

 private:
  SteadyClock clock_;
  std::unique_ptr<SocketCanBus> chassis_bus_;
  std::unique_ptr<sim::VirtualChassisRunner> runner_;
  std::unique_ptr<Driver> driver_;
  std::optional<MotionRequest> request_;
  Timestamp next_request_{0};
};

class VcanVariants : public ::testing::TestWithParam<std::string> {};

TEST_P(VcanVariants, DrivesTheRouteWithOdometryWithinBudget) {
  const std::string& variant = GetParam();
  const DriverConfig config = driver_config_for(variant, OdometrySource::kWheels);
  VcanRig rig(variant, config);
  // Half the loopback route's durations: the VM runs in real time.
  drive_route(rig, variant, "wheels",
              route(config.controller.limits, config.controller.geometry, 0.5));
}

INSTANTIATE_TEST_SUITE_P(Vcan, VcanVariants,
                         ::testing::Values("manual", "agx_v2", "padded", "mini_v3"));

}  // namespace
}  // namespace ranger::variants
