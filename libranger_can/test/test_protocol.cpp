// The protocol's vocabulary against the manual's tables and the vendor's revision: every error
// bit by byte and bit in both layouts, faults by meaning, the driver status and BMS bits,
// ultrasonic codes, IDs and layout lengths, motion-mode numberings.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
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
  EXPECT_EQ(ultrasonic_status_name(0), "no_reading");  // neither a distance nor a code
  EXPECT_EQ(ultrasonic_status_name(1), "ok");
  EXPECT_EQ(ultrasonic_status_name(1200), "ok");
  EXPECT_EQ(ultrasonic_status_name(-1), "offline");
  EXPECT_EQ(ultrasonic_status_name(-2), "checksum_failed");
  EXPECT_EQ(ultrasonic_status_name(-3), "abnormal_data");
  EXPECT_EQ(ultrasonic_status_name(-4), "system_exception");
  EXPECT_EQ(ultrasonic_status_name(-5), "unknown_code");
  EXPECT_EQ(ultrasonic_status_name(-32768), "unknown_code");
}

TEST(ProtocolIds, AllIdsAscendingWithTheirLayoutLength) {
  const auto ids = all_ids();
  const auto manual = manual_ids();
  // 39 frames in the manual, 5 more in agx_v2 (0x121, 0x231, 0x241, 0x311, 0x4A1).
  EXPECT_EQ(ids.size(), 39u + 5u);
  EXPECT_EQ(manual.size(), 39u);
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  EXPECT_TRUE(std::is_sorted(manual.begin(), manual.end()));
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());
  EXPECT_TRUE(std::includes(ids.begin(), ids.end(), manual.begin(), manual.end()));
  for (std::uint32_t id : ids) {
    EXPECT_TRUE(is_known_id(id));
    EXPECT_NE(frame_name(id), "unknown") << id;
  }
  const std::pair<std::uint32_t, int> dlcs[] = {
      {0x111, 8}, {0x141, 1}, {0x421, 1}, {0x441, 1}, {0x451, 1}, {0x211, 8}, {0x221, 8},
      {0x251, 8}, {0x258, 8}, {0x261, 8}, {0x268, 8}, {0x271, 8}, {0x281, 8}, {0x291, 2},
      {0x342, 8}, {0x343, 8}, {0x45A, 1}, {0x361, 8}, {0x362, 4}, {0x369, 8}, {0x36A, 4},
      {0x121, 8}, {0x231, 8}, {0x241, 8}, {0x311, 8}, {0x4A1, 1}};
  for (const auto& [id, dlc] : dlcs)
    EXPECT_EQ(layout_dlc(id), dlc) << std::hex << id;
  for (std::uint32_t id : {0x000u, 0x110u, 0x250u, 0x259u, 0x260u, 0x269u, 0x360u, 0x36Bu, 0x131u,
                           0x411u, 0x7FFu, 0x18FF0111u}) {
    EXPECT_FALSE(is_known_id(id)) << std::hex << id;
    EXPECT_EQ(layout_dlc(id), -1);
    EXPECT_EQ(frame_name(id), "unknown");
  }
}

CanFrame frame_with(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes)
    f.data[i++] = b;
  return f;
}

TEST(ProtocolIds, ExtraBytesPastTheLayout) {
  EXPECT_EQ(extra_bytes(frame_with(0x291, {0, 0})), 0);
  EXPECT_EQ(extra_bytes(frame_with(0x291, {0, 0, 0, 0, 0, 0, 0, 0})), 6);
  EXPECT_EQ(extra_bytes(frame_with(0x141, {2, 0, 0, 0, 0, 0, 0, 0})), 7);
  EXPECT_EQ(extra_bytes(frame_with(0x362, {0, 0, 0, 0, 0})), 1);
  EXPECT_EQ(extra_bytes(frame_with(0x221, {0, 0, 0})), 0) << "short: nothing extra";
  EXPECT_EQ(extra_bytes(frame_with(0x7FF, {0, 0, 0, 0})), 0) << "unknown ID: no layout";
  CanFrame error = frame_with(0x291, {0, 0, 0, 0});
  error.is_error = true;
  EXPECT_EQ(extra_bytes(error), 0);
  // 0x4A1: a request padded to 8 has 7 extra bytes; an answer's text is the whole frame.
  EXPECT_EQ(extra_bytes(frame_with(0x4A1, {1})), 0);
  EXPECT_EQ(extra_bytes(frame_with(0x4A1, {1, 0, 0, 0, 0, 0, 0, 0})), 7);
  EXPECT_EQ(extra_bytes(frame_with(0x4A1, {'V', '1', '.', '2', 0, 0, 0, 0})), 0);
  EXPECT_TRUE(is_version_request(frame_with(0x4A1, {1, 0, 0})));
  EXPECT_FALSE(is_version_request(frame_with(0x4A1, {1, 0, 'x'})));
  EXPECT_FALSE(is_version_request(frame_with(0x4A1, {2})));
  EXPECT_FALSE(is_version_request(frame_with(0x4A1, {})));
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
  EXPECT_EQ(frame_name(0x121), "light_command");
  EXPECT_EQ(frame_name(0x231), "light_state");
  EXPECT_EQ(frame_name(0x241), "remote_control");
  EXPECT_EQ(frame_name(0x311), "odometer");
  EXPECT_EQ(frame_name(0x4A1), "version");
}

TEST(ProtocolEnums, Names) {
  EXPECT_EQ(to_string(MotionMode::kAckermann), "ackermann");
  EXPECT_EQ(to_string(MotionMode::kOblique), "oblique");
  EXPECT_EQ(to_string(MotionMode::kSpin), "spin");
  EXPECT_EQ(to_string(MotionMode::kPark), "park");
  EXPECT_EQ(to_string(MotionMode::kSideSlip), "side_slip");
  EXPECT_EQ(to_string(static_cast<MotionMode>(7)), "unknown");
  EXPECT_EQ(to_string(ControlMode::kStandby), "standby");
  EXPECT_EQ(to_string(ControlMode::kCan), "can");
  EXPECT_EQ(to_string(ControlMode::kUart), "uart");
  EXPECT_EQ(to_string(ControlMode::kRemote), "remote");
  EXPECT_EQ(to_string(static_cast<ControlMode>(4)), "unknown");
  EXPECT_EQ(to_string(RemoteSwitch::kUp), "up");
  EXPECT_EQ(to_string(RemoteSwitch::kMiddle), "middle");
  EXPECT_EQ(to_string(RemoteSwitch::kDown), "down");
  EXPECT_EQ(to_string(RemoteSwitch::kUndefined), "undefined");
  EXPECT_EQ(to_string(LightMode::kOff), "off");
  EXPECT_EQ(to_string(LightMode::kOn), "on");
  EXPECT_EQ(to_string(LightMode::kBreathing), "breathing");
  EXPECT_EQ(to_string(LightMode::kCustom), "custom");
  EXPECT_EQ(to_string(static_cast<LightMode>(4)), "unknown");
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

// ---- Motion-mode numbering --------------------------------------------------------------------

TEST(ProtocolMotionModes, EachNumberingMapsItsWireValues) {
  using M = MotionMode;
  const std::vector<M> manual = {M::kAckermann, M::kOblique, M::kSpin};
  const std::vector<M> agx = {M::kAckermann, M::kOblique, M::kSpin, M::kPark, M::kSideSlip};
  const std::vector<M> mini = {M::kAckermann, M::kOblique, M::kSpin, M::kSideSlip};
  EXPECT_EQ(motion_modes(ModeNumbering::kManual), manual);
  EXPECT_EQ(motion_modes(ModeNumbering::kAgxV2), agx);
  EXPECT_EQ(motion_modes(ModeNumbering::kMiniV1), mini);
  for (const auto numbering :
       {ModeNumbering::kManual, ModeNumbering::kAgxV2, ModeNumbering::kMiniV1}) {
    const auto modes = motion_modes(numbering);
    for (int raw = 0; raw < 256; ++raw) {
      const auto mode = motion_mode_from_wire(static_cast<std::uint8_t>(raw), numbering);
      ASSERT_EQ(mode.has_value(), raw < static_cast<int>(modes.size())) << raw;
      if (mode) EXPECT_EQ(*motion_mode_to_wire(*mode, numbering), raw);
    }
  }
  // The enum's values are agx_v2's numbering.
  EXPECT_EQ(*motion_mode_to_wire(M::kPark, ModeNumbering::kAgxV2), 3);
  EXPECT_EQ(*motion_mode_to_wire(M::kSideSlip, ModeNumbering::kAgxV2), 4);
  // MINI V1: side slip is 3, there is no park.
  EXPECT_EQ(*motion_mode_to_wire(M::kSideSlip, ModeNumbering::kMiniV1), 3);
  EXPECT_EQ(*motion_mode_from_wire(3, ModeNumbering::kMiniV1), M::kSideSlip);
  EXPECT_FALSE(motion_mode_to_wire(M::kPark, ModeNumbering::kMiniV1).has_value());
  // The manual knows 0-2 only.
  EXPECT_FALSE(motion_mode_to_wire(M::kPark, ModeNumbering::kManual).has_value());
  EXPECT_FALSE(motion_mode_from_wire(3, ModeNumbering::kManual).has_value());
}

// ---- The frame table
// ------------------------------------------------------------------------------

TEST(ProtocolFrames, EveryIdentifierHasOneRowAndTheRowsAgreeWithTheLists) {
  for (std::uint32_t id = 0; id < 0x800; ++id) {
    int rows = 0;
    for (const FrameInfo& f : kFrameTable)
      rows += f.holds(id) ? 1 : 0;
    EXPECT_LE(rows, 1) << std::hex << id;
    EXPECT_EQ(rows == 1, is_known_id(id)) << std::hex << id;
  }
  for (const FrameInfo& f : kFrameTable) {
    EXPECT_GT(f.length, 0) << f.name;
    EXPECT_LE(f.length, 8) << f.name;
    EXPECT_NE(f.revisions & kInAgxV2, 0) << f.name << ": the vendor's revision has every frame";
    EXPECT_TRUE(f.period_ms == 0 || f.direction != Direction::kBoth) << f.name;
  }
  // Periods: the manual's feedback rates, 0x231/0x241 at the fast rate, the host's keep-alive.
  EXPECT_EQ(frame_period_ms(kSystemStatusId), 20);
  EXPECT_EQ(frame_period_ms(kUltrasonic5to8Id), 50);
  EXPECT_EQ(frame_period_ms(kMotorLowSpeedBaseId + 8), 100);
  EXPECT_EQ(frame_period_ms(kBmsBaseId + 9), 500);
  EXPECT_EQ(frame_period_ms(kRemoteControlStateId), 20);
  EXPECT_EQ(kKeepAlivePeriodMs, 20);
  EXPECT_EQ(frame_period_ms(0x7FF), 0);
  // Chassis frames: feedback and 0x4A1 answers, never the host's commands or its request.
  CanFrame f;
  f.id = kVersionId;
  f.dlc = 1;
  f.data[0] = kVersionRequestValue;
  EXPECT_FALSE(is_chassis_frame(f));
  f.data[0] = 'V';
  EXPECT_TRUE(is_chassis_frame(f));
  f.id = kMotionCommandId;
  EXPECT_FALSE(is_chassis_frame(f));
  f.id = kOdometerId;
  EXPECT_TRUE(is_chassis_frame(f));
}

// ---- The agx_v2 16-bit error word --------------------------------------------------------------

// The vendor's bits (PROTOCOL_AGX_V2.md) carry the name of their meaning, the manual layout's name
// where the manual has the same fault.
TEST(ProtocolErrorBits, Agx16BitsByName) {
  const std::pair<std::uint32_t, const char*> rows[] = {
      {0x0001, "battery_under_voltage"},               // battery fault
      {0x0002, "battery_warning"},                     // battery warning
      {0x0004, "remote_control_lost"},                 // remote-control signal lost
      {0x0008, "motor_driver_1_communication_fault"},  // motor 1 communication
      {0x0010, "motor_driver_2_communication_fault"},
      {0x0020, "motor_driver_3_communication_fault"},
      {0x0040, "motor_driver_4_communication_fault"},
      {0x0080, "steering_encoder_fault"},  // steering encoder
      {0x0100, "driver_status_error"},     // motor driver fault
      {0x0200, "host_communication_lost"},
  };
  const auto& table = system_error_bits(ErrorWordLayout::kAgxV2_16);
  ASSERT_EQ(table.size(), std::size(rows));
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(1u << table[i].index, rows[i].first);
    EXPECT_EQ(table[i].name, rows[i].second);
    EXPECT_EQ(error_bit_names(rows[i].first, ErrorWordLayout::kAgxV2_16), Names{rows[i].second});
  }
  EXPECT_EQ(error_bit_names(0x8000, ErrorWordLayout::kAgxV2_16), Names{"reserved_bit_15"});
  // Only the word's 16 bits are named: higher bits cannot come from the wire.
  EXPECT_EQ(error_bit_names(0xFFFFFFFFu, ErrorWordLayout::kAgxV2_16).size(), 16u);
  EXPECT_EQ(error_word_bits(ErrorWordLayout::kAgxV2_16), 16);
  EXPECT_EQ(error_word_bits(ErrorWordLayout::kManual32), 32);
  EXPECT_EQ(&system_error_bits(ErrorWordLayout::kManual32), &system_error_bits());
}

TEST(ProtocolErrorBits, CriticalPerLayout) {
  constexpr auto kAgx = ErrorWordLayout::kAgxV2_16;
  for (std::uint32_t bit : {0x0001u, 0x0008u, 0x0040u, 0x0080u, 0x0100u})
    EXPECT_TRUE(is_critical_error(bit, kAgx)) << bit;
  for (std::uint32_t bit : {0x0002u, 0x0004u, 0x0200u, 0x8000u})
    EXPECT_FALSE(is_critical_error(bit, kAgx)) << bit;
  for (int i = 0; i < 32; ++i) {
    EXPECT_EQ(is_critical_error(1u << i), is_critical_error(1u << i, ErrorWordLayout::kManual32));
  }
}

// ---- Faults by meaning -------------------------------------------------------------------------

TEST(ProtocolFaults, ManualBitsAtTheManualsPositions) {
  constexpr auto kManual = ErrorWordLayout::kManual32;
  auto bit = [](int byte, int b) { return 1u << error_bit_index(byte, b); };
  EXPECT_EQ(fault_bit(Fault::kBatteryUnderVoltage, kManual), bit(7, 0));
  EXPECT_EQ(fault_bit(Fault::kUltrasonicTriggered, kManual), bit(7, 1));
  EXPECT_EQ(fault_bit(Fault::kRemoteSignalLost, kManual), bit(7, 2));
  EXPECT_EQ(fault_bit(Fault::kDriverStatusError, kManual), bit(6, 0));
  EXPECT_EQ(fault_bit(Fault::kHostCommunicationLost, kManual), bit(6, 1));
  EXPECT_EQ(fault_bit(Fault::kOverTemperature, kManual), bit(6, 6));
  EXPECT_EQ(fault_bit(Fault::kOverCurrent, kManual), bit(6, 7));
  EXPECT_EQ(fault_bit(Fault::kSteeringCalibrationTimeout, kManual), bit(5, 4));
  EXPECT_EQ(fault_bit(Fault::kSafetyEdge, kManual), bit(5, 5));
  for (int n = 1; n <= 4; ++n)
    EXPECT_EQ(fault_bit(Fault::kMotorCommunication, kManual, n), bit(7, 2 + n));
  for (int n = 5; n <= 8; ++n) {
    EXPECT_EQ(fault_bit(Fault::kMotorCommunication, kManual, n), bit(6, n - 3));
    EXPECT_EQ(fault_bit(Fault::kSteeringCalibration, kManual, n), bit(5, n - 5));
    EXPECT_EQ(fault_bit(Fault::kSteeringServoWarning, kManual, n), bit(4, n - 5));
  }
  // Out-of-range motors and faults the layout lacks: 0.
  for (int n : {0, 9, -1})
    EXPECT_EQ(fault_bit(Fault::kMotorCommunication, kManual, n), 0u) << n;
  EXPECT_EQ(fault_bit(Fault::kSteeringCalibration, kManual, 4), 0u);
  EXPECT_EQ(fault_bit(Fault::kBatteryWarning, kManual), 0u);
  EXPECT_EQ(fault_bit(Fault::kSteeringEncoder, kManual), 0u);
}

TEST(ProtocolFaults, Agx16Bits) {
  constexpr auto kAgx = ErrorWordLayout::kAgxV2_16;
  EXPECT_EQ(fault_bit(Fault::kBatteryUnderVoltage, kAgx), 0x0001u);
  EXPECT_EQ(fault_bit(Fault::kBatteryWarning, kAgx), 0x0002u);
  EXPECT_EQ(fault_bit(Fault::kRemoteSignalLost, kAgx), 0x0004u);
  for (int n = 1; n <= 4; ++n)
    EXPECT_EQ(fault_bit(Fault::kMotorCommunication, kAgx, n), 0x0008u << (n - 1));
  for (int n = 5; n <= 8; ++n)
    EXPECT_EQ(fault_bit(Fault::kMotorCommunication, kAgx, n), 0u) << "no steering motors";
  EXPECT_EQ(fault_bit(Fault::kSteeringEncoder, kAgx), 0x0080u);
  EXPECT_EQ(fault_bit(Fault::kDriverStatusError, kAgx), 0x0100u);
  EXPECT_EQ(fault_bit(Fault::kHostCommunicationLost, kAgx), 0x0200u);
  for (Fault f : {Fault::kUltrasonicTriggered, Fault::kOverTemperature, Fault::kOverCurrent,
                  Fault::kSteeringCalibrationTimeout, Fault::kSafetyEdge}) {
    EXPECT_EQ(fault_bit(f, kAgx), 0u) << to_string(f);
  }
}

TEST(ProtocolFaults, EveryFaultHasANameAndEveryBitIsNamedInItsLayout) {
  std::set<std::string> names;
  for (int i = 0; i < kFaultCount; ++i) {
    const auto f = static_cast<Fault>(i);
    EXPECT_NE(to_string(f), "unknown");
    EXPECT_TRUE(names.insert(std::string(to_string(f))).second);
    for (const auto layout : {ErrorWordLayout::kManual32, ErrorWordLayout::kAgxV2_16}) {
      for (int motor = 0; motor <= 8; ++motor) {
        const std::uint32_t b = fault_bit(f, layout, motor);
        if (b == 0) continue;
        EXPECT_EQ(b & (b - 1), 0u) << "one bit";
        const auto bit_names = error_bit_names(b, layout);
        ASSERT_EQ(bit_names.size(), 1u);
        EXPECT_EQ(bit_names[0].rfind("reserved", 0), std::string::npos) << bit_names[0];
      }
    }
  }
  EXPECT_EQ(to_string(static_cast<Fault>(kFaultCount)), "unknown");
}

TEST(ProtocolFaults, TheTableHasOneRowPerMeaningAndOneBitPerRowAndLayout) {
  std::set<std::string_view> names;
  for (const FaultInfo& f : kFaultTable) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(f.manual_bit != kNoBit || f.agx16_bit != kNoBit) << f.name;
    EXPECT_EQ(find_fault(f.name), &f);
    EXPECT_EQ(find_fault(f.fault, f.motor), &f) << f.name;
    for (const auto layout : {ErrorWordLayout::kManual32, ErrorWordLayout::kAgxV2_16}) {
      if (f.bit(layout) == kNoBit) continue;
      EXPECT_LT(f.bit(layout), error_word_bits(layout)) << f.name;
      EXPECT_EQ(fault_at(layout, f.bit(layout)), &f) << f.name << ": two rows on one bit";
      EXPECT_EQ(is_critical_error(1u << f.bit(layout), layout), f.critical) << f.name;
    }
  }
  // Every fault of the enum has a row.
  for (const Fault f : kFaultNames.values()) {
    bool found = false;
    for (const FaultInfo& row : kFaultTable)
      found = found || row.fault == f;
    EXPECT_TRUE(found) << to_string(f);
  }
}

TEST(ProtocolFaults, TheCriticalSetIsMadeOfFaults) {
  // The manual's mask is the one is_critical_error always used.
  std::uint32_t manual = 0;
  for (const auto& [byte, bits] : std::vector<std::pair<int, std::vector<int>>>{
           {7, {0, 3, 4, 5, 6}}, {6, {0, 2, 3, 4, 5, 6, 7}}, {5, {0, 1, 2, 3, 4, 5}}}) {
    for (int b : bits)
      manual |= 1u << error_bit_index(byte, b);
  }
  EXPECT_EQ(interpretation::critical_error_mask(ErrorWordLayout::kManual32), manual);
  EXPECT_EQ(interpretation::critical_error_mask(ErrorWordLayout::kAgxV2_16), 0x01F9u);
}

// ---- Named driver status and BMS bits ----------------------------------------------------------

TEST(ProtocolNamedBits, ConstantsMatchTheTables) {
  const std::uint8_t driver[] = {
      driver_status::kSupplyVoltageLow,  driver_status::kMotorOverTemperature,
      driver_status::kDriverOverCurrent, driver_status::kDriverOverTemperature,
      driver_status::kSensorAbnormal,    driver_status::kDriverError,
      driver_status::kDriverDisabled};
  for (std::size_t i = 0; i < std::size(driver); ++i)
    EXPECT_EQ(driver[i], 1u << driver_status_bits()[i].index);
  EXPECT_EQ(driver_status_names(driver_status::kDriverDisabled), Names{"driver_disabled"});
  EXPECT_EQ(bms_status_names(bms_status::kOverVoltage, 0), Names{"over_voltage"});
  EXPECT_EQ(bms_status_names(bms_status::kUnderVoltage, 0), Names{"under_voltage"});
  EXPECT_EQ(bms_status_names(bms_status::kHighTemperature, 0), Names{"high_temperature"});
  EXPECT_EQ(bms_status_names(bms_status::kLowTemperature, 0), Names{"low_temperature"});
  EXPECT_EQ(bms_status_names(bms_status::kDischargeOverCurrent, 0),
            Names{"discharge_over_current"});
  EXPECT_EQ(bms_status_names(0, bms_status::kChargeOverCurrent), Names{"charge_over_current"});
}

}  // namespace
}  // namespace ranger::protocol
