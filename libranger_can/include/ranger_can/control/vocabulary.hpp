// What a front end (the ROS 1 and ROS 2 nodes, the Python binding, the CLI) needs besides the
// Driver, in namespace ranger: the vocabulary the driver's API speaks (motion, control and light
// modes, remote switches, faults) and the facts it would otherwise take from the wire — faults
// and status bits by name, which readings are fresh, the covariances, the ultrasonic distance.
// A front end includes this and control/driver.hpp and names nothing from ranger::protocol
// (tests/check_layers.py --node checks ranger_base for that).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// ---- the vocabulary ---------------------------------------------------------------------------
using protocol::ControlMode;
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

// ---- readings ---------------------------------------------------------------------------------
// Whether battery slot `slot` (0: the whole pack, 1..kBatteryCount) reported recently: a BMS
// report older than three of its periods counts as absent (an unfitted slot). `now`: the driver's
// clock (DriverSnapshot::now).
bool bms_present(const ChassisFeedback& feedback, int slot, Timestamp now);
// The distance a raw ultrasonic value stands for, in m; NaN for no reading and every error code.
double ultrasonic_range(std::int16_t raw);
// "ok", "no_reading", "offline", ... (ranger_msgs' UltrasonicReading status).
std::string_view ultrasonic_status(std::int16_t raw);

// A 6x6 covariance (x, y, z, roll, pitch, yaw), row-major as ROS messages carry it.
using Covariance = std::array<double, 36>;
Covariance diagonal_covariance(const std::array<double, 6>& diagonal);
// `floor` on the diagonal plus the odometry's growing x, y and yaw variance.
Covariance pose_covariance(const OdometryState& odometry, const std::array<double, 6>& floor);

}  // namespace ranger
