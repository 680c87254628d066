// The re-arm latch: after any stop the commander did not ask for, motion never resumes by itself
// (ISO 13850 / IEC 60204-1: resetting an emergency stop must not restart the machine).
//
// A stop cause that becomes active (e-stop, remote takeover, a critical error, the low-battery
// cut-off, link loss, a failed mode switch, an implausible chassis response) latches. The latch
// holds after the cause has cleared, even when it cleared by itself, until an explicit act:
//  * the commander sends a zero twist while no cause is active (it has seen the stop), or
//  * resume() is called while no cause is active.
// resume() while a cause is still active is refused, naming the cause. The command timeout (the
// commander went quiet) is the commander's own stop and never latches. Pure state, no clock.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

enum class StopCause : std::uint32_t {
  kLinkLost = 1u << 0,          // the chassis fell silent (0x211 missing) after being heard
  kRemote = 1u << 1,            // the remote control took the chassis (0x211 control mode 0x03)
  kEstop = 1u << 2,             // emergency stop (0x211 vehicle status)
  kCriticalError = 1u << 3,     // a 0x211 error bit that stops the chassis
  kLowBattery = 1u << 4,        // BMS SOC below the cut-off
  kModeSwitchFailed = 1u << 5,  // 0x141 never confirmed after the attempts
  kImplausible = 1u << 6,       // the chassis's feedback contradicts the protocol settings
};
using StopCauses = std::uint32_t;  // bit set of StopCause

inline StopCauses operator|(StopCauses a, StopCause b) {
  return a | static_cast<std::uint32_t>(b);
}
inline bool has(StopCauses set, StopCause c) {
  return (set & static_cast<std::uint32_t>(c)) != 0;
}
// In ascending bit order.
inline constexpr auto kStopCauseNames = text::enum_names<StopCause>({
    {StopCause::kLinkLost, "link_lost"},
    {StopCause::kRemote, "remote"},
    {StopCause::kEstop, "emergency_stop"},
    {StopCause::kCriticalError, "critical_error"},
    {StopCause::kLowBattery, "low_battery"},
    {StopCause::kModeSwitchFailed, "motion_mode_switch_failed"},
    {StopCause::kImplausible, "implausible_feedback"},
});
inline std::string_view to_string(StopCause c) {
  return kStopCauseNames.name(c);
}
// "emergency_stop,remote" (ascending bit order), "" for none.
std::string describe(StopCauses causes);

class RearmLatch {
 public:
  // The causes active now; a newly active cause latches.
  void update(StopCauses active);
  // The commander sent a zero twist: re-arms when no cause is active. Returns true if it did.
  bool on_zero_command(StopCauses active);
  // The explicit resume: re-arms when no cause is active; otherwise refused, naming the causes.
  Status resume(StopCauses active);

  bool latched() const { return latched_ != 0; }
  StopCauses causes() const { return latched_; }  // what latched since the last re-arm

 private:
  StopCauses latched_ = 0;
};

}  // namespace ranger
