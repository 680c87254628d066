// What a front end takes from control/vocabulary.hpp instead of the wire: faults and status bits
// by name, the freshness of the battery reports, the covariances, the ultrasonic distance, and
// which motion modes a profile can drive.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

// Every fault of a layout, by the fault table's name, set exactly when its bit is.
TEST(Vocabulary, FaultFlagsAreTheFaultTableByMeaningInEitherLayout) {
  for (const auto layout : {ErrorWordLayout::kManual32, ErrorWordLayout::kAgxV2_16}) {
    std::set<std::string> expected;
    for (const auto& f : protocol::kFaultTable) {
      if (f.bit(layout) != protocol::kNoBit) expected.emplace(f.name);
    }
    std::set<std::string> named;
    for (const NamedFlag& flag : fault_flags(0, layout)) {
      named.emplace(flag.name);
      EXPECT_FALSE(flag.set) << flag.name;
    }
    EXPECT_EQ(named, expected);
    for (const auto& f : protocol::kFaultTable) {
      if (f.bit(layout) == protocol::kNoBit) continue;
      for (const NamedFlag& flag : fault_flags(1u << f.bit(layout), layout))
        EXPECT_EQ(flag.set, flag.name == f.name) << f.name << " / " << flag.name;
      EXPECT_EQ(fault_names(1u << f.bit(layout), layout),
                std::vector<std::string>{std::string(f.name)});
    }
  }
}

TEST(Vocabulary, StatusBitsByName) {
  std::set<std::string> set;
  for (const NamedFlag& f : driver_status_flags(protocol::driver_status::kDriverDisabled)) {
    if (f.set) set.emplace(f.name);
  }
  EXPECT_EQ(set, std::set<std::string>{"driver_disabled"});
  set.clear();
  for (const NamedFlag& f :
       bms_flags(protocol::bms_status::kOverVoltage, protocol::bms_status::kChargeOverCurrent)) {
    if (f.set) set.emplace(f.name);
  }
  EXPECT_EQ(set, (std::set<std::string>{"over_voltage", "charge_over_current"}));
}

// A slot's BMS report counts for three of its periods (500 ms), then the slot is absent.
TEST(Vocabulary, ABatteryReportIsFreshForThreeOfItsPeriods) {
  ChassisFeedback fb;
  fb.bms[2] = Stamped<BmsData>{BmsData{}, Timestamp(10s), Timestamp(10s)};
  EXPECT_TRUE(bms_present(fb, 2, Timestamp(10s) + 1500ms));
  EXPECT_FALSE(bms_present(fb, 2, Timestamp(10s) + 1501ms));
  EXPECT_FALSE(bms_present(fb, 1, Timestamp(10s)));
  EXPECT_FALSE(bms_present(fb, kBatteryCount + 1, Timestamp(10s)));
}

TEST(Vocabulary, CovariancesAreRowMajorWithTheOdometrysGrowthOnTheFloor) {
  OdometryState odometry;
  odometry.pose_variance = {0.5, 0.25, 0.125};
  const Covariance c = pose_covariance(odometry, {1, 2, 3, 4, 5, 6});
  EXPECT_DOUBLE_EQ(c[0], 1.5);
  EXPECT_DOUBLE_EQ(c[7], 2.25);
  EXPECT_DOUBLE_EQ(c[14], 3.0);
  EXPECT_DOUBLE_EQ(c[35], 6.125);
  EXPECT_DOUBLE_EQ(c[1], 0.0);
  EXPECT_EQ(diagonal_covariance({1, 1, 1, 1, 1, 1})[6], 0.0);
}

TEST(Vocabulary, UltrasonicDistancesInMetresAndEveryCodeIsNaN) {
  EXPECT_DOUBLE_EQ(ultrasonic_range(1500), 1.5);
  EXPECT_EQ(ultrasonic_status(1500), "ok");
  for (const std::int16_t raw : {0, -1, -2, -3, -4, -100}) {
    EXPECT_TRUE(std::isnan(ultrasonic_range(raw))) << raw;
    EXPECT_NE(ultrasonic_status(raw), "ok") << raw;
  }
}

// The controller's rule, for a front end to refuse a mode by name: side slip only where the mode
// numbering has it, park never.
TEST(Vocabulary, WhichModesAProfileCanDrive) {
  const auto manual = protocol_preset("manual").value();
  const auto agx = protocol_preset("agx_v2").value();
  for (const MotionMode m : {MotionMode::kAckermann, MotionMode::kOblique, MotionMode::kSpin}) {
    EXPECT_TRUE(can_drive_in(m, manual)) << to_string(m);
    EXPECT_TRUE(can_drive_in(m, agx)) << to_string(m);
  }
  EXPECT_FALSE(can_drive_in(MotionMode::kSideSlip, manual));
  EXPECT_TRUE(can_drive_in(MotionMode::kSideSlip, agx));
  EXPECT_FALSE(can_drive_in(MotionMode::kPark, agx));
  EXPECT_EQ(std::string(frame_name(protocol::kSystemStatusId)), "system_status");
}

// sensor_msgs/BatteryState as the library says it (both nodes map it): from the BMS while it
// reports, the system status's voltage alone otherwise; status by the current's sign, health by
// the first alarm of the table.
TEST(Vocabulary, TheBatteryReportIsTheBmsOrTheSystemStatusVoltage) {
  ChassisFeedback fb;
  const auto none = battery_report(fb, Timestamp(10s));
  EXPECT_FALSE(none.present);
  EXPECT_EQ(none.status, PowerSupplyStatus::kUnknown);
  EXPECT_EQ(none.health, PowerSupplyHealth::kUnknown);
  EXPECT_TRUE(std::isnan(none.voltage));

  fb.system_status.emplace();
  fb.system_status->stamp = Timestamp(9s);
  fb.system_status->value.battery_voltage = 51.5;
  const auto status_only = battery_report(fb, Timestamp(10s));
  EXPECT_TRUE(status_only.present);
  EXPECT_EQ(status_only.stamp, Timestamp(9s));
  EXPECT_DOUBLE_EQ(status_only.voltage, 51.5);
  EXPECT_EQ(status_only.status, PowerSupplyStatus::kUnknown);

  BmsData pack;
  pack.voltage = 52.0;
  pack.current = -3.0;
  pack.soc = 150.0;  // clamped to 1
  pack.temperature = 25.0;
  fb.bms[0] = Stamped<BmsData>{pack, Timestamp(10s), Timestamp(8s)};
  BmsData slot;
  slot.voltage = 13.0;
  slot.temperature = 24.0;
  fb.bms[2] = Stamped<BmsData>{slot, Timestamp(10s), Timestamp(8s)};
  auto r = battery_report(fb, Timestamp(10s));
  EXPECT_EQ(r.stamp, Timestamp(8s));
  EXPECT_DOUBLE_EQ(r.voltage, 52.0);
  EXPECT_DOUBLE_EQ(r.percentage, 1.0);
  EXPECT_EQ(r.status, PowerSupplyStatus::kDischarging);
  EXPECT_EQ(r.health, PowerSupplyHealth::kGood);
  EXPECT_TRUE(std::isnan(r.cell_voltage[0]));
  EXPECT_DOUBLE_EQ(r.cell_voltage[1], 13.0);
  EXPECT_DOUBLE_EQ(r.cell_temperature[1], 24.0);

  EXPECT_EQ(power_supply_status(2.0), PowerSupplyStatus::kCharging);
  EXPECT_EQ(power_supply_status(0.0), PowerSupplyStatus::kNotCharging);
  namespace b = protocol::bms_status;
  EXPECT_EQ(power_supply_health(b::kOverVoltage | b::kLowTemperature, 0),
            PowerSupplyHealth::kOvervoltage);
  EXPECT_EQ(power_supply_health(b::kHighTemperature, 0), PowerSupplyHealth::kOverheat);
  EXPECT_EQ(power_supply_health(b::kLowTemperature, 0), PowerSupplyHealth::kCold);
  EXPECT_EQ(power_supply_health(0, b::kChargeOverCurrent), PowerSupplyHealth::kUnspecFailure);
  EXPECT_EQ(power_supply_health(b::kUnderVoltage, 0), PowerSupplyHealth::kUnspecFailure);
  EXPECT_EQ(power_supply_health(0, 0), PowerSupplyHealth::kGood);
}

// sensor_msgs/Range's value (REP-117): a distance, NaN for no reading, +inf for nothing seen.
TEST(Vocabulary, ARangeBeyondMaxRangeIsNothingSeen) {
  const double d = ultrasonic_range(100);
  ASSERT_TRUE(std::isfinite(d));
  EXPECT_DOUBLE_EQ(range_reading(100, d + 0.01), d);
  EXPECT_EQ(range_reading(100, d - 0.01), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(range_reading(0, 5.0)));   // no reading
  EXPECT_TRUE(std::isnan(range_reading(-1, 5.0)));  // offline
}

TEST(Vocabulary, ThePoseCovarianceIsTheFloorPlusTheVariance) {
  const auto c = pose_covariance({1.0, 2.0, 3.0}, {10, 20, 30, 40, 50, 60});
  EXPECT_DOUBLE_EQ(c[0], 11.0);
  EXPECT_DOUBLE_EQ(c[7], 22.0);
  EXPECT_DOUBLE_EQ(c[14], 30.0);
  EXPECT_DOUBLE_EQ(c[35], 63.0);
  EXPECT_DOUBLE_EQ(c[1], 0.0);
}

}  // namespace
}  // namespace ranger
