#include "ranger_can/control/rearm.hpp"

namespace ranger {

namespace {
constexpr StopCause kAllCauses[] = {StopCause::kLinkLost,   StopCause::kRemote,
                                    StopCause::kEstop,      StopCause::kCriticalError,
                                    StopCause::kLowBattery, StopCause::kModeSwitchFailed,
                                    StopCause::kImplausible};
}  // namespace

std::string_view to_string(StopCause c) {
  switch (c) {
    case StopCause::kLinkLost:
      return "link_lost";
    case StopCause::kRemote:
      return "remote";
    case StopCause::kEstop:
      return "emergency_stop";
    case StopCause::kCriticalError:
      return "critical_error";
    case StopCause::kLowBattery:
      return "low_battery";
    case StopCause::kModeSwitchFailed:
      return "motion_mode_switch_failed";
    case StopCause::kImplausible:
      return "implausible_feedback";
  }
  return "unknown";
}

std::string describe(StopCauses causes) {
  std::string out;
  for (StopCause c : kAllCauses) {
    if (!has(causes, c)) continue;
    if (!out.empty()) out += ',';
    out += to_string(c);
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
