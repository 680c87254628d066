// What a front end (the ROS 1 and ROS 2 nodes, the Python binding, the CLI) needs besides the
// Driver, in namespace ranger: the vocabulary the driver's API speaks (motion, control and light
// modes, remote switches, faults) and the facts it would otherwise take from the wire — faults
// and status bits by name, which readings are fresh, the covariances, the ultrasonic distance.
// A front end includes this and control/driver.hpp and names nothing from ranger::protocol
// (tests/check_layers.py --node checks ranger_base for that).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// ---- the vocabulary ---------------------------------------------------------------------------
using protocol::ControlMode;
using protocol::drive_mode_from_wire;  // 0 current, 1 voltage (ranger_msgs' SetDriveMode)
using protocol::DriveMode;
using protocol::Fault;
using protocol::LightMode;
using protocol::MotionMode;
using protocol::RemoteSwitch;
using protocol::VehicleStatus;
// Their stable names ("ackermann", "remote", "up", "battery_under_voltage", ...).
using protocol::to_string;
// A frame's name by its ID ("system_status", "bms"; "unknown").
using protocol::frame_name;
// What a clear-errors code clears ("all non-critical faults", "motor driver 3 communication
// fault"): the words for ranger_msgs' ClearErrors code.
using protocol::error_clear_description;

inline constexpr int kMotorCount = protocol::kMotorCount;      // motors 1..8 (4 drive, 4 steering)
inline constexpr int kBatteryCount = protocol::kBatteryCount;  // battery slots 1..4; 0: the pack

// ---- faults and status bits by name -----------------------------------------------------------
// A named bit of a status word and whether it is set.
struct NamedFlag {
  std::string_view name;
  bool set = false;
};
// Every fault of the fault table that `layout`'s error word carries, by meaning (its stable name:
// ranger_msgs' SystemErrors field names), with whether `error_word` has it set.
std::vector<NamedFlag> fault_flags(std::uint32_t error_word, ErrorWordLayout layout);
// The names of the faults set in `error_word` (reserved bits that are set as "reserved_bit_N").
std::vector<std::string> fault_names(std::uint32_t error_word, ErrorWordLayout layout);
// A motor driver's status byte (0x261..0x268) and a BMS alarm or warning pair (0x362..), by name.
std::vector<NamedFlag> driver_status_flags(std::uint8_t status);
std::vector<NamedFlag> bms_flags(std::uint8_t status1, std::uint8_t status2);
// The names of the bits set in a BMS alarm or warning pair, reserved ones as "reserved_bit_N"
// (status 1) and "status2_reserved_bit_N".
using protocol::bms_status_names;

// ---- readings ---------------------------------------------------------------------------------
// Whether battery slot `slot` (0: the whole pack, 1..kBatteryCount) reported recently: a BMS
// report older than three of its periods counts as absent (an unfitted slot). `now`: the driver's
// clock (DriverSnapshot::now).
bool bms_present(const ChassisFeedback& feedback, int slot, Timestamp now);
// The wheels' own odometers, m: front left, front right, rear left, rear right (0x311, 0x312);
// NaN where the chassis reports none, or none in a known unit.
std::array<double, 4> wheel_odometers(const ChassisFeedback& feedback);
// The whole pack's BMS alarms and warnings (0x362) by name; both empty before one is heard.
struct BmsAlarmNames {
  std::vector<std::string> alarms;
  std::vector<std::string> warnings;
};
BmsAlarmNames pack_bms_alarms(const ChassisFeedback& feedback);
// The distance a raw ultrasonic value stands for, in m; NaN for no reading and every error code.
double ultrasonic_range(std::int16_t raw);
// "ok", "no_reading", "offline", ... (ranger_msgs' UltrasonicReading status).
std::string_view ultrasonic_status(std::int16_t raw);

// sensor_msgs/Range's `range` for a raw ultrasonic value (REP-117): the distance in m; NaN for no
// reading and every error code; +inf, "nothing seen", for a distance beyond `max_range`.
double range_reading(std::int16_t raw, double max_range);

// The newest of the joint feedback's frame stamps (steering angles, wheel speeds); 0 for none.
Timestamp joints_stamp(const ChassisFeedback& feedback);

// A 6x6 covariance (x, y, z, roll, pitch, yaw), row-major as ROS messages carry it.
using Covariance = std::array<double, 36>;
Covariance diagonal_covariance(const std::array<double, 6>& diagonal);
// `floor` on the diagonal plus the odometry's growing x, y and yaw variance.
Covariance pose_covariance(const OdometryState& odometry, const std::array<double, 6>& floor);
// The same from the x, y and yaw variance alone.
Covariance pose_covariance(const std::array<double, 3>& pose_variance,
                           const std::array<double, 6>& floor);

// ---- the battery, as sensor_msgs/BatteryState reports it -------------------------------------
// power_supply_status and power_supply_health: sensor_msgs/BatteryState's numbers (both nodes'
// tests compare them with the message's constants).
enum class PowerSupplyStatus : std::uint8_t {
  kUnknown = 0,
  kCharging = 1,
  kDischarging = 2,
  kNotCharging = 3,
  kFull = 4,
};
enum class PowerSupplyHealth : std::uint8_t {
  kUnknown = 0,
  kGood = 1,
  kOverheat = 2,
  kDead = 3,
  kOvervoltage = 4,
  kUnspecFailure = 5,
  kCold = 6,
  kWatchdogTimerExpire = 7,
  kSafetyTimerExpire = 8,
};
// The pack's charge state by its current (sensor_msgs: negative while discharging, as the BMS
// reports it): charging above 0, discharging below, not charging at 0.
PowerSupplyStatus power_supply_status(double current);
// The pack's health from its BMS alarm pair: the first of over-voltage (overvoltage),
// high temperature (overheat), low temperature (cold), then under-voltage or an over-current
// (unspecified failure); good without any.
PowerSupplyHealth power_supply_health(std::uint8_t alarm1, std::uint8_t alarm2);

// What sensor_msgs/BatteryState says of the pack: from the BMS (0x361) while it reports; from the
// system status's battery voltage alone when only that is heard; nothing (present false) before.
struct BatteryReport {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  bool present = false;
  Timestamp stamp{0};  // the report's frame; 0: none (the front end stamps it with its own now)
  double voltage = kNaN, current = kNaN, temperature = kNaN;  // V, A, degC
  double percentage = kNaN;                                   // 0..1
  PowerSupplyStatus status = PowerSupplyStatus::kUnknown;
  PowerSupplyHealth health = PowerSupplyHealth::kUnknown;
  // Each battery slot 1..kBatteryCount: its voltage and temperature, NaN where not reporting.
  static_assert(kBatteryCount == 4, "one NaN per slot below");
  std::array<double, kBatteryCount> cell_voltage{kNaN, kNaN, kNaN, kNaN};
  std::array<double, kBatteryCount> cell_temperature{kNaN, kNaN, kNaN, kNaN};
};
BatteryReport battery_report(const ChassisFeedback& feedback, Timestamp now);

}  // namespace ranger
