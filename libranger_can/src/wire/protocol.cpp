// The protocol's vocabulary as data: identifiers, DLCs, names of every defined bit.
#include "ranger_can/wire/protocol.hpp"

#include "ranger_can/wire/interpretation.hpp"

#include <algorithm>
#include <initializer_list>
#include <iterator>
#include <string>

namespace ranger::protocol {

namespace {

std::vector<std::uint32_t> ids_of(std::uint8_t revisions) {
  std::vector<std::uint32_t> ids;
  for (const FrameInfo& f : kFrameTable) {
    if ((f.revisions & revisions) == 0) continue;
    for (int i = 0; i < f.count; ++i)
      ids.push_back(f.id + static_cast<std::uint32_t>(i * f.stride));
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace

std::vector<std::uint32_t> manual_ids() {
  return ids_of(kInManual);
}

std::vector<std::uint32_t> all_ids() {
  return ids_of(kInManual | kInAgxV2);
}

bool is_known_id(std::uint32_t id) {
  return find_frame(id) != nullptr;
}

int layout_dlc(std::uint32_t id) {
  const FrameInfo* f = find_frame(id);
  return f != nullptr ? f->length : -1;
}

bool is_version_request(const CanFrame& f) {
  if (f.dlc < 1 || f.data[0] != kVersionRequestValue) return false;
  const std::size_t n = std::min<std::size_t>(f.dlc, CanFrame::kMaxDlc);
  for (std::size_t i = 1; i < n; ++i) {
    if (f.data[i] != 0) return false;
  }
  return true;
}

bool is_chassis_frame(const CanFrame& frame) {
  const FrameInfo* f = find_frame(frame.id);
  if (f == nullptr || frame.is_error) return false;
  return f->direction == Direction::kFromChassis ||
         (f->direction == Direction::kBoth && !is_version_request(frame));
}

int extra_bytes(const CanFrame& frame) {
  if (frame.is_error) return 0;
  const int layout = layout_dlc(frame.id);
  if (layout < 0) return 0;
  if (frame.id == kVersionId && !is_version_request(frame)) return 0;  // an answer: all text
  const int dlc = std::min<int>(frame.dlc, static_cast<int>(CanFrame::kMaxDlc));
  return dlc > layout ? dlc - layout : 0;
}

std::string_view frame_name(std::uint32_t id) {
  const FrameInfo* f = find_frame(id);
  return f != nullptr ? f->name : "unknown";
}

// ---- Motion modes -------------------------------------------------------------------------------

namespace {

// Each numbering's modes in wire order (index = wire value). Plain arrays: the codec maps modes on
// every 0x141 and 0x291 without allocating.
constexpr MotionMode kManualModes[] = {MotionMode::kAckermann, MotionMode::kOblique,
                                       MotionMode::kSpin};
constexpr MotionMode kAgxV2Modes[] = {MotionMode::kAckermann, MotionMode::kOblique,
                                      MotionMode::kSpin, MotionMode::kPark, MotionMode::kSideSlip};
constexpr MotionMode kMiniV1Modes[] = {MotionMode::kAckermann, MotionMode::kOblique,
                                       MotionMode::kSpin, MotionMode::kSideSlip};

struct ModeTable {
  const MotionMode* modes;
  std::size_t count;
};

ModeTable mode_table(ModeNumbering numbering) {
  switch (numbering) {
    case ModeNumbering::kManual:
      return {kManualModes, std::size(kManualModes)};
    case ModeNumbering::kAgxV2:
      return {kAgxV2Modes, std::size(kAgxV2Modes)};
    case ModeNumbering::kMiniV1:
      return {kMiniV1Modes, std::size(kMiniV1Modes)};
  }
  return {nullptr, 0};
}

}  // namespace

std::vector<MotionMode> motion_modes(ModeNumbering numbering) {
  const ModeTable t = mode_table(numbering);
  return std::vector<MotionMode>(t.modes, t.modes + t.count);
}

std::optional<MotionMode> motion_mode_from_wire(std::uint8_t raw, ModeNumbering numbering) {
  const ModeTable t = mode_table(numbering);
  if (raw < t.count) return t.modes[raw];
  return std::nullopt;
}

std::optional<std::uint8_t> motion_mode_to_wire(MotionMode mode, ModeNumbering numbering) {
  const ModeTable t = mode_table(numbering);
  for (std::size_t i = 0; i < t.count; ++i) {
    if (t.modes[i] == mode) return static_cast<std::uint8_t>(i);
  }
  return std::nullopt;
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

int error_word_bits(ErrorWordLayout layout) {
  return layout == ErrorWordLayout::kAgxV2_16 ? 16 : 32;
}

namespace {

// A layout's rows of the fault table as named bits, in ascending bit order.
std::vector<NamedBit> layout_bits(ErrorWordLayout layout) {
  std::vector<NamedBit> bits;
  for (const FaultInfo& f : kFaultTable) {
    if (f.bit(layout) != kNoBit) bits.push_back({f.bit(layout), f.name, f.description});
  }
  std::sort(bits.begin(), bits.end(),
            [](const NamedBit& x, const NamedBit& y) { return x.index < y.index; });
  return bits;
}

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

}  // namespace

const std::vector<NamedBit>& system_error_bits(ErrorWordLayout layout) {
  static const std::vector<NamedBit> manual = layout_bits(ErrorWordLayout::kManual32);
  static const std::vector<NamedBit> agx16 = layout_bits(ErrorWordLayout::kAgxV2_16);
  return layout == ErrorWordLayout::kAgxV2_16 ? agx16 : manual;
}

const std::vector<NamedBit>& system_error_bits() {
  return system_error_bits(ErrorWordLayout::kManual32);
}

std::vector<std::string> error_bit_names(std::uint32_t error_word, ErrorWordLayout layout) {
  return names_of_set_bits(error_word, error_word_bits(layout), system_error_bits(layout));
}

std::vector<std::string> error_bit_names(std::uint32_t error_word) {
  return error_bit_names(error_word, ErrorWordLayout::kManual32);
}

bool is_critical_error(std::uint32_t error_word, ErrorWordLayout layout) {
  return (error_word & interpretation::critical_error_mask(layout)) != 0;
}

bool is_critical_error(std::uint32_t error_word) {
  return is_critical_error(error_word, ErrorWordLayout::kManual32);
}

const FaultInfo* find_fault(Fault fault, int motor) {
  for (const FaultInfo& f : kFaultTable) {
    if (f.fault == fault && (f.motor == 0 || f.motor == motor)) return &f;
  }
  return nullptr;
}

const FaultInfo* find_fault(std::string_view name) {
  for (const FaultInfo& f : kFaultTable) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

const FaultInfo* fault_at(ErrorWordLayout layout, int index) {
  for (const FaultInfo& f : kFaultTable) {
    if (index != kNoBit && f.bit(layout) == index) return &f;
  }
  return nullptr;
}

std::uint32_t fault_bit(Fault fault, ErrorWordLayout layout, int motor) {
  const FaultInfo* f = find_fault(fault, motor);
  return f != nullptr && f->bit(layout) != kNoBit ? 1u << f->bit(layout) : 0u;
}

// ---- 0x261-0x268 driver status bits -----------------------------------------------------------

namespace {
// The bit number of a one-bit mask.
constexpr int bit_of(std::uint8_t mask) {
  int i = 0;
  while (mask > 1) {
    mask = static_cast<std::uint8_t>(mask >> 1);
    ++i;
  }
  return i;
}
}  // namespace

const std::vector<NamedBit>& driver_status_bits() {
  namespace ds = driver_status;
  static const std::vector<NamedBit> bits = {
      {bit_of(ds::kSupplyVoltageLow), "supply_voltage_low", "power supply voltage too low"},
      {bit_of(ds::kMotorOverTemperature), "motor_over_temperature", "motor over-temperature"},
      {bit_of(ds::kDriverOverCurrent), "driver_over_current", "driver over-current"},
      {bit_of(ds::kDriverOverTemperature), "driver_over_temperature", "driver over-temperature"},
      {bit_of(ds::kSensorAbnormal), "sensor_abnormal", "sensor status abnormal"},
      {bit_of(ds::kDriverError), "driver_error", "driver error"},
      {bit_of(ds::kDriverDisabled), "driver_disabled", "driver disabled (0 = enabled)"},
  };
  return bits;
}

std::vector<std::string> driver_status_names(std::uint8_t status) {
  return names_of_set_bits(status, 8, driver_status_bits());
}

// ---- BMS alarm / warning bits -----------------------------------------------------------------

const std::vector<NamedBit>& bms_status1_bits() {
  static const std::vector<NamedBit> bits = {
      {bit_of(bms_status::kOverVoltage), "over_voltage", "over-voltage"},
      {bit_of(bms_status::kUnderVoltage), "under_voltage", "under-voltage"},
      {bit_of(bms_status::kHighTemperature), "high_temperature", "high temperature"},
      {bit_of(bms_status::kLowTemperature), "low_temperature", "low temperature"},
      {bit_of(bms_status::kDischargeOverCurrent), "discharge_over_current",
       "discharge over-current"},
  };
  return bits;
}

const std::vector<NamedBit>& bms_status2_bits() {
  static const std::vector<NamedBit> bits = {
      {bit_of(bms_status::kChargeOverCurrent), "charge_over_current", "charging over-current"},
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
  if (raw == interpretation::kUltrasonicNoReading) return "no_reading";
  if (raw > 0) return "ok";
  const auto code = static_cast<UltrasonicCode>(raw);
  return kUltrasonicCodeNames.contains(code) ? kUltrasonicCodeNames.name(code) : "unknown_code";
}

}  // namespace ranger::protocol
