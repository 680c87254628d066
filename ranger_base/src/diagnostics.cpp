#include "ranger_base/diagnostics.hpp"

#include <string>

namespace ranger_base {

void to_status(const ranger::DiagnosticGroup& group,
               diagnostic_updater::DiagnosticStatusWrapper& out) {
  out.summary(static_cast<unsigned char>(group.level), group.message);
  for (const auto& [key, value] : group.values)
    out.add(key, value);
}

ChassisDiagnostics::ChassisDiagnostics(diagnostic_updater::Updater& updater, SnapshotSource source,
                                       ranger::DiagnosticContext context)
    : source_(std::move(source)),
      groups_(std::move(context)),
      current_(std::make_shared<ranger::DriverSnapshot>()) {
  const ranger::DiagnosticContext& c = groups_.context();
  updater.setHardwareID(ranger::hardware_id(c.ns, c.port_name));
  for (std::size_t i = 0; i < ranger::kDiagnosticGroups.size(); ++i) {
    updater.add(std::string(ranger::kDiagnosticGroups[i]),
                [this, i](diagnostic_updater::DiagnosticStatusWrapper& out) {
                  to_status(groups_.group(i, *current_), out);
                });
  }
}

void ChassisDiagnostics::refresh() {
  current_ = source_();
}

}  // namespace ranger_base
