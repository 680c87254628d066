#include "support/driver_sim_rig.hpp"

#include <gtest/gtest.h>

#include <utility>

#include "ranger_can/control/model.hpp"

namespace ranger::test {

using namespace std::chrono_literals;

DriverConfig driver_config_for(const std::string& variant) {
  DriverConfig c;
  if (variant == "agx_v2") c.controller.profile = *protocol_preset("agx_v2");
  if (variant == "mini_v1" || variant == "mini_v3") {
    const auto model = model_preset("ranger_" + variant);
    EXPECT_TRUE(model.ok());
    if (!model) return c;
    c.controller.geometry = model->geometry;
    c.controller.limits = model->limits;
    c.controller.profile = model->profile;
  }
  return c;
}

DriverSimRig::DriverSimRig(const std::string& variant, const DriverConfig& config,
                           sim::SimSourceOptions options, SwitchReportUnderTest report)
    : DriverSimRig(sim_bus(variant, std::move(options), report), config) {}

DriverSimRig::SimBus DriverSimRig::sim_bus(const std::string& variant,
                                           sim::SimSourceOptions options,
                                           SwitchReportUnderTest report) {
  std::string spec = variant == "manual" ? "sim" : "sim:" + variant;
  if (report != SwitchReportUnderTest::kVariants) {
    // The variant's chassis, then the report over it (the plain `sim` applies nothing more).
    auto chassis = sim::apply_variant(variant, options.chassis);
    EXPECT_TRUE(chassis.ok());
    if (chassis) options.chassis = *chassis;
    options.chassis.switch_model = report == SwitchReportUnderTest::kField
                                       ? sim::field_switch_model()
                                       : sim::mode_left_switch_model();
    spec = "sim";
  }
  return {std::move(spec), std::move(options)};
}

DriverSimRig::DriverSimRig(SimBus bus, DriverConfig config) {
  bus.options.lock_step = true;
  auto source = sim::open_bus_source(bus.spec, clock_, bus.options);
  EXPECT_TRUE(source.ok()) << (source ? "" : source.error().message);
  sim_ = std::static_pointer_cast<sim::SimBusSource>(*source);
  driver_ = std::make_unique<Driver>(std::move(config), *source, clock_);
  driver_->set_sent_observer([this](const SentEvent& e) {
    sent_.push_back(e);
    on_sent(e);
  });
}

DriverSimRig::~DriverSimRig() {
  driver_.reset();
}

void DriverSimRig::step() {
  clock_.advance(1ms);
  chassis_stepping();
  sim_->step(clock_.now());
  chassis_stepped();
  driver_->step(clock_.now());
  driver_stepped();
}

void DriverSimRig::run_for(std::chrono::nanoseconds d) {
  const Timestamp end = clock_.now() + d;
  while (clock_.now() < end)
    step();
}

bool DriverSimRig::run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
  const Timestamp end = clock_.now() + timeout;
  while (!done()) {
    if (clock_.now() >= end) return false;
    step();
  }
  return true;
}

int DriverSimRig::drive(const MotionRequest& request, std::chrono::nanoseconds d) {
  int refused = 0;
  const Timestamp end = clock_.now() + d;
  while (clock_.now() < end) {
    if (!driver_->command(request).ok()) ++refused;
    for (int i = 0; i < 50 && clock_.now() < end; ++i)
      step();
  }
  return refused;
}

bool DriverSimRig::ready(const std::function<bool(const DriverSnapshot&)>& also) {
  return run_until(
      [&] {
        const auto s = driver_->snapshot();
        return s->controller.control_mode == protocol::ControlMode::kCan &&
               s->controller.motion_mode && (!also || also(*s));
      },
      3s);
}

sim::VirtualChassisCounters DriverSimRig::counters() {
  return sim_->with_chassis([](sim::VirtualChassis& c) { return c.counters(); });
}

}  // namespace ranger::test
