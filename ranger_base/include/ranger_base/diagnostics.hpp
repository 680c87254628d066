// /diagnostics for the chassis, through diagnostic_updater: one status per concern (CAN link,
// control mode, protocol settings, errors, battery, frame rates), each computed from a
// ranger::DriverSnapshot so the same rules are unit-tested without ROS plumbing. ranger_bringup's
// aggregator config groups them.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <diagnostic_updater/diagnostic_updater.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <ranger_can/control/driver.hpp>

namespace ranger_base {

// Status names as they appear in /diagnostics (prefixed by the node name by the updater).
inline constexpr const char* kDiagLink = "CAN link";
inline constexpr const char* kDiagControl = "Control mode";
inline constexpr const char* kDiagProtocol = "Protocol";
inline constexpr const char* kDiagErrors = "Chassis errors";
inline constexpr const char* kDiagBattery = "Battery";
inline constexpr const char* kDiagFrameRates = "Frame rates";

using diagnostic_updater::DiagnosticStatusWrapper;
using ranger::DriverSnapshot;

void diagnose_link(const DriverSnapshot& s, DiagnosticStatusWrapper& out);
void diagnose_control(const DriverSnapshot& s, DiagnosticStatusWrapper& out);
void diagnose_errors(const DriverSnapshot& s, DiagnosticStatusWrapper& out);

// What the snapshot does not say about the protocol settings: where they came from (the
// parameters), and the bus, for the commissioning command.
struct ProtocolContext {
  std::string source;     // NodeParameters::protocol.source
  std::string port_name;  // "can0": the commissioning command names it (a CAN interface only)
};
// The settings in use and where they came from; with `protocol: auto` the identification (phase,
// decision with its evidence, the settings left undecided); the plausibility monitors (every
// warning with the value to try, and the stop). ERROR while the identification failed (its
// message names what to set and the commissioning command) or a plausibility stop holds; WARN
// while a monitor warns.
void diagnose_protocol(const DriverSnapshot& s, const ProtocolContext& context,
                       DiagnosticStatusWrapper& out);
void diagnose_battery(const DriverSnapshot& s, DiagnosticStatusWrapper& out);

// Received frames per ID: the snapshot's rates (FrameStats, over its window), the rejected and
// padded counts; WARN while frames are being rejected (since the previous call).
class FrameRateMonitor {
 public:
  void diagnose(const DriverSnapshot& s, DiagnosticStatusWrapper& out);

 private:
  std::map<std::uint32_t, std::uint64_t> previous_rejected_;
};

// Registers the tasks on `updater`. Call refresh() before each updater.update(): every task of a
// round reports from the same snapshot.
class ChassisDiagnostics {
 public:
  using SnapshotSource = std::function<std::shared_ptr<const DriverSnapshot>()>;
  ChassisDiagnostics(diagnostic_updater::Updater& updater, SnapshotSource source,
                     ProtocolContext protocol = {});
  void refresh();

 private:
  SnapshotSource source_;
  ProtocolContext protocol_;
  FrameRateMonitor rates_;
  std::shared_ptr<const DriverSnapshot> current_;
};

}  // namespace ranger_base
