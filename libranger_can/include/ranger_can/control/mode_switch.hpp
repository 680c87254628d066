// The motion-mode switch sequence, as the manual requires it: a mode change (0x141) only at
// standstill. While a switch is wanted the controller commands zero; once every wheel is below
// the standstill speed the sequencer asks for 0x141, then waits until 0x291 reports the target
// with switching = 0, resending every `timeout` and reporting failure after `max_attempts`.
// Pure state: no bus, no clock; the controller feeds it and sends what it asks for.
#pragma once

#include <chrono>
#include <optional>
#include <string_view>

#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

enum class ModeSwitchPhase {
  kIdle,                  // chassis in the wanted mode (or nothing wanted)
  kStopping,              // commanding zero, waiting for standstill before sending 0x141
  kAwaitingConfirmation,  // 0x141 sent, waiting for 0x291: target mode, switching = 0
};
inline constexpr auto kModeSwitchPhaseNames = text::enum_names<ModeSwitchPhase>({
    {ModeSwitchPhase::kIdle, "idle"},
    {ModeSwitchPhase::kStopping, "stopping"},
    {ModeSwitchPhase::kAwaitingConfirmation, "awaiting_confirmation"},
});
inline std::string_view to_string(ModeSwitchPhase p) {
  return kModeSwitchPhaseNames.name(p);
}

struct ModeSwitchConfig {
  std::chrono::nanoseconds timeout = std::chrono::milliseconds(1500);  // per 0x141 attempt
  int max_attempts = 3;
};

struct ModeSwitchStatus {
  ModeSwitchPhase phase = ModeSwitchPhase::kIdle;
  std::optional<protocol::MotionMode> target;
  int attempts = 0;     // 0x141 sent for the current target
  bool failed = false;  // attempts exhausted without confirmation (retries go on at the same
                        // rate; cleared when a switch completes or is abandoned)
};

class ModeSwitchSequencer {
 public:
  explicit ModeSwitchSequencer(ModeSwitchConfig config = {}) : config_(config) {}

  // One step while motion is wanted and allowed: the mode the caller wants, the chassis's
  // current mode (0x291) and whether it stands still. Returns the mode to send in 0x141 now, if
  // one is due (the first attempt at standstill, then a retry every `timeout`).
  std::optional<protocol::MotionMode> update(protocol::MotionMode wanted,
                                             protocol::MotionMode current, bool at_standstill,
                                             Timestamp now);
  // 0x291 arrived: completes the switch when it reports the target with switching = 0.
  // Returns true when that completed a switch.
  bool on_feedback(protocol::MotionMode mode, bool switching);
  // Nothing to drive (or not allowed to): the switch is abandoned; a failure is forgotten.
  void cancel();

  // True while the sequencer holds the chassis at zero (stopping or awaiting confirmation).
  bool active() const { return status_.phase != ModeSwitchPhase::kIdle; }
  // When update() next has a retry due (max() when none).
  Timestamp next_due() const;
  const ModeSwitchStatus& status() const { return status_; }

 private:
  ModeSwitchConfig config_;
  ModeSwitchStatus status_;
  Timestamp sent_{0};  // last 0x141
};

}  // namespace ranger
