// The driver and the virtual chassis (`sim` or `sim:VARIANT`) in lock-step under a ManualClock,
// 1 ms a step (the chassis, then the driver), no thread and no sleeping: the one rig of the
// driver's tests (test_driver, test_driver_vendor), of the field facts' (test_field_facts) and,
// through IdentifyRig (support/identify_rig.hpp: a commander, the route, the plausibility stop), of
// the identification, plausibility, events and adversarial tests. A test that watches each step
// derives from it (chassis_stepping, chassis_stepped, driver_stepped, on_sent).
//
// Every driver test of a mode switch runs against both reports of it (sim/switch_model.hpp):
// the manual's (0x291 the mode being left, switching = 1 throughout) and the field's (the new mode
// at once, the flag on some switches, the wheels at 3.26 rad/s): SwitchReportUnderTest.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/switch_model.hpp"
#include "ranger_can/text.hpp"

namespace ranger::test {

// The driver configured for a variant the way its `driver` options say (agx_v2's preset; a MINI's
// model: its geometry, limits and profile); the defaults otherwise.
DriverConfig driver_config_for(const std::string& variant);

// Which report of a mode switch the chassis runs; kVariants: the variant's own.
enum class SwitchReportUnderTest { kVariants, kManual, kField };
inline constexpr auto kSwitchReportUnderTestNames = text::enum_names<SwitchReportUnderTest>({
    {SwitchReportUnderTest::kVariants, "variants_report"},
    {SwitchReportUnderTest::kManual, "manual_report"},
    {SwitchReportUnderTest::kField, "field_report"},
});
// The name of a test's instance (a gtest parameter's name).
inline std::string to_string(SwitchReportUnderTest report) {
  return std::string(kSwitchReportUnderTestNames.name(report));
}
// The two a driver test of switching runs against.
inline const std::vector<SwitchReportUnderTest> kBothSwitchReports = {
    SwitchReportUnderTest::kManual, SwitchReportUnderTest::kField};

class DriverSimRig {
 public:
  // `variant`: "manual" (the plain `sim`) or a variant's name; `options.chassis` before the
  // variant; `report` then replaces the variant's switch report.
  DriverSimRig(const std::string& variant, const DriverConfig& config,
               sim::SimSourceOptions options = {},
               SwitchReportUnderTest report = SwitchReportUnderTest::kVariants);
  virtual ~DriverSimRig();  // the driver's shutdown stop is still observed
  DriverSimRig(const DriverSimRig&) = delete;
  DriverSimRig& operator=(const DriverSimRig&) = delete;

  void step();  // 1 ms
  void run_for(std::chrono::nanoseconds d);
  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout);
  // The commander publishes `request` every 50 ms for `d` (stopping at `d`); how many of its
  // commands the driver refused.
  int drive(const MotionRequest& request, std::chrono::nanoseconds d);
  int drive(const BodyTwist& twist, std::chrono::nanoseconds d) {
    return drive(MotionRequest{twist, std::nullopt}, d);
  }
  // CAN command mode and a known motion mode (and `also`), within 3 s.
  bool ready(const std::function<bool(const DriverSnapshot&)>& also = {});

  Driver& driver() { return *driver_; }
  std::shared_ptr<const DriverSnapshot> snapshot() const { return driver_->snapshot(); }
  sim::SimBusSource& sim() { return *sim_; }
  sim::ChassisSnapshot chassis() { return sim_->snapshot(); }
  sim::VirtualChassisCounters counters();
  const std::vector<SentEvent>& sent() const { return sent_; }
  ManualClock& clock() { return clock_; }

 protected:
  // The bus as sim::open_bus_source takes it (`sim`, `sim:VARIANT`) and its options.
  struct SimBus {
    std::string spec;
    sim::SimSourceOptions options;
  };
  // The rig on `bus` as it is (lock-step set here); IdentifyRig's.
  DriverSimRig(SimBus bus, DriverConfig config);

  virtual void chassis_stepping() {}               // the clock advanced, the chassis not yet
  virtual void chassis_stepped() {}                // after the chassis stepped to now
  virtual void driver_stepped() {}                 // after the driver stepped
  virtual void on_sent(const SentEvent& /*e*/) {}  // each frame the driver sent

 private:
  static SimBus sim_bus(const std::string& variant, sim::SimSourceOptions options,
                        SwitchReportUnderTest report);

  ManualClock clock_{Timestamp(std::chrono::seconds(1000))};
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  std::vector<SentEvent> sent_;
};

}  // namespace ranger::test
