// /diagnostics: the library's diagnostic groups (ranger_can/control/diagnostics.hpp: one per
// concern, computed from a ranger::DriverSnapshot) mapped one to one onto diagnostic_updater's
// tasks, with the hardware_id "ranger:<namespace>:<port_name>". ranger_bringup's aggregator
// config groups them.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <diagnostic_updater/diagnostic_updater.h>

#include <functional>
#include <memory>

#include <ranger_can/control/diagnostics.hpp>

namespace ranger_base {

// A group as a status: its level, message and key/values (the updater names it).
void to_status(const ranger::DiagnosticGroup& group,
               diagnostic_updater::DiagnosticStatusWrapper& out);

// Registers one task per group on `updater` and sets its hardware id. Call refresh() before each
// updater.update(): every task of a round reports from the same snapshot.
class ChassisDiagnostics {
 public:
  using SnapshotSource = std::function<std::shared_ptr<const ranger::DriverSnapshot>()>;
  ChassisDiagnostics(diagnostic_updater::Updater& updater, SnapshotSource source,
                     ranger::DiagnosticContext context);
  void refresh();

 private:
  SnapshotSource source_;
  ranger::ChassisDiagnostics groups_;
  std::shared_ptr<const ranger::DriverSnapshot> current_;
};

}  // namespace ranger_base
