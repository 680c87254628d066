// The protocol's vocabulary as data: identifiers, DLCs, names of every defined bit.
#include "ranger_can/wire/protocol.hpp"

#include <initializer_list>
#include <string>

namespace ranger::protocol {

namespace {

constexpr bool is_motor_id(std::uint32_t id, std::uint32_t base) {
  return id > base && id <= base + static_cast<std::uint32_t>(kMotorCount);
}
constexpr bool is_bms_id(std::uint32_t id) {
  return id >= kBmsBaseId && id < kBmsBaseId + 10;
}

}  // namespace

std::vector<std::uint32_t> all_ids() {
  std::vector<std::uint32_t> ids = {kMotionCommandId, kMotionModeCommandId, kSystemStatusId,
                                    kMotionFeedbackId};
  for (std::uint32_t m = 1; m <= kMotorCount; ++m)
    ids.push_back(kMotorHighSpeedBaseId + m);
  for (std::uint32_t m = 1; m <= kMotorCount; ++m)
    ids.push_back(kMotorLowSpeedBaseId + m);
  ids.insert(ids.end(), {kSteeringAnglesId, kWheelSpeedsId, kMotionModeFeedbackId,
                         kUltrasonic1to4Id, kUltrasonic5to8Id});
  for (std::uint32_t k = 0; k < 10; ++k)
    ids.push_back(kBmsBaseId + k);
  ids.insert(ids.end(), {kControlModeCommandId, kErrorClearCommandId, kUltrasonicSettingId,
                         kUltrasonicSettingFeedbackId});
  return ids;  // ascending: 0x111 ... 0x36A, 0x421, 0x441, 0x451, 0x45A
}

bool is_known_id(std::uint32_t id) {
  return expected_dlc(id) >= 0;
}

int expected_dlc(std::uint32_t id) {
  switch (id) {
    case kMotionCommandId:
    case kSystemStatusId:
    case kMotionFeedbackId:
    case kSteeringAnglesId:
    case kWheelSpeedsId:
    case kUltrasonic1to4Id:
    case kUltrasonic5to8Id:
      return 8;
    case kMotionModeCommandId:
    case kControlModeCommandId:
    case kErrorClearCommandId:
    case kUltrasonicSettingId:
    case kUltrasonicSettingFeedbackId:
      return 1;
    case kMotionModeFeedbackId:
      return 2;
    default:
      break;
  }
  if (is_motor_id(id, kMotorHighSpeedBaseId) || is_motor_id(id, kMotorLowSpeedBaseId)) return 8;
  if (is_bms_id(id)) return ((id - kBmsBaseId) % 2 == 0) ? 8 : 4;
  return -1;
}

std::string_view frame_name(std::uint32_t id) {
  switch (id) {
    case kMotionCommandId:
      return "motion_command";
    case kMotionModeCommandId:
      return "motion_mode_command";
    case kControlModeCommandId:
      return "control_mode_command";
    case kErrorClearCommandId:
      return "error_clear_command";
    case kUltrasonicSettingId:
      return "ultrasonic_setting";
    case kSystemStatusId:
      return "system_status";
    case kMotionFeedbackId:
      return "motion_feedback";
    case kSteeringAnglesId:
      return "steering_angles";
    case kWheelSpeedsId:
      return "wheel_speeds";
    case kMotionModeFeedbackId:
      return "motion_mode";
    case kUltrasonic1to4Id:
    case kUltrasonic5to8Id:
      return "ultrasonic";
    case kUltrasonicSettingFeedbackId:
      return "ultrasonic_setting_feedback";
    default:
      break;
  }
  if (is_motor_id(id, kMotorHighSpeedBaseId)) return "motor_high_speed";
  if (is_motor_id(id, kMotorLowSpeedBaseId)) return "motor_low_speed";
  if (is_bms_id(id)) return ((id - kBmsBaseId) % 2 == 0) ? "bms" : "bms_alarm";
  return "unknown";
}

std::string_view to_string(MotionMode m) {
  switch (m) {
    case MotionMode::kAckermann:
      return "ackermann";
    case MotionMode::kOblique:
      return "oblique";
    case MotionMode::kSpin:
      return "spin";
  }
  return "unknown";
}

std::string_view to_string(ControlMode m) {
  switch (m) {
    case ControlMode::kStandby:
      return "standby";
    case ControlMode::kCan:
      return "can";
    case ControlMode::kRemote:
      return "remote";
  }
  return "unknown";
}

std::string_view to_string(VehicleStatus s) {
  switch (s) {
    case VehicleStatus::kNormal:
      return "normal";
    case VehicleStatus::kEmergencyStop:
      return "emergency_stop";
    case VehicleStatus::kAbnormal:
      return "abnormal";
  }
  return "unknown";
}

std::string error_clear_description(std::uint8_t code) {
  if (code == 0x00) return "all non-critical faults";
  if (code >= 0x01 && code <= 0x08) {
    return "motor driver " + std::to_string(code) + " communication fault";
  }
  if (code == 0x09) return "battery under-voltage fault (and try to restore power)";
  if (code == 0x0A) return "remote-control signal loss fault";
  if (code >= 0x0B && code <= 0x0E) {
    return "steering calibration fault of motor " + std::to_string(code - 0x0B + 5);
  }
  if (code == 0x0F) return "over-current fault";
  if (code == 0x10) return "over-temperature fault";
  return "undefined code " + std::to_string(code);
}

// ---- 0x211 error bits -------------------------------------------------------------------------

const std::vector<NamedBit>& system_error_bits() {
  // Wheel order of the manual (RF, RR, LR, LF), named as in geometry.hpp's joint names.
  static const std::vector<NamedBit> bits = {
      // byte 7 (least significant)
      {error_bit_index(7, 0), "battery_under_voltage", "battery under-voltage"},
      {error_bit_index(7, 1), "ultrasonic_obstacle_triggered",
       "ultrasonic obstacle avoidance triggered"},
      {error_bit_index(7, 2), "remote_control_lost", "remote control lost-connection protection"},
      {error_bit_index(7, 3), "motor_driver_1_communication_fault",
       "communication fault of motor driver 1 (front-right wheel)"},
      {error_bit_index(7, 4), "motor_driver_2_communication_fault",
       "communication fault of motor driver 2 (rear-right wheel)"},
      {error_bit_index(7, 5), "motor_driver_3_communication_fault",
       "communication fault of motor driver 3 (rear-left wheel)"},
      {error_bit_index(7, 6), "motor_driver_4_communication_fault",
       "communication fault of motor driver 4 (front-left wheel)"},
      // byte 6
      {error_bit_index(6, 0), "driver_status_error", "motor driver status error"},
      {error_bit_index(6, 1), "host_communication_lost",
       "communication with the upper layer (host) lost"},
      {error_bit_index(6, 2), "motor_driver_5_communication_fault",
       "communication fault of motor driver 5 (front-right steering)"},
      {error_bit_index(6, 3), "motor_driver_6_communication_fault",
       "communication fault of motor driver 6 (rear-right steering)"},
      {error_bit_index(6, 4), "motor_driver_7_communication_fault",
       "communication fault of motor driver 7 (rear-left steering)"},
      {error_bit_index(6, 5), "motor_driver_8_communication_fault",
       "communication fault of motor driver 8 (front-left steering)"},
      {error_bit_index(6, 6), "over_temperature", "over-temperature protection"},
      {error_bit_index(6, 7), "over_current", "over-current protection"},
      // byte 5
      {error_bit_index(5, 0), "steering_calibration_fault_front_right",
       "steering zero-point calibration fault, front-right"},
      {error_bit_index(5, 1), "steering_calibration_fault_rear_right",
       "steering zero-point calibration fault, rear-right"},
      {error_bit_index(5, 2), "steering_calibration_fault_rear_left",
       "steering zero-point calibration fault, rear-left"},
      {error_bit_index(5, 3), "steering_calibration_fault_front_left",
       "steering zero-point calibration fault, front-left"},
      {error_bit_index(5, 4), "steering_calibration_timeout", "steering calibration timeout"},
      {error_bit_index(5, 5), "safety_edge_collision", "safety edge (bumper) collision"},
      // byte 4 (most significant)
      {error_bit_index(4, 0), "steering_servo_warning_front_right",
       "steering servo warning, front-right"},
      {error_bit_index(4, 1), "steering_servo_warning_rear_right",
       "steering servo warning, rear-right"},
      {error_bit_index(4, 2), "steering_servo_warning_rear_left",
       "steering servo warning, rear-left"},
      {error_bit_index(4, 3), "steering_servo_warning_front_left",
       "steering servo warning, front-left"},
  };
  return bits;
}

namespace {

std::vector<std::string> names_of_set_bits(std::uint32_t word, int width,
                                           const std::vector<NamedBit>& table) {
  std::vector<std::string> names;
  for (int i = 0; i < width; ++i) {
    if ((word >> i & 1u) == 0) continue;
    bool named = false;
    for (const auto& b : table) {
      if (b.index == i) {
        names.emplace_back(b.name);
        named = true;
        break;
      }
    }
    if (!named) names.push_back("reserved_bit_" + std::to_string(i));
  }
  return names;
}

std::uint32_t mask_of(std::initializer_list<int> indices) {
  std::uint32_t m = 0;
  for (int i : indices)
    m |= 1u << i;
  return m;
}

}  // namespace

std::vector<std::string> error_bit_names(std::uint32_t error_word) {
  return names_of_set_bits(error_word, 32, system_error_bits());
}

bool is_critical_error(std::uint32_t error_word) {
  // Faults after which the chassis does not drive until they are cleared (0x441 or KEY1):
  // collision, driver and communication faults, protections, calibration faults. Warnings (steering
  // servo), host-link loss (cured by commanding again), ultrasonic triggering and remote-control
  // loss are transient conditions and do not count.
  static const std::uint32_t kCritical = mask_of({
      error_bit_index(7, 0),
      error_bit_index(7, 3),
      error_bit_index(7, 4),
      error_bit_index(7, 5),
      error_bit_index(7, 6),
      error_bit_index(6, 0),
      error_bit_index(6, 2),
      error_bit_index(6, 3),
      error_bit_index(6, 4),
      error_bit_index(6, 5),
      error_bit_index(6, 6),
      error_bit_index(6, 7),
      error_bit_index(5, 0),
      error_bit_index(5, 1),
      error_bit_index(5, 2),
      error_bit_index(5, 3),
      error_bit_index(5, 4),
      error_bit_index(5, 5),
  });
  return (error_word & kCritical) != 0;
}

// ---- 0x261-0x268 driver status bits -----------------------------------------------------------

const std::vector<NamedBit>& driver_status_bits() {
  static const std::vector<NamedBit> bits = {
      {0, "supply_voltage_low", "power supply voltage too low"},
      {1, "motor_over_temperature", "motor over-temperature"},
      {2, "driver_over_current", "driver over-current"},
      {3, "driver_over_temperature", "driver over-temperature"},
      {4, "sensor_abnormal", "sensor status abnormal"},
      {5, "driver_error", "driver error"},
      {6, "driver_disabled", "driver disabled (0 = enabled)"},
  };
  return bits;
}

std::vector<std::string> driver_status_names(std::uint8_t status) {
  return names_of_set_bits(status, 8, driver_status_bits());
}

// ---- BMS alarm / warning bits -----------------------------------------------------------------

const std::vector<NamedBit>& bms_status1_bits() {
  static const std::vector<NamedBit> bits = {
      {1, "over_voltage", "over-voltage"},
      {2, "under_voltage", "under-voltage"},
      {3, "high_temperature", "high temperature"},
      {4, "low_temperature", "low temperature"},
      {7, "discharge_over_current", "discharge over-current"},
  };
  return bits;
}

const std::vector<NamedBit>& bms_status2_bits() {
  static const std::vector<NamedBit> bits = {
      {0, "charge_over_current", "charging over-current"},
  };
  return bits;
}

std::vector<std::string> bms_status_names(std::uint8_t status1, std::uint8_t status2) {
  std::vector<std::string> names = names_of_set_bits(status1, 8, bms_status1_bits());
  for (auto& n : names_of_set_bits(status2, 8, bms_status2_bits())) {
    names.push_back(n.rfind("reserved_bit_", 0) == 0 ? "status2_" + n : std::move(n));
  }
  return names;
}

// ---- Ultrasonic -------------------------------------------------------------------------------

std::string_view ultrasonic_status_name(std::int16_t raw) {
  if (raw >= 0) return "ok";
  switch (static_cast<UltrasonicCode>(raw)) {
    case UltrasonicCode::kOffline:
      return "offline";
    case UltrasonicCode::kChecksumFailed:
      return "checksum_failed";
    case UltrasonicCode::kAbnormalData:
      return "abnormal_data";
    case UltrasonicCode::kSystemException:
      return "system_exception";
  }
  return "unknown_code";
}

}  // namespace ranger::protocol
