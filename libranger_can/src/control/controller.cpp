#include "ranger_can/control/controller.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "ranger_can/control/parameters.hpp"
#include "ranger_can/transport/error_frame.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using protocol::ControlMode;
using protocol::MotionMode;

bool known_control_mode(std::uint8_t raw) {
  return raw == static_cast<std::uint8_t>(ControlMode::kStandby) ||
         raw == static_cast<std::uint8_t>(ControlMode::kCan) ||
         raw == static_cast<std::uint8_t>(ControlMode::kUart) ||
         raw == static_cast<std::uint8_t>(ControlMode::kRemote);
}

// The modes a twist can be driven in; side slip only where the profile's numbering has it, and
// only when forced (the automatic selection never picks it).
bool drivable_mode(MotionMode m) {
  return m == MotionMode::kAckermann || m == MotionMode::kOblique || m == MotionMode::kSpin ||
         m == MotionMode::kSideSlip;
}

bool is_zero(const BodyTwist& t) {
  return t.vx == 0.0 && t.vy == 0.0 && t.wz == 0.0;
}

Status check_duration(const char* name, std::chrono::nanoseconds d) {
  if (d.count() <= 0) {
    return Error{Errc::kOutOfRange, std::string("controller: ") + name + " must be > 0"};
  }
  return ok_status();
}

}  // namespace

Status check_finite(const MotionRequest& request) {
  const struct {
    const char* name;
    double value;
  } components[] = {{"linear.x", request.twist.vx},         {"linear.y", request.twist.vy},
                    {"linear.z", request.out_of_plane.vz},  {"angular.x", request.out_of_plane.wx},
                    {"angular.y", request.out_of_plane.wy}, {"angular.z", request.twist.wz}};
  for (const auto& c : components) {
    if (!std::isfinite(c.value)) {
      return Error{Errc::kNotFinite,
                   std::string(c.name) + " is " + (std::isnan(c.value) ? "NaN" : "infinite")};
    }
  }
  return ok_status();
}

bool can_drive_in(MotionMode mode, const ProtocolProfile& profile) {
  return drivable_mode(mode) &&
         protocol::motion_mode_to_wire(mode, profile.mode_numbering).has_value();
}

std::vector<MotionMode> drivable_modes(const ProtocolProfile& profile) {
  std::vector<MotionMode> out;
  for (MotionMode m : protocol::kMotionModeNames.values()) {
    if (can_drive_in(m, profile)) out.push_back(m);
  }
  return out;
}

Status check_drivable(MotionMode mode, const ProtocolProfile& profile) {
  if (can_drive_in(mode, profile)) return ok_status();
  std::string modes;
  for (MotionMode m : drivable_modes(profile))
    modes += (modes.empty() ? "" : ", ") + std::string(protocol::to_string(m));
  return Error{Errc::kInvalidArgument, std::string(protocol::to_string(mode)) +
                                           ": unsupported by protocol " + profile.revision +
                                           " (it drives " + modes + ")"};
}

Status ControllerConfig::validate() const {
  if (Status st = geometry.validate(); !st) return st;
  if (Status st = limits.validate(); !st) return st;
  if (Status st = mode_selection.validate(); !st) return st;
  if (Status st = limit_vx.validate(); !st) return st;
  if (Status st = limit_vy.validate(); !st) return st;
  if (Status st = limit_wz.validate(); !st) return st;
  const struct {
    const char* name;
    std::chrono::nanoseconds value;
  } durations[] = {{"link_timeout", link_timeout},
                   {"control_mode_retry_period", control_mode_retry_period},
                   {"keep_alive_period", keep_alive_period},
                   {"min_command_interval", min_command_interval},
                   {"cmd_timeout", cmd_timeout},
                   {"mode_switch_timeout", mode_switch_timeout},
                   {"mode_switch_blind_time", mode_switch_blind_time},
                   {"mode_switch_min_time", mode_switch_min_time},
                   {"ultrasonic_confirm_timeout", ultrasonic_confirm_timeout}};
  for (const auto& d : durations) {
    if (Status st = check_duration(d.name, d.value); !st) return st;
  }
  if (keep_alive_period >= std::chrono::milliseconds(protocol::kChassisCommandTimeoutMs)) {
    return Error{Errc::kOutOfRange,
                 "controller: keep_alive_period must be below the chassis's 500 ms timeout"};
  }
  if (mode_switch_max_attempts < 1 || ultrasonic_max_attempts < 1) {
    return Error{Errc::kOutOfRange,
                 "controller: mode_switch_max_attempts and ultrasonic_max_attempts must be >= 1"};
  }
  if (!std::isfinite(standstill_speed) || standstill_speed < 0.0) {
    return Error{Errc::kOutOfRange, "controller: standstill_speed must be finite and >= 0"};
  }
  // The ranges the parameter table gives (control/parameters.hpp).
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"steer_first_threshold", steer_first_threshold},
        {"low_battery_soc", low_battery_soc}}) {
    if (Status st = check_value(*find_driver_parameter(name), value); !st) {
      return Error{st.error().code, "controller: " + st.error().message};
    }
  }
  return ok_status();
}

ChassisController::ChassisController(Bus& bus, ControllerConfig config)
    : bus_(bus),
      config_(std::move(config)),
      selector_(config_.mode_selection),
      mode_switch_(ModeSwitchConfig{config_.mode_switch_timeout, config_.mode_switch_max_attempts,
                                    config_.mode_switch_blind_time, config_.mode_switch_min_time}),
      limiter_vx_(config_.limit_vx),
      limiter_vy_(config_.limit_vy),
      limiter_wz_(config_.limit_wz) {
  state_.zero_twist_rearms = config_.rearm_on_zero_twist;
  update_faults();
}

ChassisController::~ChassisController() {
  try {
    shutdown(state_.now);
  } catch (...) {  // a destructor must not throw; the chassis stops by itself after 500 ms
  }
}

// ---- input -------------------------------------------------------------------------------------

void ChassisController::on_frame(const CanFrame& frame, Timestamp now) {
  state_.now = now;
  if (frame.is_error) {
    ++state_.counters.error_frames;
    // Bus-off: nothing we send arrives any more, and what is queued goes out only after the
    // controller restarts. Treat it as link loss at once, so that only zero commands queue up
    // behind the moving ones already in flight (waiting link_timeout would queue moving ones).
    if (interpret_error_frame(frame).new_state == BusState::kBusOff &&
        state_.link == LinkState::kConnected) {
      lose_link();
      update_causes();
      update_faults();
    }
    return;
  }
  ++state_.counters.frames_received;
  Result<Message> message = decode(frame, config_.profile);
  if (!message) {
    ++state_.counters.decode_errors;
    state_.last_error = message.error().message;
    return;
  }
  on_message(*message, frame.stamp, now);
}

void ChassisController::on_message(const Message& message, Timestamp stamp, Timestamp now) {
  state_.now = now;
  if (!feedback_.record(message, stamp, now)) return;  // host -> chassis: no chassis state
  if (const auto* status = std::get_if<SystemStatus>(&message)) {
    on_system_status(*status, now);
  } else if (const auto* mode = std::get_if<MotionModeFeedback>(&message)) {
    on_motion_mode(*mode);
  } else if (const auto* angles = std::get_if<SteeringAnglesFeedback>(&message)) {
    constexpr double kStill = 0.005;  // rad between two frames: the wheels stand
    wheels_still_ = previous_wheel_angles_.has_value();
    for (std::size_t i = 0; wheels_still_ && i < angles->angles.size(); ++i) {
      // Modulo pi: a wheel at +90 deg stands as one at -90 deg.
      wheels_still_ = std::fabs(std::remainder(angles->angles[i] - (*previous_wheel_angles_)[i],
                                               M_PI)) <= kStill;
    }
    previous_wheel_angles_ = angles->angles;
    settle_switch(now);  // the wheels may have arrived at a switch's angles
    return;
  } else if (const auto* bms = std::get_if<BmsData>(&message)) {
    if (bms->battery == 0) state_.battery_soc = bms->soc;
  } else if (const auto* us = std::get_if<UltrasonicSettingFeedback>(&message)) {
    state_.ultrasonic_enabled = us->enabled;
    if (state_.ultrasonic_requested && *state_.ultrasonic_requested == us->enabled) {
      state_.ultrasonic_requested.reset();
      state_.ultrasonic_failed = false;
      ultrasonic_attempts_ = 0;
    }
  } else {
    return;  // wheel, motor, ultrasonic and other frames change no cause and no fault
  }
  update_causes();
  update_faults();
}

void ChassisController::on_system_status(const SystemStatus& m, Timestamp now) {
  last_status_time_ = now;
  state_.link = LinkState::kConnected;
  const bool was_can = state_.control_mode == ControlMode::kCan;
  state_.control_mode_raw = m.control_mode_raw;
  state_.control_mode = known_control_mode(m.control_mode_raw)
                            ? std::optional<ControlMode>(m.control_mode)
                            : std::nullopt;
  const bool is_can = state_.control_mode == ControlMode::kCan;
  // Awaiting ends with CAN mode, and under remote control there is nothing to await.
  if (state_.control_mode != ControlMode::kStandby) state_.awaiting_command_mode = false;
  if (state_.control_mode == ControlMode::kRemote && !config_.auto_reclaim_after_remote) {
    state_.reclaim_blocked = true;  // remote control is final: only resume() asks again
  }
  if (is_can) state_.reclaim_blocked = false;  // the operator handed back with SWB
  if (is_can && !was_can) {
    next_keep_alive_ = now;  // (re)gained control: keep-alive starts at the next tick
    command_changed_ = true;
  }
  state_.vehicle_status = m.vehicle_status_raw <= 2
                              ? std::optional<protocol::VehicleStatus>(m.vehicle_status)
                              : std::nullopt;
  state_.error_bits = m.error_bits;
}

void ChassisController::on_motion_mode(const MotionModeFeedback& m) {
  state_.chassis_mode = m.mode_known ? std::optional<MotionMode>(m.mode) : std::nullopt;
  // Out of park once 0x291 says so and the switch out is done (a chassis reporting the new mode at
  // once still turns its wheels: the switch goes on to its end, mode_switch.hpp).
  if (state_.chassis_mode != MotionMode::kPark && !mode_switch_.active()) leave_park_ = false;
  if (m.mode == MotionMode::kPark && m.mode_known) {
    // Park: nothing to command in, but the switch into it (request_park) completes here.
    state_.motion_mode.reset();
    state_.chassis_switching = m.switching;
    mode_switch_.on_feedback(m.mode, m.switching);
    settle_switch(state_.now);
    return;
  }
  if (!m.mode_known || !drivable_mode(m.mode)) {
    // A mode this driver cannot command in (unknown value, park, side slip): the meaning of
    // 0x111 is unknown, so nothing moves (kModeUnknown). The switching bit still counts.
    state_.motion_mode.reset();
    state_.chassis_switching = m.switching;
    return;
  }
  state_.motion_mode = m.mode;
  state_.chassis_switching = m.switching;
  mode_switch_.on_feedback(m.mode, m.switching);
  settle_switch(state_.now);
}

std::optional<bool> ChassisController::wheels_at_switch_target(Timestamp now) const {
  const auto& target = mode_switch_.status().target;
  if (!target || !is_fresh(feedback_.steering_angles, now, config_.link_timeout)) {
    return std::nullopt;
  }
  if (!wheels_still_) return false;  // still turning
  const auto wanted =
      wheel_angles_for_command(MotionCommand{}, *target, config_.geometry, config_.profile);
  for (std::size_t i = 0; i < wanted.size(); ++i) {
    const double measured =
        interpretation::rep103_from_manual_wheel_angle(feedback_.steering_angles->value.angles[i]);
    // A wheel at +90 deg stands as one at -90 deg: compare modulo pi.
    const double off = std::remainder(measured - wanted[i], M_PI);
    if (std::fabs(off) > config_.mode_switch_wheel_tolerance) return false;
  }
  return true;
}

void ChassisController::settle_switch(Timestamp now) {
  if (mode_switch_.settle(wheels_at_switch_target(now), now)) command_changed_ = true;
}

// ---- commands ----------------------------------------------------------------------------------

Status ChassisController::set_command(const MotionRequest& request, Timestamp now) {
  state_.now = now;
  if (state_.shut_down) {
    return Error{Errc::kInvalidArgument, "controller: set_command after shutdown"};
  }
  if (Status st = check_finite(request); !st) {
    // A NaN is a caller bug, not a wish to keep driving the previous command: stop, and say so
    // (kInvalidCommand) until a valid request comes.
    state_.requested = MotionRequest{};
    state_.has_command = true;
    state_.last_command_time = now;
    state_.cmd_timed_out = false;
    state_.invalid_command = st.error().message;
    state_.stale_command.clear();
    ++state_.counters.invalid_commands;
    command_changed_ = true;
    return Error{Errc::kNotFinite, "controller: command " + st.error().message + "; stopping"};
  }
  state_.stale_command.clear();
  if (request.age && *request.age > config_.cmd_timeout) {
    // A command older than the command timeout would have timed out already: stop, and say so
    // (kStaleCommand) until a fresh request comes.
    using Seconds = std::chrono::duration<double>;
    state_.requested = MotionRequest{};
    state_.has_command = true;
    state_.last_command_time = now;
    state_.cmd_timed_out = false;
    state_.invalid_command.clear();
    state_.stale_command = "stamped " + text::number_text(Seconds(*request.age).count()) +
                           " s ago, older than cmd_vel_timeout " +
                           text::number_text(Seconds(config_.cmd_timeout).count()) + " s";
    command_changed_ = true;
    return Error{Errc::kTimeout, "controller: command " + state_.stale_command + "; stopping"};
  }
  if (request.mode) {
    if (Status st = check_drivable(*request.mode, config_.profile); !st) {
      return Error{Errc::kInvalidArgument, "controller: motion mode " + st.error().message};
    }
  }
  if (is_zero(request.twist)) {
    // A zero twist abandons a switch that never completed. It re-arms only where the owner opted
    // in (rearm_on_zero_twist), once every cause of an involuntary stop has cleared.
    if (mode_switch_.status().failed) mode_switch_.cancel();
    update_causes();
    if (config_.rearm_on_zero_twist && latch_.on_zero_command(state_.active_causes)) {
      ++state_.counters.rearms;
    }
    state_.latched_causes = latch_.causes();
  }
  state_.invalid_command.clear();
  state_.requested = request;
  state_.has_command = true;
  state_.last_command_time = now;
  state_.cmd_timed_out = false;
  command_changed_ = true;
  return ok_status();
}

bool ChassisController::can_drive_in(MotionMode mode) const {
  return ranger::can_drive_in(mode, config_.profile);
}

void ChassisController::request_motion_mode(std::optional<MotionMode> mode, Timestamp now) {
  state_.now = now;
  if (mode && !can_drive_in(*mode)) return;
  state_.mode_override = mode;
  command_changed_ = true;
}

Status ChassisController::request_control_mode(ControlMode mode, Timestamp now) {
  state_.now = now;
  if (mode != ControlMode::kStandby && mode != ControlMode::kCan) {
    return Error{Errc::kInvalidArgument,
                 "controller: the host can request only standby (0x00) or CAN mode (0x01)"};
  }
  ++state_.counters.control_mode_requests;
  if (mode == ControlMode::kCan) state_.awaiting_command_mode = true;
  if (!send(ControlModeCommand{mode}, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::clear_errors(std::uint8_t code, Timestamp now) {
  state_.now = now;
  if (code > protocol::kMaxErrorClearCode) {
    return Error{Errc::kInvalidArgument, "controller: 0x441 error-clear code " +
                                             std::to_string(code) +
                                             " is not defined (valid 0x00..0x10)"};
  }
  ++state_.counters.error_clear_requests;
  if (!send(ErrorClearCommand{code}, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::refuse_unsupported(const Message& command) const {
  const auto missing = unsupported_feature(command, config_.profile);
  if (!missing) return ok_status();
  return Error{Errc::kInvalidArgument, missing->feature + ": unsupported by protocol " +
                                           config_.profile.revision + " (" + missing->reason + ")"};
}

Status ChassisController::set_drive_mode(protocol::DriveMode mode, Timestamp now) {
  state_.now = now;
  const DriveModeCommand command{mode};
  if (Status st = refuse_unsupported(command); !st) return st;
  if (!send(command, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::set_ultrasonic(bool enable, Timestamp now) {
  state_.now = now;
  state_.ultrasonic_requested = enable;
  state_.ultrasonic_failed = false;
  ultrasonic_attempts_ = 1;
  ultrasonic_sent_ = now;
  ++state_.counters.ultrasonic_requests;
  update_faults();
  if (!send(UltrasonicSettingCommand{enable}, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::request_park(bool on, Timestamp now) {
  state_.now = now;
  if (!protocol::motion_mode_to_wire(MotionMode::kPark, config_.profile.mode_numbering)) {
    return Error{Errc::kInvalidArgument, "park: unsupported by protocol " +
                                             config_.profile.revision +
                                             " (its motion-mode numbering has no park mode)"};
  }
  if (on == state_.park_requested) {
    // A chassis found in park (parked before this driver ran): releasing switches it out.
    if (!on && state_.chassis_mode == MotionMode::kPark && !leave_park_) {
      leave_park_ = true;
      command_changed_ = true;
    }
    return ok_status();
  }
  state_.park_requested = on;
  leave_park_ = !on;
  mode_switch_.cancel();  // towards park, or out of it: a switch under way is abandoned
  command_changed_ = true;
  return ok_status();
}

Status ChassisController::set_lights(const LightCommand& lights, Timestamp now) {
  state_.now = now;
  if (Status st = refuse_unsupported(lights); !st) return st;
  LightCommand c = lights;
  c.counter = light_counter_++;
  ++state_.counters.light_commands;
  if (!send(c, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::request_version(Timestamp now) {
  state_.now = now;
  feedback_.version.clear();
  ++state_.counters.version_requests;
  if (!send(VersionRequest{}, now)) return Error{Errc::kIoError, state_.last_error};
  return ok_status();
}

Status ChassisController::resume(Timestamp now) {
  state_.now = now;
  if (state_.shut_down) return Error{Errc::kInvalidArgument, "controller: resume after shutdown"};
  update_link(now);
  update_causes();
  if (state_.link != LinkState::kConnected) {
    return Error{Errc::kInvalidArgument, "resume refused: the chassis is not connected (" +
                                             std::string(to_string(state_.link)) + ")"};
  }
  if (Status st = latch_.resume(state_.active_causes); !st) return st;
  ++state_.counters.rearms;
  state_.latched_causes = latch_.causes();
  state_.reclaim_blocked = false;
  next_control_request_ = now;  // in standby: ask for CAN mode at the next tick
  command_changed_ = true;
  update_faults();
  return ok_status();
}

void ChassisController::set_implausible(std::string reason) {
  if (reason == implausible_reason_) return;
  implausible_reason_ = std::move(reason);
  state_.implausible_reason = implausible_reason_;
  command_changed_ = true;
  update_causes();
  update_faults();
}

void ChassisController::set_identifying(std::optional<IdentificationPhase> phase) {
  if (phase == state_.identifying) return;
  state_.identifying = phase;
  if (!state_.identifying && !state_.standstill_probe) {
    probe_mode_.reset();
    state_.probe.reset();
  }
  command_changed_ = true;
}

void ChassisController::set_standstill_probe(bool active) {
  if (active == state_.standstill_probe) return;
  state_.standstill_probe = active;
  if (!state_.identifying && !state_.standstill_probe) {
    probe_mode_.reset();
    state_.probe.reset();
  }
  command_changed_ = true;
}

void ChassisController::set_quiet(bool quiet) {
  if (quiet == state_.quiet) return;
  state_.quiet = quiet;
  command_changed_ = true;
  if (!quiet) next_control_request_ = state_.now;  // ask for CAN mode at the next tick
}

void ChassisController::set_probe(std::optional<MotionMode> mode,
                                  std::optional<MotionCommand> command) {
  if (mode && !drivable_mode(*mode)) mode.reset();
  if (command) {
    // Zero speed, whatever the caller filled in: a probe never rolls a wheel.
    command->linear_speed = 0.0;
    command->spin_speed = 0.0;
    command->yaw_rate = 0.0;
  }
  const bool changed =
      mode != probe_mode_ || command.has_value() != state_.probe.has_value() ||
      (command && state_.probe && command->steering_angle != state_.probe->steering_angle);
  probe_mode_ = mode;
  state_.probe = command;
  if (changed) command_changed_ = true;
}

Status ChassisController::set_profile(const ProtocolProfile& profile) {
  if (Status st = profile.validate(); !st) return st;
  config_.profile = profile;
  faults_valid_ = false;  // the error word's names depend on the layout
  command_changed_ = true;
  update_causes();
  update_faults();
  return ok_status();
}

void ChassisController::shutdown(Timestamp now) {
  if (state_.shut_down) return;
  state_.now = now;
  // Stop, whatever the state: a zero 0x111 never hurts (unless nothing was ever said: quiet).
  send_motion(MotionCommand{}, nullptr, now, /*shutdown=*/true);
  if (config_.release_control_on_shutdown && state_.control_mode == ControlMode::kCan &&
      !state_.quiet) {
    ++state_.counters.control_mode_requests;
    send(ControlModeCommand{ControlMode::kStandby}, now, nullptr, /*shutdown=*/true);
  }
  state_.shut_down = true;
  mode_switch_.cancel();
  state_.mode_switch = mode_switch_.status();
  state_.limited = BodyTwist{};
}

// ---- the periodic state machine ---------------------------------------------------------------

void ChassisController::tick(Timestamp now) {
  if (state_.shut_down) return;
  state_.now = now;
  update_link(now);
  update_causes();
  run_control_mode(now);
  run_ultrasonic(now);
  run_motion(now);
  update_faults();
}

Timestamp ChassisController::next_tick_due() const {
  Timestamp due = state_.now + config_.keep_alive_period;
  auto earlier = [&due](Timestamp t) { due = std::min(due, t); };
  if (state_.control_mode == ControlMode::kCan) {
    earlier(next_keep_alive_);
    // A changed command goes out as soon as the rate bound allows.
    if (command_changed_) {
      earlier(prompt_sent_ ? last_prompt_send_ + config_.min_command_interval : state_.now);
    }
  }
  if (state_.awaiting_command_mode ||
      (state_.control_mode == ControlMode::kStandby && !state_.reclaim_blocked)) {
    earlier(next_control_request_);
  }
  if (state_.link == LinkState::kConnected) earlier(last_status_time_ + config_.link_timeout);
  if (state_.has_command && !state_.cmd_timed_out) {
    earlier(state_.last_command_time + config_.cmd_timeout);
  }
  if (state_.ultrasonic_requested) earlier(ultrasonic_sent_ + config_.ultrasonic_confirm_timeout);
  earlier(mode_switch_.next_due());
  return std::max(due, state_.now);
}

void ChassisController::update_link(Timestamp now) {
  if (state_.link == LinkState::kConnected && now - last_status_time_ > config_.link_timeout) {
    lose_link();
  }
}

void ChassisController::lose_link() {
  state_.link = LinkState::kStale;
  ++state_.counters.link_losses;
  state_.awaiting_command_mode = false;
  selector_.reset();
  mode_switch_.cancel();
  command_changed_ = true;
}

void ChassisController::update_causes() {
  StopCauses active = 0;
  if (state_.link == LinkState::kStale) active = active | StopCause::kLinkLost;
  if (state_.link == LinkState::kConnected) {
    if (state_.control_mode == ControlMode::kRemote) active = active | StopCause::kRemote;
    // The e-stop by its fault bit too, where the fault word has one: a real RANGER MINI 3.0
    // reports a pressed e-stop as body status 2 (abnormal) with fault bit 7, never as status 1
    // (docs/FIELD_FACTS.md), so status 1 alone would miss it.
    const std::uint32_t estop_bit =
        protocol::fault_bit(protocol::Fault::kEmergencyStop, config_.profile.error_word);
    if (state_.vehicle_status == protocol::VehicleStatus::kEmergencyStop ||
        (state_.error_bits & estop_bit) != 0) {
      active = active | StopCause::kEstop;
    }
    if (protocol::is_critical_error(state_.error_bits, config_.profile.error_word)) {
      active = active | StopCause::kCriticalError;
    }
  }
  if (state_.battery_soc && *state_.battery_soc < config_.low_battery_soc) {
    active = active | StopCause::kLowBattery;
  }
  if (mode_switch_.status().failed) active = active | StopCause::kModeSwitchFailed;
  if (!implausible_reason_.empty()) active = active | StopCause::kImplausible;
  state_.active_causes = active;
  latch_.update(active);
  state_.latched_causes = latch_.causes();
}

void ChassisController::run_control_mode(Timestamp now) {
  if (config_.listen_only || !config_.auto_command_mode || state_.quiet) return;
  if (state_.link != LinkState::kConnected || state_.reclaim_blocked) return;
  // Only standby is answered with a request: remote control is never fought, and an unknown
  // mode is not guessed at.
  if (state_.control_mode != ControlMode::kStandby) return;
  if (now < next_control_request_) return;
  ++state_.counters.control_mode_requests;
  state_.awaiting_command_mode = true;
  next_control_request_ = now + config_.control_mode_retry_period;
  send(ControlModeCommand{ControlMode::kCan}, now);
}

void ChassisController::run_ultrasonic(Timestamp now) {
  if (!state_.ultrasonic_requested) return;
  if (now - ultrasonic_sent_ < config_.ultrasonic_confirm_timeout) return;
  if (ultrasonic_attempts_ >= config_.ultrasonic_max_attempts) {
    state_.ultrasonic_requested.reset();
    state_.ultrasonic_failed = true;
    return;
  }
  ++ultrasonic_attempts_;
  ultrasonic_sent_ = now;
  ++state_.counters.ultrasonic_requests;
  send(UltrasonicSettingCommand{*state_.ultrasonic_requested}, now);
}

MotionRefusal ChassisController::evaluate_refusal() const {
  const StopCauses active = state_.active_causes;
  const bool identifying = state_.identifying.has_value() || state_.standstill_probe;
  // Listening: the driver withholds every frame on purpose, so the link is not what is missing.
  if (state_.quiet && identifying) return MotionRefusal::kIdentifying;
  if (state_.link != LinkState::kConnected) return MotionRefusal::kLinkLost;
  if (has(active, StopCause::kRemote)) return MotionRefusal::kRemote;
  if (has(active, StopCause::kEstop)) return MotionRefusal::kEstop;
  if (has(active, StopCause::kCriticalError)) return MotionRefusal::kCriticalError;
  if (has(active, StopCause::kLowBattery)) return MotionRefusal::kLowBattery;
  if (has(active, StopCause::kModeSwitchFailed)) return MotionRefusal::kModeSwitchFailed;
  if (has(active, StopCause::kImplausible)) return MotionRefusal::kImplausible;
  if (state_.latched_causes != 0) return MotionRefusal::kRearmRequired;
  if (state_.control_mode != ControlMode::kCan) return MotionRefusal::kStandby;
  if (state_.park_requested) return MotionRefusal::kParked;
  // A released park is left by a switch (run_motion); park itself commands nothing.
  if (!state_.motion_mode && !(leave_park_ && state_.parked())) return MotionRefusal::kModeUnknown;
  if (identifying) return MotionRefusal::kIdentifying;
  if (state_.cmd_timed_out) return MotionRefusal::kCmdTimeout;
  if (!state_.invalid_command.empty()) return MotionRefusal::kInvalidCommand;
  if (!state_.stale_command.empty()) return MotionRefusal::kStaleCommand;
  if (selector_.below_minimum(state_.requested.twist)) return MotionRefusal::kBelowMinimum;
  return MotionRefusal::kNone;
}

bool ChassisController::at_standstill(Timestamp now) const {
  const ChassisFeedback& fb = feedback_;
  if (is_fresh(fb.wheel_speeds, now, config_.link_timeout)) {
    const auto& speeds = fb.wheel_speeds->value.speeds;
    return std::all_of(speeds.begin(), speeds.end(),
                       [&](double s) { return std::fabs(s) <= config_.standstill_speed; });
  }
  if (is_fresh(fb.motion, now, config_.link_timeout)) {
    return std::fabs(fb.motion->value.speed) <= config_.standstill_speed;
  }
  return false;  // no fresh feedback: standstill cannot be confirmed
}

std::uint32_t ChassisController::adjustments(const KinematicsSolution& solution) const {
  // Automatic selection with a switch to come (the selector waits for confirm_time and the dwell
  // before it hands the request to the mode that expresses it): the current mode's solution is a
  // stopgap of a few hundred milliseconds (a rotation asked at standstill turns the wheels to
  // full lock until spin), not what becomes of the request.
  const bool automatic = !state_.requested.mode && !state_.mode_override;
  if (automatic && selector_.classify(state_.requested.twist, solution.mode) != solution.mode) {
    return kKinematicsExact;
  }
  return solution.flags;
}

double ChassisController::steer_first_factor(const KinematicsSolution& solution,
                                             Timestamp now) const {
  const double threshold = config_.steer_first_threshold;
  if (threshold <= 0.0 || solution.mode == MotionMode::kSpin) return 1.0;
  if (!is_fresh(feedback_.steering_angles, now, config_.link_timeout)) return 1.0;
  const auto wanted =
      wheel_angles_for_command(solution.command, solution.mode, config_.geometry, config_.profile);
  double worst = 0.0;
  for (std::size_t i = 0; i < wanted.size(); ++i) {
    const double measured =
        interpretation::rep103_from_manual_wheel_angle(feedback_.steering_angles->value.angles[i]);
    worst = std::max(worst, std::fabs(wanted[i] - measured));
  }
  return std::clamp((2.0 * threshold - worst) / threshold, 0.0, 1.0);
}

// What step 2 of run_motion decided: the refusal before any mode switch, and what may move.
struct ChassisController::MotionGate {
  MotionRefusal refusal = MotionRefusal::kNone;
  bool probing = false;       // the identification's zero-speed probe
  bool parking = false;       // park wanted: to rest, then 0x141 park
  bool leaving_park = false;  // park released: out of it without waiting for a twist
  bool may_drive = false;     // something to command (and allowed to)
};

void ChassisController::run_motion(Timestamp now) {
  check_command_timeout(now);                                             // 1.
  MotionGate gate = gate_motion();                                        // 2.
  const std::optional<MotionMode> mode_to_send = switch_mode(gate, now);  // 3.
  const MotionRefusal refusal = settle_refusal(gate.refusal);
  MotionCommand command{};  // 4.
  const KinematicsSolution* solution = motion_command(refusal, gate.probing, now, command);
  keep_alive(command, solution, now);  // 5.
  // 6. The mode command goes after the zero 0x111 of this tick.
  if (mode_to_send) {
    ++state_.counters.mode_switch_requests;
    send(MotionModeCommand{*mode_to_send}, now);
  }
}

// 1. The caller's command timeout.
void ChassisController::check_command_timeout(Timestamp now) {
  if (state_.has_command && !state_.cmd_timed_out &&
      now - state_.last_command_time >= config_.cmd_timeout) {
    state_.cmd_timed_out = true;
    ++state_.counters.cmd_timeouts;
    command_changed_ = true;
  }
}

// 2. Everything that forbids motion except a mode switch.
ChassisController::MotionGate ChassisController::gate_motion() const {
  MotionGate g;
  g.refusal = evaluate_refusal();
  const MotionRefusal r = g.refusal;
  // A switch that failed goes on retrying at its bounded rate (it stops nothing else).
  // The identification's probe: zero speed, a steering angle, possibly in another mode.
  g.probing = r == MotionRefusal::kIdentifying && state_.probe.has_value() &&
              state_.motion_mode.has_value() && !state_.quiet;
  g.parking = r == MotionRefusal::kParked && state_.chassis_mode.has_value();
  const bool drivable = r == MotionRefusal::kNone || r == MotionRefusal::kModeSwitchFailed;
  g.leaving_park =
      leave_park_ && (state_.parked() || mode_switch_.active()) &&
      (drivable || r == MotionRefusal::kCmdTimeout || r == MotionRefusal::kBelowMinimum ||
       r == MotionRefusal::kInvalidCommand || r == MotionRefusal::kStaleCommand);
  g.may_drive = (drivable && state_.has_command) || (g.probing && probe_mode_.has_value()) ||
                g.parking || g.leaving_park;
  return g;
}

// 3a. The mode wanted: park, the probe's, the request's, the forced one, else the selector's.
MotionMode ChassisController::wanted_mode(const MotionGate& g, MotionMode current, Timestamp now) {
  MotionMode wanted = current;
  if (g.parking) {
    wanted = MotionMode::kPark;
  } else if (g.probing) {
    wanted = *probe_mode_;
  } else if (state_.requested.mode) {
    wanted = *state_.requested.mode;
  } else if (state_.mode_override) {
    wanted = *state_.mode_override;
  } else {
    wanted = selector_.select(state_.requested.twist, current, now);
  }
  // Out of park into the mode the commander forced, else Ackermann (the selector keeps the
  // current mode for a twist it cannot classify).
  if (!g.parking && wanted == MotionMode::kPark) {
    wanted = state_.mode_override.value_or(MotionMode::kAckermann);
  }
  return wanted;
}

// 3b. Motion-mode switching: stop -> 0x141 -> confirmation; the mode to send now, if any.
std::optional<MotionMode> ChassisController::switch_mode(const MotionGate& g, Timestamp now) {
  std::optional<MotionMode> mode_to_send;
  if (!g.may_drive) {
    mode_switch_.cancel();  // nothing to drive (or not allowed to): no reason to switch
  } else {
    const MotionMode current = state_.motion_mode ? *state_.motion_mode : *state_.chassis_mode;
    const MotionMode wanted = wanted_mode(g, current, now);
    settle_switch(now);  // without 0x271: the chassis's switch time may have passed
    const bool was_active = mode_switch_.active();
    const int attempts = mode_switch_.status().attempts;
    mode_to_send = mode_switch_.update(wanted, current, at_standstill(now), now);
    if (mode_switch_.active() != was_active) command_changed_ = true;
    if (mode_to_send && attempts > 0 && mode_switch_.status().attempts > attempts) {
      ++state_.counters.mode_switch_timeouts;
    }
  }
  state_.mode_switch = mode_switch_.status();
  return mode_to_send;
}

// 3c. The refusal once the switch is known (failed, or under way).
MotionRefusal ChassisController::settle_refusal(MotionRefusal refusal) {
  if (state_.mode_switch.failed != has(state_.active_causes, StopCause::kModeSwitchFailed)) {
    update_causes();  // the switch failed (or its failure ended) in this very step
    refusal = evaluate_refusal();
  }
  if (refusal == MotionRefusal::kNone && (state_.chassis_switching || mode_switch_.active())) {
    refusal =
        mode_switch_.status().failed ? MotionRefusal::kModeSwitchFailed : MotionRefusal::kSwitching;
  }
  if (refusal != state_.refusal) command_changed_ = true;
  state_.refusal = refusal;
  return refusal;
}

// 4. The 0x111 to send: the limited request in the chassis's mode, or zero (the probe's steering
// while probing); the solution behind it, if any.
const KinematicsSolution* ChassisController::motion_command(MotionRefusal refusal, bool probing,
                                                            Timestamp now, MotionCommand& command) {
  const KinematicsSolution* solution = nullptr;
  state_.steer_first_factor = 1.0;
  state_.adjustments = 0;
  if (refusal == MotionRefusal::kNone && state_.has_command && state_.motion_mode) {
    const double dt = limiter_started_ ? seconds(now - last_limit_time_) : 0.0;
    const BodyTwist& target = state_.requested.twist;
    const BodyTwist previous = state_.limited;
    state_.limited = BodyTwist{limiter_vx_.limit(target.vx, previous.vx, dt),
                               limiter_vy_.limit(target.vy, previous.vy, dt),
                               limiter_wz_.limit(target.wz, previous.wz, dt)};
    Result<KinematicsSolution> solved = selector_.solve(
        state_.limited, *state_.motion_mode, config_.geometry, config_.limits, config_.profile);
    if (solved) {
      steer_first(*solved, now);
      state_.adjustments = adjustments(*solved);
      command = solved->command;
      state_.last_solution = *solved;
      solution = &*state_.last_solution;
    } else {
      state_.last_error = solved.error().message;
      state_.limited = BodyTwist{};
    }
  } else {
    state_.limited = BodyTwist{};  // refusals stop at once; the limiter restarts from zero
    if (probing && !state_.chassis_switching && !mode_switch_.active()) {
      command = *state_.probe;  // zero speeds (set_probe), the probe's steering
    }
  }
  limiter_started_ = true;
  last_limit_time_ = now;
  return solution;
}

// Steer first: hold the speed back while the wheels are far from the commanded angle.
void ChassisController::steer_first(KinematicsSolution& solved, Timestamp now) {
  const double factor = steer_first_factor(solved, now);
  if (factor < 1.0) {
    solved.command.linear_speed *= factor;
    solved.achieved = BodyTwist{solved.achieved.vx * factor, solved.achieved.vy * factor,
                                solved.achieved.wz * factor};
    state_.limited = BodyTwist{state_.limited.vx * factor, state_.limited.vy * factor,
                               state_.limited.wz * factor};
    if (state_.steer_first_factor == 1.0) command_changed_ = true;
  }
  state_.steer_first_factor = factor;
}

// 5. Keep-alive / prompt send, only while the chassis is (last known) in CAN command mode: in
// standby it ignores 0x111, and under remote control the host stays silent.
void ChassisController::keep_alive(const MotionCommand& command, const KinematicsSolution* solution,
                                   Timestamp now) {
  if (state_.control_mode != ControlMode::kCan) return;
  const bool scheduled = now >= next_keep_alive_;
  const bool prompt = command_changed_ &&
                      (!prompt_sent_ || now - last_prompt_send_ >= config_.min_command_interval);
  if (!scheduled && !prompt && state_.last_motion_command) return;
  send_motion(command, solution, now);
  if (prompt && !scheduled) {
    last_prompt_send_ = now;
    prompt_sent_ = true;
  }
  command_changed_ = false;
  next_keep_alive_ = scheduled && next_keep_alive_ + config_.keep_alive_period > now
                         ? next_keep_alive_ + config_.keep_alive_period
                         : now + config_.keep_alive_period;
}

// ---- output and bookkeeping --------------------------------------------------------------------

bool ChassisController::send(const Message& message, Timestamp now,
                             const KinematicsSolution* solution, bool shutdown) {
  if (config_.listen_only || state_.quiet) return false;
  Result<CanFrame> frame = encode(message, config_.profile);
  if (!frame) {
    ++state_.counters.send_failures;
    state_.last_error = frame.error().message;
    return false;
  }
  frame->stamp = now;
  Status st = bus_.send(*frame);
  if (!st) {
    ++state_.counters.send_failures;
    state_.last_error = st.error().message;
    return false;
  }
  ++state_.counters.frames_sent;
  if (observer_) {
    SentFrame sent;
    sent.frame = *frame;
    sent.message = message;
    sent.shutdown = shutdown;
    if (solution) {
      sent.solution = *solution;
      sent.achieved = solution->achieved;
      sent.adjustments = state_.adjustments;
      sent.requested = state_.requested.twist;
    }
    observer_(sent);
  }
  return true;
}

void ChassisController::send_motion(const MotionCommand& command,
                                    const KinematicsSolution* solution, Timestamp now,
                                    bool shutdown) {
  if (config_.listen_only || state_.quiet) return;
  state_.last_motion_command = command;
  state_.last_motion_command_time = now;
  if (send(command, now, solution, shutdown)) ++state_.counters.motion_commands_sent;
}

void ChassisController::update_faults() {
  // Rebuilt only when an input changes: 0x211 arrives 50 times a second.
  const std::uint64_t signature =
      static_cast<std::uint64_t>(state_.error_bits) |
      (static_cast<std::uint64_t>(state_.active_causes) << 32) |
      (static_cast<std::uint64_t>(state_.vehicle_status == protocol::VehicleStatus::kAbnormal)
       << 48) |
      (static_cast<std::uint64_t>(state_.ultrasonic_failed) << 49) |
      (static_cast<std::uint64_t>(feedback_.system_status.has_value() &&
                                  !state_.vehicle_status.has_value())
       << 50);
  if (faults_valid_ && signature == faults_signature_) return;
  faults_valid_ = true;
  faults_signature_ = signature;
  std::vector<std::string> faults;
  const auto add = [&faults](ControllerFault f) { faults.emplace_back(to_string(f)); };
  const StopCauses active = state_.active_causes;
  if (has(active, StopCause::kLinkLost)) add(ControllerFault::kLinkLost);
  if (has(active, StopCause::kEstop)) add(ControllerFault::kEmergencyStop);
  if (state_.vehicle_status == protocol::VehicleStatus::kAbnormal) {
    add(ControllerFault::kVehicleAbnormal);
  }
  if (feedback_.system_status && !state_.vehicle_status) {
    add(ControllerFault::kVehicleStatusUnknown);
  }
  for (std::string& name :
       protocol::error_bit_names(state_.error_bits, config_.profile.error_word)) {
    faults.push_back(std::move(name));
  }
  if (has(active, StopCause::kLowBattery)) add(ControllerFault::kLowBattery);
  if (has(active, StopCause::kModeSwitchFailed)) add(ControllerFault::kModeSwitchFailed);
  if (has(active, StopCause::kImplausible)) add(ControllerFault::kImplausibleFeedback);
  if (state_.ultrasonic_failed) add(ControllerFault::kUltrasonicUnconfirmed);
  state_.faults = std::move(faults);
}

}  // namespace ranger
