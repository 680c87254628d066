// The motion-mode switch sequence, as the manual requires it: a mode change (0x141) only at
// standstill. While a switch is wanted the controller commands zero; once every wheel is below
// the standstill speed the sequencer asks for 0x141, then waits until the chassis has switched,
// resending every `timeout` and reporting failure after `max_attempts`.
// A switch is complete when 0x291 reports the target with switching = 0 *and* the wheels stand at
// the new mode's angles: read from 0x271 where the chassis sends it (the controller judges them,
// settle()), else, and at the latest, once `blind_time`, the chassis's own switch time, has passed
// since the first 0x141.
// Never on 0x291 alone: a real RANGER MINI 3.0 reports the new mode as soon as 0x141 arrives and
// raises the switching flag on some switches only (docs/FIELD_FACTS.md), while the wheels turn
// for up to 0.57 s and speed commands are ignored until they are there.
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
  kAwaitingWheels,        // 0x291 confirmed; waiting for the wheels (0x271) or blind_time
};
inline constexpr auto kModeSwitchPhaseNames = text::enum_names<ModeSwitchPhase>({
    {ModeSwitchPhase::kIdle, "idle"},
    {ModeSwitchPhase::kStopping, "stopping"},
    {ModeSwitchPhase::kAwaitingConfirmation, "awaiting_confirmation"},
    {ModeSwitchPhase::kAwaitingWheels, "awaiting_wheels"},
});
inline std::string_view to_string(ModeSwitchPhase p) {
  return kModeSwitchPhaseNames.name(p);
}

struct ModeSwitchConfig {
  std::chrono::nanoseconds timeout = std::chrono::milliseconds(1500);  // per 0x141 attempt
  int max_attempts = 3;
  // Without 0x271, a switch is taken complete this long after its 0x141 at the earliest: the
  // chassis's own switch time (the field's longest, 0.57 s, rounded up).
  std::chrono::nanoseconds blind_time = std::chrono::milliseconds(580);
  // Never sooner than this after the first 0x141, whatever 0x271 shows: the chassis's shortest
  // switch (the field's 0.08 s, with the bus's latency).
  std::chrono::nanoseconds min_time = std::chrono::milliseconds(100);
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
  // 0x291 arrived: the chassis reports the target with switching = 0 (or no longer does).
  void on_feedback(protocol::MotionMode mode, bool switching);
  // Completes the switch when 0x291 has confirmed it and the wheels are there: `wheels_at_target`
  // as 0x271 reads them (nullopt: no fresh 0x271); blind_time after the first 0x141 completes it
  // in any case. True when that
  // completed a switch.
  bool settle(std::optional<bool> wheels_at_target, Timestamp now);
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
  Timestamp sent_{0};   // last 0x141
  Timestamp first_{0};  // the first 0x141 of this switch (blind_time counts from it)
};

}  // namespace ranger
