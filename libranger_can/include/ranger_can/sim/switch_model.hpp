// The motion-mode switch as the virtual chassis reports and performs it: what 0x291 says while
// the wheels turn, and how long they take. One part of the virtual chassis (virtual_chassis.hpp
// owns the time and the frames; chassis_model.hpp turns the wheels along the TurnProfile given
// here).
//
// Two reports, each a named setting (SwitchReport):
//  * mode_left — the RANGER user manual's reading, this project's first: 0x291 byte 0 reports the
//    mode being left and byte 1 (switching) is 1 for the whole switch. The default of the RANGER
//    (`sim`, `sim:manual`, `sim:agx_v2`).
//  * at_once — what a real RANGER MINI 3.0 shows (field notes of zeroworks-robotics/ranger_ros2,
//    docs/, the state observation summary of 2026-09-14: 941 mode changes in 4.4 h of CAN logs):
//    byte 0 shows the *new* mode as soon as 0x141 is received; byte 1 is raised on some switches
//    only (439 of 941, 47 %: `flag_share`, drawn per switch from `seed`, deterministic), for as
//    long as the wheels turn. The default of `sim:mini_v3` and `--model ranger_mini_v3`, and of
//    the RANGER variant `sim:field_switch`.
// Two ways the wheels turn (SwitchTurn):
//  * fixed_duration — every wheel linearly from where it stands to the new mode's angles over the
//    chassis's mode_switch_duration (the first reading: no source gave a time);
//  * slew — the field's fit t = d / 3.26 rad/s + 0.064 s for the largest wheel turn d (1.57 rad in
//    about 0.54 s): a trapezoidal velocity profile with the peak rate `slew_rate` and an
//    acceleration of slew_rate / slew_lag, triangular below slew_rate * slew_lag = 0.21 rad (the
//    notes' "triangular below 0.21 rad"); every wheel on the same normalised profile, so all four
//    arrive together; never shorter than `minimum_time` (0.08 s, the shortest median by
//    transition). The measured switch times, 0.08-0.36 s median by transition, at most 0.57 s,
//    follow from the geometry of the MINI 3.0.
// Speed commands are ignored until the wheels are there (its manual; ChassisModel::set_target).
#pragma once

#include <cstdint>
#include <random>
#include <string_view>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

enum class SwitchReport {
  kModeLeft,  // 0x291: the mode being left, switching = 1 throughout (the manual's reading)
  kAtOnce,    // 0x291: the new mode at once, switching = 1 on some switches (the field)
};
inline constexpr auto kSwitchReportNames = text::enum_names<SwitchReport>({
    {SwitchReport::kModeLeft, "mode_left"},
    {SwitchReport::kAtOnce, "at_once"},
});
inline std::string_view to_string(SwitchReport r) {
  return kSwitchReportNames.name(r);
}

enum class SwitchTurn {
  kFixedDuration,  // linearly over mode_switch_duration
  kSlew,           // at slew_rate with a trapezoidal profile (the field)
};
inline constexpr auto kSwitchTurnNames = text::enum_names<SwitchTurn>({
    {SwitchTurn::kFixedDuration, "fixed_duration"},
    {SwitchTurn::kSlew, "slew"},
});
inline std::string_view to_string(SwitchTurn t) {
  return kSwitchTurnNames.name(t);
}

// The field's figures (the state observation summary of 2026-09-14; docs/FIELD_FACTS.md).
inline constexpr double kFieldSlewRate = 3.26;            // rad/s, the steering's peak rate
inline constexpr double kFieldSlewLag = 0.064;            // s, t = d / rate + lag
inline constexpr double kFieldMinimumSwitchTime = 0.08;   // s, the shortest median by transition
inline constexpr double kFieldFlagShare = 439.0 / 941.0;  // switches with 0x291 byte 1 raised

struct SwitchModelConfig {
  SwitchReport report = SwitchReport::kModeLeft;
  double flag_share = 1.0;  // share of switches whose 0x291 raises byte 1 (at_once only)
  std::uint32_t seed = 1;   // the per-switch draw of the flag
  SwitchTurn turn = SwitchTurn::kFixedDuration;
  double slew_rate = kFieldSlewRate;              // rad/s (slew)
  double slew_lag = kFieldSlewLag;                // s (slew)
  double minimum_time = kFieldMinimumSwitchTime;  // s (slew)
};

// The field's switch: at_once, the flag on 47 % of the switches, slewing at 3.26 rad/s.
SwitchModelConfig field_switch_model();
// The manual's reading: mode_left, the flag throughout, a fixed duration.
SwitchModelConfig mode_left_switch_model();

// How the wheels turn once the body is at rest: the time a turn of `distance` (rad, the largest
// wheel's) takes and how far along it the wheels are after `t` seconds (0..1).
struct TurnProfile {
  double fixed_duration = 0.5;  // s (rate <= 0)
  double rate = 0.0;            // rad/s; > 0: trapezoidal slew
  double acceleration = 0.0;    // rad/s^2 (slew)
  double minimum_time = 0.0;    // s (slew): the switch completes no sooner
  double duration(double distance) const;
  double fraction(double t, double distance) const;
};

// What 0x291 reports of a switch.
struct SwitchReportValue {
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  bool switching = false;
};

class SwitchModel {
 public:
  SwitchModel(const SwitchModelConfig& config, double fixed_duration_s);

  // The profile a switch starting now turns the wheels along.
  TurnProfile turn_profile() const;
  // A switch began (0x141 or the remote): draws whether this one raises the flag.
  void on_switch_started();
  // 0x291's mode and flag, given the mode the chassis is in, whether it is switching and to what,
  // and whether the switch is held (fault injection: a switch that never completes keeps the flag
  // raised, whichever report).
  SwitchReportValue report(protocol::MotionMode mode, bool switching, protocol::MotionMode target,
                           bool held = false) const;
  const SwitchModelConfig& config() const { return config_; }

 private:
  SwitchModelConfig config_;
  double fixed_duration_s_;
  std::mt19937 rng_;
  bool flag_ = true;  // the current switch raises byte 1
};

}  // namespace ranger::sim
