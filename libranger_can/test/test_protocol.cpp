// The protocol's vocabulary against the manual's tables: every error bit by byte and bit, the
// driver status and BMS bits, ultrasonic codes, IDs and DLCs.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::protocol {
namespace {

using Names = std::vector<std::string>;

// The 0x211 error bits as the manual's table lists them: (byte, bit) -> name.
struct ErrorBitRow {
  int byte, bit;
  const char* name;
};
const ErrorBitRow kManualErrorBits[] = {
    {4, 0, "steering_servo_warning_front_right"},
    {4, 1, "steering_servo_warning_rear_right"},
    {4, 2, "steering_servo_warning_rear_left"},
    {4, 3, "steering_servo_warning_front_left"},
    {5, 0, "steering_calibration_fault_front_right"},
    {5, 1, "steering_calibration_fault_rear_right"},
    {5, 2, "steering_calibration_fault_rear_left"},
    {5, 3, "steering_calibration_fault_front_left"},
    {5, 4, "steering_calibration_timeout"},
    {5, 5, "safety_edge_collision"},
    {6, 0, "driver_status_error"},
    {6, 1, "host_communication_lost"},
    {6, 2, "motor_driver_5_communication_fault"},
    {6, 3, "motor_driver_6_communication_fault"},
    {6, 4, "motor_driver_7_communication_fault"},
    {6, 5, "motor_driver_8_communication_fault"},
    {6, 6, "over_temperature"},
    {6, 7, "over_current"},
    {7, 0, "battery_under_voltage"},
    {7, 1, "ultrasonic_obstacle_triggered"},
    {7, 2, "remote_control_lost"},
    {7, 3, "motor_driver_1_communication_fault"},
    {7, 4, "motor_driver_2_communication_fault"},
    {7, 5, "motor_driver_3_communication_fault"},
    {7, 6, "motor_driver_4_communication_fault"},
};

// A 0x211 frame with exactly one bit set in byte `byte` (4..7), decoded through the codec so the
// test also pins the byte order of the error word.
std::uint32_t error_word_from_frame(int byte, int bit) {
  CanFrame f;
  f.id = kSystemStatusId;
  f.dlc = 8;
  f.data[static_cast<std::size_t>(byte)] = static_cast<std::uint8_t>(1u << bit);
  const auto m = decode(f);
  EXPECT_TRUE(m.ok());
  return std::get<SystemStatus>(*m).error_bits;
}

TEST(ProtocolErrorBits, EveryManualBitHasItsName) {
  for (const auto& row : kManualErrorBits) {
    const std::uint32_t word = error_word_from_frame(row.byte, row.bit);
    EXPECT_EQ(word, 1u << error_bit_index(row.byte, row.bit));
    EXPECT_EQ(error_bit_names(word), Names{row.name}) << "byte " << row.byte << " bit " << row.bit;
  }
}

TEST(ProtocolErrorBits, TableMatchesTheManualExactly) {
  const auto& table = system_error_bits();
  ASSERT_EQ(table.size(), std::size(kManualErrorBits));
  std::set<std::string> names;
  for (const auto& b : table) {
    EXPECT_TRUE(names.insert(std::string(b.name)).second) << "duplicate name " << b.name;
    EXPECT_FALSE(b.description.empty());
  }
  for (std::size_t i = 1; i < table.size(); ++i)
    EXPECT_LT(table[i - 1].index, table[i].index);
}

TEST(ProtocolErrorBits, ReservedBitsAreNamedByPosition) {
  // Reserved: byte 4 bits 4-7, byte 5 bits 6-7, byte 7 bit 7.
  EXPECT_EQ(error_bit_names(1u << error_bit_index(4, 7)), Names{"reserved_bit_31"});
  EXPECT_EQ(error_bit_names(1u << error_bit_index(5, 6)), Names{"reserved_bit_22"});
  EXPECT_EQ(error_bit_names(1u << error_bit_index(7, 7)), Names{"reserved_bit_7"});
  EXPECT_TRUE(error_bit_names(0).empty());
  EXPECT_EQ(error_bit_names(0xFFFFFFFFu).size(), 32u);
}

TEST(ProtocolErrorBits, SeveralBitsInAscendingOrder) {
  const std::uint32_t word = (1u << error_bit_index(5, 5)) | (1u << error_bit_index(7, 0));
  EXPECT_EQ(error_bit_names(word), (Names{"battery_under_voltage", "safety_edge_collision"}));
}

TEST(ProtocolErrorBits, CriticalErrors) {
  auto bit = [](int byte, int b) { return 1u << error_bit_index(byte, b); };
  EXPECT_FALSE(is_critical_error(0));
  EXPECT_TRUE(is_critical_error(bit(5, 5)));   // collision: must stop at once
  EXPECT_TRUE(is_critical_error(bit(6, 7)));   // over-current
  EXPECT_TRUE(is_critical_error(bit(6, 6)));   // over-temperature
  EXPECT_TRUE(is_critical_error(bit(7, 0)));   // under-voltage
  EXPECT_TRUE(is_critical_error(bit(7, 3)));   // motor 1 communication
  EXPECT_TRUE(is_critical_error(bit(6, 5)));   // motor 8 communication
  EXPECT_TRUE(is_critical_error(bit(5, 0)));   // steering calibration
  EXPECT_FALSE(is_critical_error(bit(4, 0)));  // a steering servo warning is only a warning
  EXPECT_FALSE(is_critical_error(bit(6, 1)));  // host link loss ends when the host commands
  EXPECT_FALSE(is_critical_error(bit(4, 7)));  // reserved
}

TEST(ProtocolDriverStatus, EveryBit) {
  const char* expected[] = {"supply_voltage_low",  "motor_over_temperature",
                            "driver_over_current", "driver_over_temperature",
                            "sensor_abnormal",     "driver_error",
                            "driver_disabled"};
  for (int bit = 0; bit < 7; ++bit) {
    EXPECT_EQ(driver_status_names(static_cast<std::uint8_t>(1u << bit)), Names{expected[bit]});
  }
  EXPECT_EQ(driver_status_names(0x80), Names{"reserved_bit_7"});
  EXPECT_TRUE(driver_status_names(0).empty());
  EXPECT_EQ(driver_status_bits().size(), 7u);
}

TEST(ProtocolBms, StatusBits) {
  EXPECT_EQ(bms_status_names(0x02, 0), Names{"over_voltage"});
  EXPECT_EQ(bms_status_names(0x04, 0), Names{"under_voltage"});
  EXPECT_EQ(bms_status_names(0x08, 0), Names{"high_temperature"});
  EXPECT_EQ(bms_status_names(0x10, 0), Names{"low_temperature"});
  EXPECT_EQ(bms_status_names(0x80, 0), Names{"discharge_over_current"});
  EXPECT_EQ(bms_status_names(0, 0x01), Names{"charge_over_current"});
  EXPECT_EQ(bms_status_names(0x01, 0x02), (Names{"reserved_bit_0", "status2_reserved_bit_1"}));
  EXPECT_TRUE(bms_status_names(0, 0).empty());
  EXPECT_EQ(bms_status1_bits().size(), 5u);
  EXPECT_EQ(bms_status2_bits().size(), 1u);
}

TEST(ProtocolUltrasonic, Codes) {
  EXPECT_EQ(ultrasonic_status_name(0), "ok");
  EXPECT_EQ(ultrasonic_status_name(1200), "ok");
  EXPECT_EQ(ultrasonic_status_name(-1), "offline");
  EXPECT_EQ(ultrasonic_status_name(-2), "checksum_failed");
  EXPECT_EQ(ultrasonic_status_name(-3), "abnormal_data");
  EXPECT_EQ(ultrasonic_status_name(-4), "system_exception");
  EXPECT_EQ(ultrasonic_status_name(-5), "unknown_code");
  EXPECT_EQ(ultrasonic_status_name(-32768), "unknown_code");
}

TEST(ProtocolIds, AllIdsAscendingWithTheirDlc) {
  const auto ids = all_ids();
  EXPECT_EQ(ids.size(), 5u + 2u + 16u + 3u + 2u + 10u + 1u);  // 39 frames in the manual
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());
  for (std::uint32_t id : ids) {
    EXPECT_TRUE(is_known_id(id));
    EXPECT_NE(frame_name(id), "unknown") << id;
  }
  const std::pair<std::uint32_t, int> dlcs[] = {
      {0x111, 8}, {0x141, 1}, {0x421, 1}, {0x441, 1}, {0x451, 1}, {0x211, 8}, {0x221, 8},
      {0x251, 8}, {0x258, 8}, {0x261, 8}, {0x268, 8}, {0x271, 8}, {0x281, 8}, {0x291, 2},
      {0x342, 8}, {0x343, 8}, {0x45A, 1}, {0x361, 8}, {0x362, 4}, {0x369, 8}, {0x36A, 4}};
  for (const auto& [id, dlc] : dlcs)
    EXPECT_EQ(expected_dlc(id), dlc) << std::hex << id;
  for (std::uint32_t id :
       {0x000u, 0x110u, 0x250u, 0x259u, 0x260u, 0x269u, 0x360u, 0x36Bu, 0x7FFu, 0x18FF0111u}) {
    EXPECT_FALSE(is_known_id(id)) << std::hex << id;
    EXPECT_EQ(expected_dlc(id), -1);
    EXPECT_EQ(frame_name(id), "unknown");
  }
}

TEST(ProtocolIds, FrameNamesOfTheJsonContract) {
  EXPECT_EQ(frame_name(0x111), "motion_command");
  EXPECT_EQ(frame_name(0x211), "system_status");
  EXPECT_EQ(frame_name(0x221), "motion_feedback");
  EXPECT_EQ(frame_name(0x271), "steering_angles");
  EXPECT_EQ(frame_name(0x281), "wheel_speeds");
  EXPECT_EQ(frame_name(0x291), "motion_mode");
  for (std::uint32_t id : {0x361u, 0x363u, 0x365u, 0x367u, 0x369u})
    EXPECT_EQ(frame_name(id), "bms");
  for (std::uint32_t id : {0x362u, 0x36Au})
    EXPECT_EQ(frame_name(id), "bms_alarm");
  EXPECT_EQ(frame_name(0x141), "motion_mode_command");
  EXPECT_EQ(frame_name(0x255), "motor_high_speed");
  EXPECT_EQ(frame_name(0x265), "motor_low_speed");
  EXPECT_EQ(frame_name(0x342), "ultrasonic");
  EXPECT_EQ(frame_name(0x45A), "ultrasonic_setting_feedback");
}

TEST(ProtocolEnums, Names) {
  EXPECT_EQ(to_string(MotionMode::kAckermann), "ackermann");
  EXPECT_EQ(to_string(MotionMode::kOblique), "oblique");
  EXPECT_EQ(to_string(MotionMode::kSpin), "spin");
  EXPECT_EQ(to_string(static_cast<MotionMode>(7)), "unknown");
  EXPECT_EQ(to_string(ControlMode::kStandby), "standby");
  EXPECT_EQ(to_string(ControlMode::kCan), "can");
  EXPECT_EQ(to_string(ControlMode::kRemote), "remote");
  EXPECT_EQ(to_string(VehicleStatus::kNormal), "normal");
  EXPECT_EQ(to_string(VehicleStatus::kEmergencyStop), "emergency_stop");
  EXPECT_EQ(to_string(VehicleStatus::kAbnormal), "abnormal");
}

TEST(ProtocolErrorClear, Descriptions) {
  EXPECT_EQ(error_clear_description(0x00), "all non-critical faults");
  EXPECT_EQ(error_clear_description(0x03), "motor driver 3 communication fault");
  EXPECT_EQ(error_clear_description(0x08), "motor driver 8 communication fault");
  EXPECT_NE(error_clear_description(0x09).find("under-voltage"), std::string::npos);
  EXPECT_NE(error_clear_description(0x0A).find("remote"), std::string::npos);
  EXPECT_EQ(error_clear_description(0x0B), "steering calibration fault of motor 5");
  EXPECT_EQ(error_clear_description(0x0E), "steering calibration fault of motor 8");
  EXPECT_EQ(error_clear_description(0x0F), "over-current fault");
  EXPECT_EQ(error_clear_description(0x10), "over-temperature fault");
  EXPECT_EQ(error_clear_description(0x11), "undefined code 17");
}

}  // namespace
}  // namespace ranger::protocol
