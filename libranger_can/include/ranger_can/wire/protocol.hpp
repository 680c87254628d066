// The RANGER CAN protocol's vocabulary: identifiers, enumerations and named bits, exactly as the
// manual (section 3.2, transcribed in shared/reference/PROTOCOL.md) defines them. Units and
// scaling live in codec.hpp; the manual's open points live in interpretation.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace ranger::protocol {

// ---- Identifiers ------------------------------------------------------------------------------
// Host -> chassis
inline constexpr std::uint32_t kMotionCommandId = 0x111;
inline constexpr std::uint32_t kMotionModeCommandId = 0x141;
inline constexpr std::uint32_t kControlModeCommandId = 0x421;
inline constexpr std::uint32_t kErrorClearCommandId = 0x441;
inline constexpr std::uint32_t kUltrasonicSettingId = 0x451;
// Chassis -> host
inline constexpr std::uint32_t kSystemStatusId = 0x211;
inline constexpr std::uint32_t kMotionFeedbackId = 0x221;
inline constexpr std::uint32_t kMotorHighSpeedBaseId = 0x250;  // + motor number 1..8
inline constexpr std::uint32_t kMotorLowSpeedBaseId = 0x260;   // + motor number 1..8
inline constexpr std::uint32_t kSteeringAnglesId = 0x271;
inline constexpr std::uint32_t kWheelSpeedsId = 0x281;
inline constexpr std::uint32_t kMotionModeFeedbackId = 0x291;
inline constexpr std::uint32_t kUltrasonic1to4Id = 0x342;
inline constexpr std::uint32_t kUltrasonic5to8Id = 0x343;
inline constexpr std::uint32_t kUltrasonicSettingFeedbackId = 0x45A;
inline constexpr std::uint32_t kBmsBaseId = 0x361;  // data: 0x361 + 2k, alarm: 0x362 + 2k, k = 0..4

inline constexpr int kMotorCount = 8;
inline constexpr int kUltrasonicCount = 8;
inline constexpr int kBatteryCount = 4;  // slots 1..4; index 0 is the whole pack

// Every identifier the protocol defines, in ascending order (used for receive filters, the DBC
// cross-check and frame-rate statistics).
std::vector<std::uint32_t> all_ids();
bool is_known_id(std::uint32_t id);
// The DLC the protocol defines for `id`, or -1 for an unknown ID.
int expected_dlc(std::uint32_t id);
// A short snake_case name for `id` ("motion_command", "bms", ...), "unknown" otherwise.
std::string_view frame_name(std::uint32_t id);

// Nominal feedback periods from the manual, for rate checks and the simulator.
inline constexpr int kFastPeriodMs = 20;        // 0x211 0x221 0x251-8 0x271 0x281 0x291
inline constexpr int kUltrasonicPeriodMs = 50;  // 0x342 0x343
inline constexpr int kSlowPeriodMs = 100;       // 0x261-8
inline constexpr int kBmsPeriodMs = 500;        // 0x361-0x36A
// The chassis stops if no 0x111 arrives for this long; the host keeps it alive at 20 ms.
inline constexpr int kChassisCommandTimeoutMs = 500;
inline constexpr int kKeepAlivePeriodMs = 20;

// ---- Enumerations (values as on the wire) -----------------------------------------------------
enum class MotionMode : std::uint8_t { kAckermann = 0x00, kOblique = 0x01, kSpin = 0x02 };
enum class ControlMode : std::uint8_t { kStandby = 0x00, kCan = 0x01, kRemote = 0x03 };
// 0x01 is not in this manual's table; see interpretation.hpp (kVehicleStatusEstop).
enum class VehicleStatus : std::uint8_t { kNormal = 0x00, kEmergencyStop = 0x01, kAbnormal = 0x02 };

// 0x441 payload: which fault to clear.
enum class ErrorClearCode : std::uint8_t {
  kAllNonCritical = 0x00,
  kMotor1Comm = 0x01,  // ... kMotor1Comm + (n-1) for motor n = 1..8
  kMotor8Comm = 0x08,
  kBatteryUnderVoltage = 0x09,
  kRemoteSignalLoss = 0x0A,
  kSteeringCalibMotor5 = 0x0B,  // ... 0x0E for motor 8
  kSteeringCalibMotor8 = 0x0E,
  kOverCurrent = 0x0F,
  kOverTemperature = 0x10,
};
inline constexpr std::uint8_t kMaxErrorClearCode = 0x10;

std::string_view to_string(MotionMode m);
std::string_view to_string(ControlMode m);
std::string_view to_string(VehicleStatus s);
// Describes what a 0x441 code clears ("all non-critical faults", "motor driver 3 communication").
std::string error_clear_description(std::uint8_t code);

// ---- 0x211 error bits -------------------------------------------------------------------------
// The four error bytes form one big-endian uint32 (byte 4 is the most significant), so a bit's
// position in the word is (7 - byte) * 8 + bit.
constexpr int error_bit_index(int byte, int bit) {
  return (7 - byte) * 8 + bit;
}

struct NamedBit {
  int index;              // bit position in the word (or byte) it belongs to
  std::string_view name;  // snake_case, stable: used in JSON, ROS messages and diagnostics
  std::string_view description;
};

// Every defined error bit of 0x211, in ascending bit order (reserved bits are absent).
const std::vector<NamedBit>& system_error_bits();
// Names of the bits set in `error_word`; reserved bits that are set appear as "reserved_bit_N".
std::vector<std::string> error_bit_names(std::uint32_t error_word);

// Bits that, when set, mean the chassis will not (or must not) move.
bool is_critical_error(std::uint32_t error_word);

// ---- 0x261-0x268 driver status bits -----------------------------------------------------------
const std::vector<NamedBit>& driver_status_bits();
std::vector<std::string> driver_status_names(std::uint8_t status);

// ---- 0x362... BMS alarm / warning bits --------------------------------------------------------
// Status byte 1 (alarm and warning use the same layout) and status byte 2.
const std::vector<NamedBit>& bms_status1_bits();
const std::vector<NamedBit>& bms_status2_bits();
// Names of the bits set in one status pair (alarm1/alarm2 or warning1/warning2); reserved bits
// appear as "reserved_bit_N" (status byte 1) or "status2_reserved_bit_N" (status byte 2).
std::vector<std::string> bms_status_names(std::uint8_t status1, std::uint8_t status2);

// ---- Ultrasonic negative distance codes -------------------------------------------------------
enum class UltrasonicCode : std::int16_t {
  kOffline = -1,
  kChecksumFailed = -2,
  kAbnormalData = -3,
  kSystemException = -4,
};
// "ok" for a non-negative raw value, otherwise the code's name ("offline", ...) or "unknown_code".
std::string_view ultrasonic_status_name(std::int16_t raw);

}  // namespace ranger::protocol
