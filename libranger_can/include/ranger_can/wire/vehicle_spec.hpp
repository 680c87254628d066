// Vehicle facts from the RANGER manual that are neither protocol nor geometry: the battery pack.
// One place for them, read by the virtual chassis's battery model and (through the control layer,
// since the node includes nothing from wire/) by the node's battery diagnostics.
#pragma once

#include <string_view>

namespace ranger::vehicle_spec {

// Manual 1.1: 48 V batteries, 24 Ah each, up to four; battery type 铁锂电池 (lithium iron
// phosphate; the English column says only "lithium-ion"). Manual 3.1 (charging) and 2.2 (the
// expansion connector's supply): normal voltage range 46-50 V.
inline constexpr std::string_view kBatteryChemistry = "LiFePO4";
inline constexpr double kBatteryNominalVoltage = 48.0;    // V
inline constexpr double kBatteryNormalMinVoltage = 46.0;  // V, lower end of the normal range
inline constexpr double kBatteryNormalMaxVoltage = 50.0;  // V, upper end of the normal range
inline constexpr double kBatteryCapacityAh = 24.0;        // per battery
inline constexpr int kMaxBatteries = 4;
// Manual 2.1 (table 2.1, low-voltage warning): under 15 % SOC the lights flash; under 10 % the
// drivers lose power.
inline constexpr double kLowBatteryWarningSoc = 15.0;  // %
inline constexpr double kLowBatteryCutoffSoc = 10.0;   // %

}  // namespace ranger::vehicle_spec
