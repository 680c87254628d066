// /diagnostics for the chassis, through diagnostic_updater: one status per concern (CAN link,
// control mode, errors, battery, frame rates), each computed from a LinkSnapshot so the same
// rules are unit-tested without ROS plumbing. ranger_bringup's aggregator config groups them.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <diagnostic_updater/diagnostic_updater.h>

#include <cstdint>
#include <map>
#include <optional>

#include "ranger_base/chassis_link.hpp"

namespace ranger_base {

// Status names as they appear in /diagnostics (prefixed by the node name by the updater).
inline constexpr const char* kDiagLink = "CAN link";
inline constexpr const char* kDiagControl = "Control mode";
inline constexpr const char* kDiagErrors = "Chassis errors";
inline constexpr const char* kDiagBattery = "Battery";
inline constexpr const char* kDiagFrameRates = "Frame rates";

void diagnose_link(const LinkSnapshot& s, diagnostic_updater::DiagnosticStatusWrapper& out);
void diagnose_control(const LinkSnapshot& s, diagnostic_updater::DiagnosticStatusWrapper& out);
void diagnose_errors(const LinkSnapshot& s, diagnostic_updater::DiagnosticStatusWrapper& out);
void diagnose_battery(const LinkSnapshot& s, diagnostic_updater::DiagnosticStatusWrapper& out);

// Frame rates per ID since the previous call (the first call only records the counts).
class FrameRateMonitor {
 public:
  void diagnose(const LinkSnapshot& s, diagnostic_updater::DiagnosticStatusWrapper& out);

 private:
  std::optional<ranger::Timestamp> previous_time_;
  std::map<std::uint32_t, std::uint64_t> previous_counts_;
};

// Registers the tasks on `updater`. Call refresh() before each updater.update(): every task of a
// round reports from the same snapshot.
class ChassisDiagnostics {
 public:
  ChassisDiagnostics(diagnostic_updater::Updater& updater, const ChassisLink& link);
  void refresh();

 private:
  const ChassisLink& link_;
  FrameRateMonitor rates_;
  LinkSnapshot current_;
};

}  // namespace ranger_base
