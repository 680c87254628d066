// The RANGER CAN protocol's vocabulary: identifiers, enumerations and named bits, as the manual
// (section 3.2, transcribed in shared/reference/PROTOCOL.md) and the vendor's later revision
// (shared/reference/PROTOCOL_AGX_V2.md) define them. Where the two revisions differ, the facts of
// both are here, selected by a profile field (profile.hpp): the error-word layout, the motion-mode
// numbering. Units and scaling live in codec.hpp; the manual's open points in interpretation.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::protocol {

// ---- Identifiers ------------------------------------------------------------------------------
// Host -> chassis
inline constexpr std::uint32_t kMotionCommandId = 0x111;
inline constexpr std::uint32_t kLightCommandId = 0x121;  // agx_v2
inline constexpr std::uint32_t kMotionModeCommandId = 0x141;
inline constexpr std::uint32_t kControlModeCommandId = 0x421;
inline constexpr std::uint32_t kErrorClearCommandId = 0x441;
inline constexpr std::uint32_t kUltrasonicSettingId = 0x451;
// Both directions (agx_v2): the host's version request (DLC 1, byte 0 = 0x01) and the chassis's
// answers (ASCII text, up to 8 characters a frame).
inline constexpr std::uint32_t kVersionId = 0x4A1;
inline constexpr std::uint8_t kVersionRequestValue = 0x01;
// Chassis -> host
inline constexpr std::uint32_t kSystemStatusId = 0x211;
inline constexpr std::uint32_t kMotionFeedbackId = 0x221;
inline constexpr std::uint32_t kLightStateId = 0x231;          // agx_v2
inline constexpr std::uint32_t kRemoteControlStateId = 0x241;  // agx_v2
inline constexpr std::uint32_t kMotorHighSpeedBaseId = 0x250;  // + motor number 1..8
inline constexpr std::uint32_t kMotorLowSpeedBaseId = 0x260;   // + motor number 1..8
inline constexpr std::uint32_t kSteeringAnglesId = 0x271;
inline constexpr std::uint32_t kWheelSpeedsId = 0x281;
inline constexpr std::uint32_t kMotionModeFeedbackId = 0x291;
inline constexpr std::uint32_t kOdometerId = 0x311;  // agx_v2
inline constexpr std::uint32_t kUltrasonic1to4Id = 0x342;
inline constexpr std::uint32_t kUltrasonic5to8Id = 0x343;
inline constexpr std::uint32_t kUltrasonicSettingFeedbackId = 0x45A;
inline constexpr std::uint32_t kBmsBaseId = 0x361;  // data: 0x361 + 2k, alarm: 0x362 + 2k, k = 0..4

inline constexpr int kMotorCount = 8;
inline constexpr int kUltrasonicCount = 8;
inline constexpr int kBatteryCount = 4;  // slots 1..4; index 0 is the whole pack

// ---- The frame table ----------------------------------------------------------------------------
// Every frame of either revision, once: its identifier(s), name, direction, the length of its
// layout, its nominal period and the revisions that define it. The ID lists, DLC checks, names,
// the identification's vendor-only set, the monitor's expected rates, the virtual chassis's send
// schedule and the DBC cross-check (tests/dbc/check_dbc.py parses this table) all read it.
enum class Direction : std::uint8_t {
  kToChassis,    // the host's commands
  kFromChassis,  // the chassis's feedback
  kBoth,         // 0x4A1: the host's request and the chassis's answers
};
inline constexpr auto kDirectionNames = text::enum_names<Direction>({
    {Direction::kToChassis, "to_chassis"},
    {Direction::kFromChassis, "from_chassis"},
    {Direction::kBoth, "both"},
});
inline std::string_view to_string(Direction d) {
  return kDirectionNames.name(d);
}

// The revisions that define a frame (a bit set).
inline constexpr std::uint8_t kInManual = 1u << 0;  // the manual, section 3.2 (PROTOCOL.md)
inline constexpr std::uint8_t kInAgxV2 = 1u << 1;   // the vendor's revision (PROTOCOL_AGX_V2.md)

struct FrameInfo {
  std::uint32_t id;  // the first identifier of the row
  int count;         // identifiers in the row: id, id + stride, ... (motors, batteries)
  int stride;
  std::string_view name;  // snake_case, stable
  Direction direction;
  int length;     // the layout's length in bytes, the same in every revision that defines the frame
                  // (a received frame may be longer, never shorter); 0x4A1: the request's
  int period_ms;  // nominal period; 0: sent on request or on change
  std::uint8_t revisions;

  constexpr bool holds(std::uint32_t x) const {
    if (x < id) return false;
    const std::uint32_t offset = x - id;
    return offset % static_cast<std::uint32_t>(stride) == 0 &&
           offset / static_cast<std::uint32_t>(stride) < static_cast<std::uint32_t>(count);
  }
};

// clang-format off
inline constexpr FrameInfo kFrameTable[] = {
  // id                          count stride name                     direction               length period  revisions
  {kMotionCommandId,               1, 1, "motion_command",              Direction::kToChassis,   8,  20, kInManual | kInAgxV2},
  {kLightCommandId,                1, 1, "light_command",               Direction::kToChassis,   8,   0, kInAgxV2},
  {kMotionModeCommandId,           1, 1, "motion_mode_command",         Direction::kToChassis,   1,   0, kInManual | kInAgxV2},
  {kSystemStatusId,                1, 1, "system_status",               Direction::kFromChassis, 8,  20, kInManual | kInAgxV2},
  {kMotionFeedbackId,              1, 1, "motion_feedback",             Direction::kFromChassis, 8,  20, kInManual | kInAgxV2},
  // 0x231 and 0x241: the period the vendor's manuals of the same family give (assumed here)
  {kLightStateId,                  1, 1, "light_state",                 Direction::kFromChassis, 8,  20, kInAgxV2},
  {kRemoteControlStateId,          1, 1, "remote_control",              Direction::kFromChassis, 8,  20, kInAgxV2},
  {kMotorHighSpeedBaseId + 1, kMotorCount, 1, "motor_high_speed",       Direction::kFromChassis, 8,  20, kInManual | kInAgxV2},
  {kMotorLowSpeedBaseId + 1,  kMotorCount, 1, "motor_low_speed",        Direction::kFromChassis, 8, 100, kInManual | kInAgxV2},
  {kSteeringAnglesId,              1, 1, "steering_angles",             Direction::kFromChassis, 8,  20, kInManual | kInAgxV2},
  {kWheelSpeedsId,                 1, 1, "wheel_speeds",                Direction::kFromChassis, 8,  20, kInManual | kInAgxV2},
  {kMotionModeFeedbackId,          1, 1, "motion_mode",                 Direction::kFromChassis, 2,  20, kInManual | kInAgxV2},
  {kOdometerId,                    1, 1, "odometer",                    Direction::kFromChassis, 8,   0, kInAgxV2},
  {kUltrasonic1to4Id,              2, 1, "ultrasonic",                  Direction::kFromChassis, 8,  50, kInManual | kInAgxV2},
  {kBmsBaseId,         kBatteryCount + 1, 2, "bms",                     Direction::kFromChassis, 8, 500, kInManual | kInAgxV2},
  {kBmsBaseId + 1,     kBatteryCount + 1, 2, "bms_alarm",               Direction::kFromChassis, 4, 500, kInManual | kInAgxV2},
  {kControlModeCommandId,          1, 1, "control_mode_command",        Direction::kToChassis,   1,   0, kInManual | kInAgxV2},
  {kErrorClearCommandId,           1, 1, "error_clear_command",         Direction::kToChassis,   1,   0, kInManual | kInAgxV2},
  {kUltrasonicSettingId,           1, 1, "ultrasonic_setting",          Direction::kToChassis,   1,   0, kInManual | kInAgxV2},
  {kUltrasonicSettingFeedbackId,   1, 1, "ultrasonic_setting_feedback", Direction::kFromChassis, 1,   0, kInManual | kInAgxV2},
  {kVersionId,                     1, 1, "version",                     Direction::kBoth,        1,   0, kInAgxV2},
};
// clang-format on

// The index of `id`'s row in kFrameTable; std::size(kFrameTable) for an identifier of neither
// revision. (An index, not a pointer: constant evaluation under -fsanitize=undefined refuses to
// compare a pointer into the table with nullptr.)
constexpr std::size_t frame_index(std::uint32_t id) {
  for (std::size_t i = 0; i < std::size(kFrameTable); ++i) {
    if (kFrameTable[i].holds(id)) return i;
  }
  return std::size(kFrameTable);
}
// The row of `id`; nullptr for an identifier of neither revision.
constexpr const FrameInfo* find_frame(std::uint32_t id) {
  const std::size_t i = frame_index(id);
  return i < std::size(kFrameTable) ? &kFrameTable[i] : nullptr;
}
// The nominal period of `id`'s frame in milliseconds (0: on request or on change, or unknown).
constexpr int frame_period_ms(std::uint32_t id) {
  const std::size_t i = frame_index(id);
  return i < std::size(kFrameTable) ? kFrameTable[i].period_ms : 0;
}

// Every identifier of either revision, in ascending order (receive filters, frame-rate
// statistics). The decoder knows all of them whatever the profile.
std::vector<std::uint32_t> all_ids();
// The identifiers of the manual (section 3.2), in ascending order.
std::vector<std::uint32_t> manual_ids();
bool is_known_id(std::uint32_t id);
// The length of `id`'s layout: the bytes its decoder reads (-1 for an unknown ID). A received
// frame may be longer (its extra bytes are ignored), never shorter. 0x4A1: 1 (the request; an
// answer's text is as long as the frame).
int layout_dlc(std::uint32_t id);
// Bytes of `frame` past its layout that a decoder ignores (0 for an unknown ID, an error frame, a
// frame not longer than its layout, or a 0x4A1 answer, whose text is the whole frame).
int extra_bytes(const CanFrame& frame);
// A 0x4A1 frame is the host's version request when byte 0 is 0x01 and every further byte is zero
// (a request padded to 8 bytes); anything else on 0x4A1 is an answer (text).
bool is_version_request(const CanFrame& frame);
// True when the chassis sent `frame` (feedback, or a 0x4A1 answer), false for the host's.
bool is_chassis_frame(const CanFrame& frame);
// A short snake_case name for `id` ("motion_command", "bms", ...), "unknown" otherwise.
std::string_view frame_name(std::uint32_t id);

// The chassis stops if no 0x111 arrives for this long; the host keeps it alive at 0x111's period.
inline constexpr int kChassisCommandTimeoutMs = 500;
inline constexpr int kKeepAlivePeriodMs = frame_period_ms(kMotionCommandId);

// ---- Enumerations ------------------------------------------------------------------------------
// Motion modes. The values are agx_v2's wire numbering; the wire value of a mode depends on the
// profile's ModeNumbering (motion_mode_from_wire / motion_mode_to_wire): the manual knows only
// 0-2, the MINI V1 sends side slip as 3 and has no park.
enum class MotionMode : std::uint8_t {
  kAckermann = 0x00,
  kOblique = 0x01,
  kSpin = 0x02,
  kPark = 0x03,
  kSideSlip = 0x04,
};
// Control modes (0x211 byte 1, 0x421). UART (0x02) is agx_v2's; the host may select only standby
// and CAN.
enum class ControlMode : std::uint8_t {
  kStandby = 0x00,
  kCan = 0x01,
  kUart = 0x02,
  kRemote = 0x03
};
// 0x01 is not in this manual's table; the profile's vehicle_status_1_is_estop decides.
enum class VehicleStatus : std::uint8_t { kNormal = 0x00, kEmergencyStop = 0x01, kAbnormal = 0x02 };

// The modes `numbering` defines, in wire order.
std::vector<MotionMode> motion_modes(ModeNumbering numbering);
// The mode wire value `raw` stands for under `numbering`; nullopt when it defines none.
std::optional<MotionMode> motion_mode_from_wire(std::uint8_t raw, ModeNumbering numbering);
// The wire value of `mode` under `numbering`; nullopt when the numbering has no such mode.
std::optional<std::uint8_t> motion_mode_to_wire(MotionMode mode, ModeNumbering numbering);

// 0x241 switch positions (two bits per switch; wire values). 0 is not defined.
enum class RemoteSwitch : std::uint8_t { kUndefined = 0, kMiddle = 1, kUp = 2, kDown = 3 };
// 0x241 bytes 1-5: int8 stick and knob positions. Reading (no RANGER source states it): the
// vendor's remote reports -100..100, full deflection at +-100, as on its other chassis.
inline constexpr double kRemoteAxisFullScale = 100.0;
// 0x121 / 0x231 light modes (wire values).
enum class LightMode : std::uint8_t { kOff = 0, kOn = 1, kBreathing = 2, kCustom = 3 };

// 0x441 payload: which fault to clear. 0x00 clears every fault that is not critical
// (interpretation::critical_error_mask); a critical fault is cleared by its own code (0x01-0x10)
// or by the remote control's KEY1.
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

// Names (snake_case, stable) and every enumerator of each, in wire order: what the scenario
// language, the CLI and the ROS node accept and print.
inline constexpr auto kMotionModeNames = text::enum_names<MotionMode>({
    {MotionMode::kAckermann, "ackermann"},
    {MotionMode::kOblique, "oblique"},
    {MotionMode::kSpin, "spin"},
    {MotionMode::kPark, "park"},
    {MotionMode::kSideSlip, "side_slip"},
});
inline constexpr auto kControlModeNames = text::enum_names<ControlMode>({
    {ControlMode::kStandby, "standby"},
    {ControlMode::kCan, "can"},
    {ControlMode::kUart, "uart"},
    {ControlMode::kRemote, "remote"},
});
inline constexpr auto kVehicleStatusNames = text::enum_names<VehicleStatus>({
    {VehicleStatus::kNormal, "normal"},
    {VehicleStatus::kEmergencyStop, "emergency_stop"},
    {VehicleStatus::kAbnormal, "abnormal"},
});
inline constexpr auto kRemoteSwitchNames = text::enum_names<RemoteSwitch>({
    {RemoteSwitch::kUndefined, "undefined"},
    {RemoteSwitch::kMiddle, "middle"},
    {RemoteSwitch::kUp, "up"},
    {RemoteSwitch::kDown, "down"},
});
inline constexpr auto kLightModeNames = text::enum_names<LightMode>({
    {LightMode::kOff, "off"},
    {LightMode::kOn, "on"},
    {LightMode::kBreathing, "breathing"},
    {LightMode::kCustom, "custom"},
});
inline std::string_view to_string(MotionMode m) {
  return kMotionModeNames.name(m);
}
inline std::string_view to_string(ControlMode m) {
  return kControlModeNames.name(m);
}
inline std::string_view to_string(VehicleStatus s) {
  return kVehicleStatusNames.name(s);
}
inline std::string_view to_string(RemoteSwitch s) {
  return kRemoteSwitchNames.name(s);
}
inline std::string_view to_string(LightMode m) {
  return kLightModeNames.name(m);
}
// Describes what a 0x441 code clears ("all non-critical faults", "motor driver 3 communication
// fault").
std::string error_clear_description(std::uint8_t code);

// ---- 0x211 error bits -------------------------------------------------------------------------
// Two layouts (profile.hpp, ErrorWordLayout):
//  * kManual32: bytes 4-7 form one big-endian uint32 (byte 4 is the most significant), so a bit's
//    position in the word is (7 - byte) * 8 + bit;
//  * kAgxV2_16: bytes 4-5 form a big-endian uint16, byte 6 is reserved, byte 7 is a counter.
// SystemStatus::error_bits holds the word of the layout in use.
constexpr int error_bit_index(int byte, int bit) {
  return (7 - byte) * 8 + bit;
}
// Width of the error word, in bits: 32 or 16.
int error_word_bits(ErrorWordLayout layout);

struct NamedBit {
  int index;              // bit position in the word (or byte) it belongs to
  std::string_view name;  // snake_case, stable: used in JSON, ROS messages and diagnostics
  std::string_view description;
};

// Every defined error bit of a layout: the rows of the fault table (below) with a bit in it, in
// ascending bit order (reserved bits are absent). A fault's name is the same in either layout.
const std::vector<NamedBit>& system_error_bits(ErrorWordLayout layout);
const std::vector<NamedBit>& system_error_bits();  // the manual's (kManual32)
// Names of the bits set in `error_word`; reserved bits that are set appear as "reserved_bit_N".
std::vector<std::string> error_bit_names(std::uint32_t error_word, ErrorWordLayout layout);
std::vector<std::string> error_bit_names(std::uint32_t error_word);  // kManual32

// Bits that, when set, mean the chassis will not (or must not) move: the critical set of
// interpretation.hpp (critical_error_mask).
bool is_critical_error(std::uint32_t error_word, ErrorWordLayout layout);
bool is_critical_error(std::uint32_t error_word);  // kManual32

// Faults by meaning, so that the controller, the virtual chassis and the ROS node never write a
// bit position. `motor` numbers the motor of a motor-numbered fault (protocol numbering, 1..8: the
// wheels 1-4 and steering motors 5-8 in the manual's wheel order RF, RR, LR, LF); 0 otherwise.
enum class Fault {
  kBatteryUnderVoltage,
  kBatteryWarning,
  kUltrasonicTriggered,
  kRemoteSignalLost,
  kHostCommunicationLost,
  kDriverStatusError,
  kOverTemperature,
  kOverCurrent,
  kMotorCommunication,   // motor-numbered
  kSteeringCalibration,  // motor-numbered (steering motors 5..8)
  kSteeringCalibrationTimeout,
  kSafetyEdge,
  kSteeringServoWarning,  // motor-numbered (steering motors 5..8)
  kSteeringEncoder,
};
// The names of the faults by meaning (a motor-numbered fault's rows in the fault table below
// carry the motor in their own names).
inline constexpr auto kFaultNames = text::enum_names<Fault>({
    {Fault::kBatteryUnderVoltage, "battery_under_voltage"},
    {Fault::kBatteryWarning, "battery_warning"},
    {Fault::kUltrasonicTriggered, "ultrasonic_triggered"},
    {Fault::kRemoteSignalLost, "remote_signal_lost"},
    {Fault::kHostCommunicationLost, "host_communication_lost"},
    {Fault::kDriverStatusError, "driver_status_error"},
    {Fault::kOverTemperature, "over_temperature"},
    {Fault::kOverCurrent, "over_current"},
    {Fault::kMotorCommunication, "motor_communication"},
    {Fault::kSteeringCalibration, "steering_calibration"},
    {Fault::kSteeringCalibrationTimeout, "steering_calibration_timeout"},
    {Fault::kSafetyEdge, "safety_edge"},
    {Fault::kSteeringServoWarning, "steering_servo_warning"},
    {Fault::kSteeringEncoder, "steering_encoder"},
});
inline constexpr int kFaultCount = static_cast<int>(kFaultNames.size());
inline std::string_view to_string(Fault f) {
  return kFaultNames.name(f);
}

// ---- The fault table --------------------------------------------------------------------------
// One row per fault the chassis reports in 0x211, by meaning: its bit in each error-word layout
// (kNoBit when the layout has none), its stable snake_case name (ControllerState::faults, the ROS
// message's SystemErrors field, diagnostics, the scenario language: the same name on both
// revisions), whether it is critical (the chassis does not drive until it is cleared: our reading,
// interpretation.hpp) and a description. Every bit position of either layout is written here and
// nowhere else.
inline constexpr int kNoBit = -1;
struct FaultInfo {
  Fault fault;
  int motor;       // 1..8 for a motor-numbered fault, 0 otherwise
  int manual_bit;  // position in the kManual32 word (error_bit_index(byte, bit)) or kNoBit
  int agx16_bit;   // position in the kAgxV2_16 word or kNoBit
  bool critical;
  std::string_view name;
  std::string_view description;

  constexpr int bit(ErrorWordLayout layout) const {
    return layout == ErrorWordLayout::kAgxV2_16 ? agx16_bit : manual_bit;
  }
};
// clang-format off
inline constexpr FaultInfo kFaultTable[] = {
  // fault                             motor manual bit              agx16  critical
  {Fault::kBatteryUnderVoltage,         0, error_bit_index(7, 0),     0, true,  "battery_under_voltage", "battery under-voltage (agx_v2: battery fault)"},
  {Fault::kBatteryWarning,              0, kNoBit,                    1, false, "battery_warning", "battery warning"},
  {Fault::kUltrasonicTriggered,         0, error_bit_index(7, 1), kNoBit, false, "ultrasonic_obstacle_triggered", "ultrasonic obstacle avoidance triggered"},
  {Fault::kRemoteSignalLost,            0, error_bit_index(7, 2),     2, false, "remote_control_lost", "remote control lost-connection protection"},
  {Fault::kMotorCommunication,          1, error_bit_index(7, 3),     3, true,  "motor_driver_1_communication_fault", "communication fault of motor driver 1 (front-right wheel)"},
  {Fault::kMotorCommunication,          2, error_bit_index(7, 4),     4, true,  "motor_driver_2_communication_fault", "communication fault of motor driver 2 (rear-right wheel)"},
  {Fault::kMotorCommunication,          3, error_bit_index(7, 5),     5, true,  "motor_driver_3_communication_fault", "communication fault of motor driver 3 (rear-left wheel)"},
  {Fault::kMotorCommunication,          4, error_bit_index(7, 6),     6, true,  "motor_driver_4_communication_fault", "communication fault of motor driver 4 (front-left wheel)"},
  {Fault::kDriverStatusError,           0, error_bit_index(6, 0),     8, true,  "driver_status_error", "motor driver status error (agx_v2: motor driver fault)"},
  {Fault::kHostCommunicationLost,       0, error_bit_index(6, 1),     9, false, "host_communication_lost", "communication with the upper layer (host) lost"},
  {Fault::kMotorCommunication,          5, error_bit_index(6, 2), kNoBit, true,  "motor_driver_5_communication_fault", "communication fault of motor driver 5 (front-right steering)"},
  {Fault::kMotorCommunication,          6, error_bit_index(6, 3), kNoBit, true,  "motor_driver_6_communication_fault", "communication fault of motor driver 6 (rear-right steering)"},
  {Fault::kMotorCommunication,          7, error_bit_index(6, 4), kNoBit, true,  "motor_driver_7_communication_fault", "communication fault of motor driver 7 (rear-left steering)"},
  {Fault::kMotorCommunication,          8, error_bit_index(6, 5), kNoBit, true,  "motor_driver_8_communication_fault", "communication fault of motor driver 8 (front-left steering)"},
  {Fault::kOverTemperature,             0, error_bit_index(6, 6), kNoBit, true,  "over_temperature", "over-temperature protection"},
  {Fault::kOverCurrent,                 0, error_bit_index(6, 7), kNoBit, true,  "over_current", "over-current protection"},
  {Fault::kSteeringCalibration,         5, error_bit_index(5, 0), kNoBit, true,  "steering_calibration_fault_front_right", "steering zero-point calibration fault, front-right"},
  {Fault::kSteeringCalibration,         6, error_bit_index(5, 1), kNoBit, true,  "steering_calibration_fault_rear_right", "steering zero-point calibration fault, rear-right"},
  {Fault::kSteeringCalibration,         7, error_bit_index(5, 2), kNoBit, true,  "steering_calibration_fault_rear_left", "steering zero-point calibration fault, rear-left"},
  {Fault::kSteeringCalibration,         8, error_bit_index(5, 3), kNoBit, true,  "steering_calibration_fault_front_left", "steering zero-point calibration fault, front-left"},
  {Fault::kSteeringCalibrationTimeout,  0, error_bit_index(5, 4), kNoBit, true,  "steering_calibration_timeout", "steering calibration timeout"},
  {Fault::kSafetyEdge,                  0, error_bit_index(5, 5), kNoBit, true,  "safety_edge_collision", "safety edge (bumper) collision"},
  {Fault::kSteeringServoWarning,        5, error_bit_index(4, 0), kNoBit, false, "steering_servo_warning_front_right", "steering servo warning, front-right"},
  {Fault::kSteeringServoWarning,        6, error_bit_index(4, 1), kNoBit, false, "steering_servo_warning_rear_right", "steering servo warning, rear-right"},
  {Fault::kSteeringServoWarning,        7, error_bit_index(4, 2), kNoBit, false, "steering_servo_warning_rear_left", "steering servo warning, rear-left"},
  {Fault::kSteeringServoWarning,        8, error_bit_index(4, 3), kNoBit, false, "steering_servo_warning_front_left", "steering servo warning, front-left"},
  {Fault::kSteeringEncoder,             0, kNoBit,                    7, true,  "steering_encoder_fault", "steering encoder fault"},
};
// clang-format on

// The row of `fault` (and `motor`, for a motor-numbered fault); nullptr when the table has none.
const FaultInfo* find_fault(Fault fault, int motor = 0);
// The row named `name`; nullptr when no row has that name.
const FaultInfo* find_fault(std::string_view name);
// The row whose bit in `layout`'s word is `index`; nullptr for a reserved bit.
const FaultInfo* fault_at(ErrorWordLayout layout, int index);
// The fault's bit (a one-bit mask) in a layout's word, 0 when the layout has no such bit.
std::uint32_t fault_bit(Fault fault, ErrorWordLayout layout, int motor = 0);

// ---- 0x261-0x268 driver status bits -----------------------------------------------------------
// In the manual's meaning (bit 6 set = disabled); the codec converts agx_v2's enable bit
// (profile: driver_status_bit6).
namespace driver_status {
inline constexpr std::uint8_t kSupplyVoltageLow = 1u << 0;
inline constexpr std::uint8_t kMotorOverTemperature = 1u << 1;
inline constexpr std::uint8_t kDriverOverCurrent = 1u << 2;
inline constexpr std::uint8_t kDriverOverTemperature = 1u << 3;
inline constexpr std::uint8_t kSensorAbnormal = 1u << 4;
inline constexpr std::uint8_t kDriverError = 1u << 5;
inline constexpr std::uint8_t kDriverDisabled = 1u << 6;
}  // namespace driver_status
const std::vector<NamedBit>& driver_status_bits();
std::vector<std::string> driver_status_names(std::uint8_t status);

// ---- 0x362... BMS alarm / warning bits --------------------------------------------------------
// Status byte 1 (alarm and warning use the same layout) and status byte 2.
namespace bms_status {
inline constexpr std::uint8_t kOverVoltage = 1u << 1;           // status byte 1
inline constexpr std::uint8_t kUnderVoltage = 1u << 2;          // status byte 1
inline constexpr std::uint8_t kHighTemperature = 1u << 3;       // status byte 1
inline constexpr std::uint8_t kLowTemperature = 1u << 4;        // status byte 1
inline constexpr std::uint8_t kDischargeOverCurrent = 1u << 7;  // status byte 1
inline constexpr std::uint8_t kChargeOverCurrent = 1u << 0;     // status byte 2
}  // namespace bms_status
const std::vector<NamedBit>& bms_status1_bits();
const std::vector<NamedBit>& bms_status2_bits();
// Names of the bits set in one status pair (alarm1/alarm2 or warning1/warning2); reserved bits
// appear as "reserved_bit_N" (status byte 1) or "status2_reserved_bit_N" (status byte 2).
std::vector<std::string> bms_status_names(std::uint8_t status1, std::uint8_t status2);

// ---- Ultrasonic distance codes ----------------------------------------------------------------
// The manual: a positive value is a distance, a negative one a code. 0 is neither: it is read as
// "no reading" (interpretation::kUltrasonicNoReading).
enum class UltrasonicCode : std::int16_t {
  kOffline = -1,
  kChecksumFailed = -2,
  kAbnormalData = -3,
  kSystemException = -4,
};
inline constexpr auto kUltrasonicCodeNames = text::enum_names<UltrasonicCode>({
    {UltrasonicCode::kOffline, "offline"},
    {UltrasonicCode::kChecksumFailed, "checksum_failed"},
    {UltrasonicCode::kAbnormalData, "abnormal_data"},
    {UltrasonicCode::kSystemException, "system_exception"},
});
// "ok" for a positive raw value (a distance), "no_reading" for 0, otherwise the code's name
// ("offline", ...) or "unknown_code".
std::string_view ultrasonic_status_name(std::int16_t raw);

}  // namespace ranger::protocol
