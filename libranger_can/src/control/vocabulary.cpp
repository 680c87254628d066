#include "ranger_can/control/vocabulary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

std::vector<NamedFlag> flags_of(std::uint32_t word, const std::vector<protocol::NamedBit>& bits,
                                std::vector<NamedFlag> out = {}) {
  for (const protocol::NamedBit& bit : bits)
    out.push_back({bit.name, ((word >> bit.index) & 1u) != 0});
  return out;
}

// A BMS report older than this many of its periods counts as absent.
constexpr int kStalePeriods = 3;

}  // namespace

std::vector<NamedFlag> fault_flags(std::uint32_t error_word, ErrorWordLayout layout) {
  std::vector<NamedFlag> out;
  for (const protocol::FaultInfo& f : protocol::kFaultTable) {
    const int bit = f.bit(layout);
    if (bit != protocol::kNoBit) out.push_back({f.name, ((error_word >> bit) & 1u) != 0});
  }
  return out;
}

std::vector<std::string> fault_names(std::uint32_t error_word, ErrorWordLayout layout) {
  return protocol::error_bit_names(error_word, layout);
}

std::vector<NamedFlag> driver_status_flags(std::uint8_t status) {
  return flags_of(status, protocol::driver_status_bits());
}

std::vector<NamedFlag> bms_flags(std::uint8_t status1, std::uint8_t status2) {
  return flags_of(status2, protocol::bms_status2_bits(),
                  flags_of(status1, protocol::bms_status1_bits()));
}

bool bms_present(const ChassisFeedback& feedback, int slot, Timestamp now) {
  if (slot < 0 || slot > kBatteryCount) return false;
  const int period_ms = protocol::frame_period_ms(protocol::kBmsBaseId);
  return is_fresh(feedback.bms[static_cast<std::size_t>(slot)], now,
                  std::chrono::milliseconds(kStalePeriods * period_ms));
}

std::array<double, 4> wheel_odometers(const ChassisFeedback& feedback) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::array<double, 4> out{};
  const auto fill = [&](const auto& odometer, double& left, double& right) {
    left = odometer ? odometer->value.left_distance.value_or(nan) : nan;
    right = odometer ? odometer->value.right_distance.value_or(nan) : nan;
  };
  fill(feedback.odometer, out[0], out[1]);
  fill(feedback.rear_odometer, out[2], out[3]);
  return out;
}

BmsAlarmNames pack_bms_alarms(const ChassisFeedback& feedback) {
  BmsAlarmNames out;
  if (const auto& alarm = feedback.bms_alarm[0]) {
    out.alarms = bms_status_names(alarm->value.alarm1, alarm->value.alarm2);
    out.warnings = bms_status_names(alarm->value.warning1, alarm->value.warning2);
  }
  return out;
}

double ultrasonic_range(std::int16_t raw) {
  return interpretation::ultrasonic_distance_m(raw).value_or(
      std::numeric_limits<double>::quiet_NaN());
}

std::string_view ultrasonic_status(std::int16_t raw) {
  return protocol::ultrasonic_status_name(raw);
}

Covariance diagonal_covariance(const std::array<double, 6>& diagonal) {
  Covariance out{};
  for (std::size_t i = 0; i < diagonal.size(); ++i)
    out[i * 7] = diagonal[i];
  return out;
}

Covariance pose_covariance(const OdometryState& odometry, const std::array<double, 6>& floor) {
  return pose_covariance(
      {odometry.pose_variance[0], odometry.pose_variance[1], odometry.pose_variance[2]}, floor);
}

Covariance pose_covariance(const std::array<double, 3>& pose_variance,
                           const std::array<double, 6>& floor) {
  Covariance out = diagonal_covariance(floor);
  out[0] += pose_variance[0];   // x
  out[7] += pose_variance[1];   // y
  out[35] += pose_variance[2];  // yaw
  return out;
}

double range_reading(std::int16_t raw, double max_range) {
  const double range = ultrasonic_range(raw);
  if (std::isfinite(range) && range > max_range) return std::numeric_limits<double>::infinity();
  return range;
}

Timestamp joints_stamp(const ChassisFeedback& feedback) {
  Timestamp t{0};
  if (feedback.steering_angles) t = std::max(t, feedback.steering_angles->stamp);
  if (feedback.wheel_speeds) t = std::max(t, feedback.wheel_speeds->stamp);
  return t;
}

PowerSupplyStatus power_supply_status(double current) {
  if (current > 0.0) return PowerSupplyStatus::kCharging;
  if (current < 0.0) return PowerSupplyStatus::kDischarging;
  return PowerSupplyStatus::kNotCharging;
}

PowerSupplyHealth power_supply_health(std::uint8_t alarm1, std::uint8_t alarm2) {
  namespace b = protocol::bms_status;
  // The first rule whose bits are set decides.
  static constexpr struct {
    std::uint8_t status1, status2;
    PowerSupplyHealth health;
  } kRules[] = {
      {b::kOverVoltage, 0, PowerSupplyHealth::kOvervoltage},
      {b::kHighTemperature, 0, PowerSupplyHealth::kOverheat},
      {b::kLowTemperature, 0, PowerSupplyHealth::kCold},
      {b::kUnderVoltage | b::kDischargeOverCurrent, b::kChargeOverCurrent,
       PowerSupplyHealth::kUnspecFailure},
  };
  for (const auto& rule : kRules) {
    if ((alarm1 & rule.status1) != 0 || (alarm2 & rule.status2) != 0) return rule.health;
  }
  return PowerSupplyHealth::kGood;
}

BatteryReport battery_report(const ChassisFeedback& feedback, Timestamp now) {
  BatteryReport out;
  const auto& pack = feedback.bms[0];
  if (bms_present(feedback, 0, now)) {
    out.present = true;
    out.stamp = pack->stamp;
    out.voltage = pack->value.voltage;
    out.current = pack->value.current;
    out.temperature = pack->value.temperature;
    out.percentage = std::clamp(pack->value.soc / 100.0, 0.0, 1.0);
    out.status = power_supply_status(pack->value.current);
    out.health = PowerSupplyHealth::kGood;
    if (const auto& alarm = feedback.bms_alarm[0])
      out.health = power_supply_health(alarm->value.alarm1, alarm->value.alarm2);
  } else if (const auto& status = feedback.system_status) {
    out.present = true;  // the chassis runs, so it has a battery; the BMS is not reporting
    out.stamp = status->stamp;
    out.voltage = status->value.battery_voltage;
  }
  for (int b = 1; b <= kBatteryCount; ++b) {
    const auto slot = static_cast<std::size_t>(b);
    if (!bms_present(feedback, b, now)) continue;
    out.cell_voltage[slot - 1] = feedback.bms[slot]->value.voltage;
    out.cell_temperature[slot - 1] = feedback.bms[slot]->value.temperature;
  }
  return out;
}

}  // namespace ranger
