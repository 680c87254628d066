// Every virtual chassis variant driven by the driver set to match it, in lock-step on the
// in-process bus under a ManualClock (1 ms: the chassis, then the driver): the route of
// variant_route.hpp with the odometry from the wheels (0x271 + 0x281, the default) and from 0x221
// alone (the source that reads steering_reference, feedback_speed and the spin field).
// Deterministic, no threads, no sleeping. `undecidable` is not driven: test_chassis_variants.cpp
// checks what it sends.
#include "ranger_can/clock.hpp"
#include "variant_route.hpp"

namespace ranger::variants {
namespace {

class LockStepRig final : public Rig {
 public:
  LockStepRig(const std::string& variant, const DriverConfig& config)
      : clock_(Timestamp{std::chrono::seconds(1000)}) {
    sim::SimSourceOptions options;
    options.lock_step = true;
    auto source = sim::open_bus_source("sim:" + variant, clock_, options);
    EXPECT_TRUE(source.ok()) << (source ? "" : source.error().message);
    sim_ = std::static_pointer_cast<sim::SimBusSource>(*source);
    driver_ = std::make_unique<Driver>(config, *source, clock_);
  }
  ~LockStepRig() override { driver_.reset(); }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) override {
    const Timestamp end = clock_.now() + timeout;
    while (!done()) {
      if (clock_.now() >= end) return false;
      clock_.advance(1ms);
      if (request_ && clock_.now() >= next_request_) {
        EXPECT_TRUE(driver_->command(*request_).ok());
        next_request_ = clock_.now() + 100ms;
      }
      sim_->step(clock_.now());
      driver_->step(clock_.now());
    }
    return true;
  }
  sim::ChassisSnapshot chassis() override { return sim_->snapshot(); }
  std::shared_ptr<const DriverSnapshot> driver() override { return driver_->snapshot(); }
  void command(const MotionRequest& request) override {
    request_ = request;
    next_request_ = clock_.now();
  }
  std::string name() const override { return "loopback"; }

 private:
  ManualClock clock_;
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  std::optional<MotionRequest> request_;
  Timestamp next_request_{0};
};

struct Case {
  std::string variant;
  OdometrySource source;
};
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.variant << " (" << to_string(c.source) << " odometry)";
}

class Variants : public ::testing::TestWithParam<Case> {};

TEST_P(Variants, DrivesTheRouteWithOdometryWithinBudget) {
  const Case& c = GetParam();
  const DriverConfig config = driver_config_for(c.variant, c.source);
  ASSERT_TRUE(config.validate().ok()) << config.validate().error().message;
  LockStepRig rig(c.variant, config);
  drive_route(rig, c.variant, std::string(to_string(c.source)),
              route(config.controller.limits, config.controller.geometry));
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const std::string& v : sim::variant_names()) {
    if (v == "undecidable") continue;
    out.push_back({v, OdometrySource::kWheels});
    out.push_back({v, OdometrySource::kMotion});
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(LockStep, Variants, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           return param_info.param.variant + "_" +
                                  std::string(to_string(param_info.param.source));
                         });

TEST(VariantTable, EveryVariantButUndecidableIsDriven) {
  EXPECT_EQ(cases().size(), 2 * (sim::variant_names().size() - 1));
}

TEST(VariantTable, TheDriverOptionsOfEveryVariantMakeAValidConfig) {
  for (const std::string& v : sim::variant_names()) {
    SCOPED_TRACE(v);
    EXPECT_TRUE(driver_config_for(v, OdometrySource::kWheels).validate().ok());
  }
  // The driver matches the chassis: the same profile.
  for (const std::string& v : sim::variant_names()) {
    SCOPED_TRACE(v);
    const auto chassis = sim::apply_variant(v, sim::VirtualChassisConfig{});
    ASSERT_TRUE(chassis.ok());
    ProtocolProfile driver = driver_config_for(v, OdometrySource::kWheels).controller.profile;
    EXPECT_EQ(describe(driver), describe(chassis->profile));
  }
}

}  // namespace
}  // namespace ranger::variants
