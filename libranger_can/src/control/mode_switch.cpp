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
    case ModeSwitchPhase::kAwaitingWheels:
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
    sent_ = first_ = now;
    return status_.target;
  }
  return std::nullopt;
}

void ModeSwitchSequencer::on_feedback(protocol::MotionMode mode, bool switching) {
  if (status_.phase != ModeSwitchPhase::kAwaitingConfirmation &&
      status_.phase != ModeSwitchPhase::kAwaitingWheels) {
    return;
  }
  const bool confirmed = !switching && status_.target && *status_.target == mode;
  status_.phase =
      confirmed ? ModeSwitchPhase::kAwaitingWheels : ModeSwitchPhase::kAwaitingConfirmation;
}

bool ModeSwitchSequencer::settle(std::optional<bool> wheels_at_target, Timestamp now) {
  if (status_.phase != ModeSwitchPhase::kAwaitingWheels) return false;
  // The wheels seen there, or the chassis's own switch time over (with or without 0x271: wheels
  // that settle a little off their nominal angles do not hold a switch forever).
  const bool there = (wheels_at_target && *wheels_at_target && now - first_ >= config_.min_time) ||
                     now - first_ >= config_.blind_time;
  if (!there) return false;
  status_ = ModeSwitchStatus{};
  return true;
}

void ModeSwitchSequencer::cancel() {
  status_ = ModeSwitchStatus{};
}

Timestamp ModeSwitchSequencer::next_due() const {
  switch (status_.phase) {
    case ModeSwitchPhase::kAwaitingConfirmation:
      return sent_ + config_.timeout;
    case ModeSwitchPhase::kAwaitingWheels:
      return std::min(sent_ + config_.timeout, first_ + config_.blind_time);
    default:
      return Timestamp::max();
  }
}

}  // namespace ranger
