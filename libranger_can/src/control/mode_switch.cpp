#include "ranger_can/control/mode_switch.hpp"

#include <algorithm>

namespace ranger {

std::optional<protocol::MotionMode> ModeSwitchSequencer::update(protocol::MotionMode wanted,
                                                                protocol::MotionMode current,
                                                                bool at_standstill, Timestamp now) {
  switch (status_.phase) {
    case ModeSwitchPhase::kIdle:
      if (wanted == current) return std::nullopt;
      status_.phase = ModeSwitchPhase::kStopping;
      status_.target = wanted;
      status_.attempts = 0;
      break;
    case ModeSwitchPhase::kStopping:
      if (wanted == current) {
        cancel();
        return std::nullopt;
      }
      status_.target = wanted;
      break;
    case ModeSwitchPhase::kAwaitingConfirmation:
      if (now - sent_ < config_.timeout) return std::nullopt;
      // Reported as failed once the attempts are used up; retried at the same bounded rate all the
      // same (the chassis stands still meanwhile), so a chassis that recovers completes it.
      if (status_.attempts >= config_.max_attempts) status_.failed = true;
      ++status_.attempts;
      sent_ = now;
      return status_.target;
  }
  if (status_.phase == ModeSwitchPhase::kStopping && at_standstill) {
    status_.phase = ModeSwitchPhase::kAwaitingConfirmation;
    status_.attempts = 1;
    sent_ = now;
    return status_.target;
  }
  return std::nullopt;
}

bool ModeSwitchSequencer::on_feedback(protocol::MotionMode mode, bool switching) {
  if (switching || !status_.target || *status_.target != mode) return false;
  if (status_.phase != ModeSwitchPhase::kAwaitingConfirmation) return false;
  status_ = ModeSwitchStatus{};
  return true;
}

void ModeSwitchSequencer::cancel() {
  status_ = ModeSwitchStatus{};
}

Timestamp ModeSwitchSequencer::next_due() const {
  if (status_.phase != ModeSwitchPhase::kAwaitingConfirmation) return Timestamp::max();
  return sent_ + config_.timeout;
}

}  // namespace ranger
