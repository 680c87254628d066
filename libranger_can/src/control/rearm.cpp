#include "ranger_can/control/rearm.hpp"

namespace ranger {

std::string describe(StopCauses causes) {
  std::string out;
  for (const auto& [cause, name] : kStopCauseNames) {
    if (!has(causes, cause)) continue;
    if (!out.empty()) out += ',';
    out += name;
  }
  return out;
}

void RearmLatch::update(StopCauses active) {
  latched_ |= active;
}

bool RearmLatch::on_zero_command(StopCauses active) {
  update(active);
  if (active != 0 || latched_ == 0) return false;
  latched_ = 0;
  return true;
}

Status RearmLatch::resume(StopCauses active) {
  update(active);
  if (active != 0) {
    return Error{Errc::kInvalidArgument, "resume refused: still active: " + describe(active)};
  }
  latched_ = 0;
  return ok_status();
}

}  // namespace ranger
