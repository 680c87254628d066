// Plausible telemetry for the virtual RANGER's eight motors and its battery: motor speeds,
// currents, encoder positions and temperatures, and a pack that drains with load. Derived from
// the motion model's wheel states; nothing here feeds back into the motion. The numbers are
// first-order physics with the manual's vehicle data (135 kg, 48 V, 24 Ah per battery), good
// enough for dashboards and alarms, not a calibrated model of the real drives. The pack is the
// manual's lithium iron phosphate (wire/vehicle_spec.hpp): 15 cells in series, a flat plateau of
// about 3.2-3.3 V per cell, so 46-50 V (the manual's normal range) over 10-90 % SOC, with steep
// ends below and above.
#pragma once

#include <array>
#include <cstdint>

#include "ranger_can/sim/chassis_model.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

struct DrivetrainConfig {
  double vehicle_mass = 135.0;         // kg, own weight (manual 1.1)
  double payload = 0.0;                // kg, up to 150
  double rolling_resistance = 0.02;    // rolling resistance coefficient
  double drive_torque_constant = 0.8;  // N*m per A, hub motor
  double drive_efficiency = 0.85;
  double drive_pulses_per_rev = 4096.0;     // encoder pulses per wheel revolution
  double steering_gear_ratio = 50.0;        // steering motor revolutions per wheel revolution
  double steering_pulses_per_rev = 4096.0;  // per steering motor revolution
  double steering_hold_current = 0.3;       // A
  double steering_current_per_rate = 1.5;   // A per rad/s of wheel slew
  double idle_current = 1.5;                // A drawn from the pack by the electronics
  int batteries = 2;                        // fitted batteries, 1..4 (24 Ah each)
  double battery_capacity_ah = 24.0;        // per battery
  double battery_soh = 98.0;                // %
  double pack_resistance = 0.05;            // ohm
  double ambient_temperature = 25.0;        // degC
  double thermal_time_constant = 300.0;     // s
  double motor_heating = 0.8;               // degC above ambient per A^2 at steady state
  double driver_heating = 0.4;              // degC above ambient per A^2 at steady state
};

// Open-circuit voltage of the 48 V LiFePO4 pack at `soc_percent` (clamped to 0..100): a typical
// LiFePO4 cell curve (piecewise linear), times 15 cells. 42 V empty, 48 V nominal near 20 %,
// 46.0-50.0 V from 10 % to 90 %, 51.75 V full.
double lifepo4_pack_open_circuit_voltage(double soc_percent);

struct MotorTelemetry {
  double rpm = 0.0;
  double current = 0.0;       // A, signed with the torque
  std::int32_t position = 0;  // encoder pulses (a counter: wraps like the hardware's)
  double driver_temperature = 25.0;
  double motor_temperature = 25.0;
};

struct BatteryTelemetry {
  double soc = 100.0;    // %
  double soh = 100.0;    // %
  double voltage = 0.0;  // V
  // A; the BMS convention used here: positive = charging, negative = discharging (the manual
  // does not say; most BMS report it this way).
  double current = 0.0;
  double temperature = 25.0;  // degC
};

class DrivetrainModel {
 public:
  explicit DrivetrainModel(const DrivetrainConfig& config, double initial_soc);

  // Updates telemetry after the motion model advanced by dt seconds. `powered` false means the
  // drivers have no power (low-battery cut-off or e-stop): they draw nothing.
  void advance(double dt, const ChassisModel& motion, bool powered);

  void set_soc(double soc);  // clamped to [0, 100]
  double soc() const { return soc_; }

  // Motor n = 1..8 (protocol.hpp numbering) at index n-1.
  const std::array<MotorTelemetry, protocol::kMotorCount>& motors() const { return motors_; }
  BatteryTelemetry pack() const;
  BatteryTelemetry battery(int slot) const;  // 1..batteries: the pack's share
  int batteries() const { return config_.batteries; }

 private:
  double open_circuit_voltage() const;

  DrivetrainConfig config_;
  double soc_;
  double pack_current_ = 0.0;
  double battery_temperature_;
  std::array<MotorTelemetry, protocol::kMotorCount> motors_{};
  std::array<double, kWheelCount> drive_revolutions_{};
  std::array<double, kWheelCount> last_wheel_speed_{};
};

}  // namespace ranger::sim
