#include "ranger_can/sim/drivetrain_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "ranger_can/wire/vehicle_spec.hpp"

namespace ranger::sim {

namespace {
constexpr double kGravity = 9.81;
// A 48 V LiFePO4 pack (manual 1.1: 铁锂电池): 15 cells of 3.2 V nominal.
constexpr double kCellsInSeries = 15.0;
constexpr double kNominalError = kCellsInSeries * 3.2 - vehicle_spec::kBatteryNominalVoltage;
static_assert(kNominalError < 1e-9 && kNominalError > -1e-9);
// Open-circuit voltage of one LiFePO4 cell by SOC (%), at rest: steep below 10 % and above
// 95 %, a plateau of 3.07-3.33 V between (46.0-50.0 V for the pack at 10-90 %).
constexpr std::array<std::pair<double, double>, 13> kCellCurve = {{
    {0.0, 2.80},
    {5.0, 3.00},
    {10.0, 3.07},
    {20.0, 3.18},
    {30.0, 3.22},
    {40.0, 3.245},
    {50.0, 3.26},
    {60.0, 3.275},
    {70.0, 3.29},
    {80.0, 3.305},
    {90.0, 3.33},
    {95.0, 3.36},
    {100.0, 3.45},
}};

// Encoder counters wrap around like the hardware's 32-bit counters do (a counter, not a value to
// saturate).
std::int32_t to_counter(double pulses) {
  const double wrapped = std::fmod(std::round(pulses), 4294967296.0);
  const auto u = static_cast<std::uint32_t>(static_cast<std::int64_t>(wrapped) & 0xFFFFFFFF);
  return static_cast<std::int32_t>(u);
}
}  // namespace

DrivetrainModel::DrivetrainModel(const DrivetrainConfig& config, double initial_soc)
    : config_(config),
      soc_(std::clamp(initial_soc, 0.0, 100.0)),
      battery_temperature_(config.ambient_temperature) {
  config_.batteries = std::clamp(config_.batteries, 1, protocol::kBatteryCount);
  for (auto& m : motors_) {
    m.driver_temperature = config_.ambient_temperature;
    m.motor_temperature = config_.ambient_temperature;
  }
}

void DrivetrainModel::set_soc(double soc) {
  if (std::isfinite(soc)) soc_ = std::clamp(soc, 0.0, 100.0);
}

double lifepo4_pack_open_circuit_voltage(double soc_percent) {
  const double soc = std::isnan(soc_percent) ? 0.0 : std::clamp(soc_percent, 0.0, 100.0);
  for (std::size_t i = 1; i < kCellCurve.size(); ++i) {
    const auto [s1, v1] = kCellCurve[i];
    if (soc <= s1) {
      const auto [s0, v0] = kCellCurve[i - 1];
      return kCellsInSeries * (v0 + (v1 - v0) * (soc - s0) / (s1 - s0));
    }
  }
  return kCellsInSeries * kCellCurve.back().second;
}

double DrivetrainModel::open_circuit_voltage() const {
  return lifepo4_pack_open_circuit_voltage(soc_);
}

void DrivetrainModel::advance(double dt, const ChassisModel& motion, bool powered) {
  if (!(dt > 0.0)) return;
  const WheelStates wheels = motion.wheels();
  const double wheel_radius = motion.geometry().wheel_radius;
  const double mass_per_wheel = (config_.vehicle_mass + config_.payload) / kWheelCount;
  const double voltage =
      std::max(1.0, open_circuit_voltage() - pack_current_ * config_.pack_resistance);

  double electrical_power = 0.0;
  for (int i = 0; i < kWheelCount; ++i) {
    MotorTelemetry& drive = motors_[i];
    const double v = wheels[i].speed;
    const double accel = (v - last_wheel_speed_[i]) / dt;
    last_wheel_speed_[i] = v;
    const double rolling =
        v == 0.0 ? 0.0 : std::copysign(config_.rolling_resistance * mass_per_wheel * kGravity, v);
    const double force = powered ? mass_per_wheel * accel + rolling : 0.0;
    drive.current = force * wheel_radius / config_.drive_torque_constant;
    drive.rpm = v / (2.0 * M_PI * wheel_radius) * 60.0;
    drive_revolutions_[i] += v / (2.0 * M_PI * wheel_radius) * dt;
    drive.position = to_counter(drive_revolutions_[i] * config_.drive_pulses_per_rev);
    const double mechanical = force * v;
    electrical_power += mechanical >= 0 ? mechanical / config_.drive_efficiency
                                        : mechanical * config_.drive_efficiency;

    MotorTelemetry& steer = motors_[i + kWheelCount];
    const double rate = motion.wheel_angle_rates()[i];
    steer.rpm = rate * config_.steering_gear_ratio / (2.0 * M_PI) * 60.0;
    steer.current = powered
                        ? std::copysign(config_.steering_hold_current, rate == 0.0 ? 1.0 : rate) +
                              config_.steering_current_per_rate * rate
                        : 0.0;
    steer.position = to_counter(wheels[i].angle / (2.0 * M_PI) * config_.steering_gear_ratio *
                                config_.steering_pulses_per_rev);
    electrical_power += std::abs(steer.current) * voltage * 0.1;  // small motors, mostly holding
  }
  pack_current_ = config_.idle_current + electrical_power / voltage;

  const double capacity_as = config_.battery_capacity_ah * config_.batteries * 3600.0;
  soc_ = std::clamp(soc_ - pack_current_ * dt / capacity_as * 100.0, 0.0, 100.0);

  const double alpha = std::min(1.0, dt / config_.thermal_time_constant);
  for (auto& m : motors_) {
    const double i2 = m.current * m.current;
    m.motor_temperature +=
        (config_.ambient_temperature + config_.motor_heating * i2 - m.motor_temperature) * alpha;
    m.driver_temperature +=
        (config_.ambient_temperature + config_.driver_heating * i2 - m.driver_temperature) * alpha;
  }
  const double pack_heating = pack_current_ * pack_current_ * config_.pack_resistance;  // W
  battery_temperature_ +=
      (config_.ambient_temperature + 0.5 * pack_heating - battery_temperature_) * alpha;
}

BatteryTelemetry DrivetrainModel::pack() const {
  BatteryTelemetry b;
  b.soc = soc_;
  b.soh = config_.battery_soh;
  b.voltage = open_circuit_voltage() - pack_current_ * config_.pack_resistance;
  b.current = -pack_current_;
  b.temperature = battery_temperature_;
  return b;
}

BatteryTelemetry DrivetrainModel::battery(int slot) const {
  BatteryTelemetry b = pack();
  if (slot >= 1 && slot <= config_.batteries) b.current /= config_.batteries;
  return b;
}

}  // namespace ranger::sim
