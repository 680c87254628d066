#include "ranger_can/control/controller.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

namespace ranger {
namespace {

using protocol::ControlMode;
using protocol::MotionMode;

bool known_control_mode(std::uint8_t raw) {
  return raw == static_cast<std::uint8_t>(ControlMode::kStandby) ||
         raw == static_cast<std::uint8_t>(ControlMode::kCan) ||
         raw == static_cast<std::uint8_t>(ControlMode::kRemote);
}

bool known_motion_mode(std::uint8_t raw) {
  return raw <= static_cast<std::uint8_t>(MotionMode::kSpin);
}

Status check_duration(const char* name, std::chrono::nanoseconds d) {
  if (d.count() <= 0) {
    return Error{Errc::kOutOfRange, std::string("controller: ") + name + " must be > 0"};
  }
  return ok_status();
}

}  // namespace

std::string_view to_string(MotionRefusal r) {
  switch (r) {
    case MotionRefusal::kNone:
      return "none";
    case MotionRefusal::kLinkLost:
      return "link_lost";
    case MotionRefusal::kRemote:
      return "remote";
    case MotionRefusal::kStandby:
      return "standby";
    case MotionRefusal::kEstop:
      return "estop";
    case MotionRefusal::kCriticalError:
      return "critical_error";
    case MotionRefusal::kLowBattery:
      return "low_battery";
    case MotionRefusal::kModeUnknown:
      return "mode_unknown";
    case MotionRefusal::kSwitching:
      return "switching";
    case MotionRefusal::kCmdTimeout:
      return "cmd_timeout";
  }
  return "unknown";
}

std::string_view to_string(LinkState s) {
  switch (s) {
    case LinkState::kNeverConnected:
      return "never_connected";
    case LinkState::kConnected:
      return "connected";
    case LinkState::kStale:
      return "stale";
  }
  return "unknown";
}

std::string_view to_string(ModeSwitchPhase p) {
  switch (p) {
    case ModeSwitchPhase::kIdle:
      return "idle";
    case ModeSwitchPhase::kStopping:
      return "stopping";
    case ModeSwitchPhase::kAwaitingConfirmation:
      return "awaiting_confirmation";
  }
  return "unknown";
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
  if (!std::isfinite(low_battery_soc) || low_battery_soc < 0.0 || low_battery_soc > 100.0) {
    return Error{Errc::kOutOfRange, "controller: low_battery_soc must be in [0, 100] %"};
  }
  return ok_status();
}

ChassisController::ChassisController(Bus& bus, ControllerConfig config)
    : bus_(bus),
      config_(std::move(config)),
      selector_(config_.mode_selection),
      limiter_vx_(config_.limit_vx),
      limiter_vy_(config_.limit_vy),
      limiter_wz_(config_.limit_wz) {
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
    return;
  }
  ++state_.counters.frames_received;
  Result<Message> message = decode(frame);
  if (!message) {
    ++state_.counters.decode_errors;
    state_.last_error = message.error().message;
    return;
  }
  on_message(*message, frame.stamp, now);
}

void ChassisController::on_message(const Message& message, Timestamp stamp, Timestamp now) {
  state_.now = now;
  ChassisFeedback& fb = state_.feedback;
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        const Stamped<T> stamped{m, now, stamp};
        if constexpr (std::is_same_v<T, SystemStatus>) {
          fb.system_status = stamped;
          last_status_time_ = now;
          if (state_.link != LinkState::kConnected) state_.link = LinkState::kConnected;
          const bool was_can = state_.control_mode == ControlMode::kCan;
          state_.control_mode_raw = m.control_mode_raw;
          state_.control_mode = known_control_mode(m.control_mode_raw)
                                    ? std::optional<ControlMode>(m.control_mode)
                                    : std::nullopt;
          const bool is_can = state_.control_mode == ControlMode::kCan;
          // Awaiting ends with CAN mode, and under remote control there is nothing to await.
          if (state_.control_mode != ControlMode::kStandby) state_.awaiting_command_mode = false;
          if (is_can && !was_can) {
            next_keep_alive_ = now;  // (re)gained control: keep-alive starts at the next tick
            command_changed_ = true;
          }
          state_.vehicle_status = m.vehicle_status_raw <= 2
                                      ? std::optional<protocol::VehicleStatus>(m.vehicle_status)
                                      : std::nullopt;
          state_.estop = state_.vehicle_status == protocol::VehicleStatus::kEmergencyStop;
          state_.error_bits = m.error_bits;
          state_.critical_error = protocol::is_critical_error(m.error_bits);
        } else if constexpr (std::is_same_v<T, MotionFeedback>) {
          fb.motion = stamped;
        } else if constexpr (std::is_same_v<T, MotionModeFeedback>) {
          fb.motion_mode = stamped;
          if (known_motion_mode(m.mode_raw)) {
            state_.motion_mode = m.mode;
            state_.chassis_switching = m.switching;
            if (state_.mode_switch_phase == ModeSwitchPhase::kAwaitingConfirmation &&
                state_.mode_switch_target == m.mode && !m.switching) {
              state_.mode_switch_phase = ModeSwitchPhase::kIdle;
              state_.mode_switch_target.reset();
              state_.mode_switch_attempts = 0;
              state_.mode_switch_failed = false;
              command_changed_ = true;
            }
          } else {
            // A mode this driver does not know: what a 0x111 would do is unknown, so motion is
            // refused (kModeUnknown) until a known mode is reported; its switching bit still
            // counts.
            state_.motion_mode.reset();
            state_.chassis_switching = m.switching;
          }
        } else if constexpr (std::is_same_v<T, SteeringAnglesFeedback>) {
          fb.steering_angles = stamped;
        } else if constexpr (std::is_same_v<T, WheelSpeedsFeedback>) {
          fb.wheel_speeds = stamped;
        } else if constexpr (std::is_same_v<T, MotorHighSpeedFeedback>) {
          if (m.motor >= 1 && m.motor <= protocol::kMotorCount) {
            fb.motor_high_speed[static_cast<std::size_t>(m.motor - 1)] = stamped;
          }
        } else if constexpr (std::is_same_v<T, MotorLowSpeedFeedback>) {
          if (m.motor >= 1 && m.motor <= protocol::kMotorCount) {
            fb.motor_low_speed[static_cast<std::size_t>(m.motor - 1)] = stamped;
          }
        } else if constexpr (std::is_same_v<T, BmsData>) {
          if (m.battery >= 0 && m.battery <= protocol::kBatteryCount) {
            fb.bms[static_cast<std::size_t>(m.battery)] = stamped;
          }
          if (m.battery == 0) {
            state_.battery_soc = m.soc;
            state_.low_battery = m.soc < config_.low_battery_soc;
          }
        } else if constexpr (std::is_same_v<T, BmsAlarm>) {
          if (m.battery >= 0 && m.battery <= protocol::kBatteryCount) {
            fb.bms_alarm[static_cast<std::size_t>(m.battery)] = stamped;
          }
        } else if constexpr (std::is_same_v<T, UltrasonicFeedback>) {
          fb.ultrasonic[m.first_sensor >= 5 ? 1 : 0] = stamped;
        } else if constexpr (std::is_same_v<T, UltrasonicSettingFeedback>) {
          fb.ultrasonic_setting = stamped;
          state_.ultrasonic_enabled = m.enabled;
          if (state_.ultrasonic_requested == m.enabled) {
            state_.ultrasonic_requested.reset();
            state_.ultrasonic_failed = false;
            ultrasonic_attempts_ = 0;
          }
        }
        // Host -> chassis messages seen on the bus (another host, our own echo) carry no state.
      },
      message);
  update_faults();
}

// ---- commands ----------------------------------------------------------------------------------

Status ChassisController::set_command(const MotionRequest& request, Timestamp now) {
  state_.now = now;
  if (state_.shut_down) {
    return Error{Errc::kInvalidArgument, "controller: set_command after shutdown"};
  }
  const struct {
    const char* name;
    double value;
  } components[] = {{"vx", request.twist.vx}, {"vy", request.twist.vy}, {"wz", request.twist.wz}};
  for (const auto& c : components) {
    if (!std::isfinite(c.value)) {
      // A NaN is a caller bug, not a wish to keep driving the previous command: stop.
      state_.requested = MotionRequest{};
      state_.has_command = true;
      state_.last_command_time = now;
      state_.cmd_timed_out = false;
      command_changed_ = true;
      return Error{Errc::kNotFinite, std::string("controller: command ") + c.name + " is " +
                                         (std::isnan(c.value) ? "NaN" : "infinite") + "; stopping"};
    }
  }
  if (request.mode && !known_motion_mode(static_cast<std::uint8_t>(*request.mode))) {
    return Error{Errc::kInvalidArgument, "controller: unknown motion mode " +
                                             std::to_string(static_cast<int>(*request.mode))};
  }
  state_.requested = request;
  state_.has_command = true;
  state_.last_command_time = now;
  state_.cmd_timed_out = false;
  command_changed_ = true;
  return ok_status();
}

void ChassisController::request_motion_mode(std::optional<MotionMode> mode, Timestamp now) {
  state_.now = now;
  if (mode && !known_motion_mode(static_cast<std::uint8_t>(*mode))) return;
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

void ChassisController::shutdown(Timestamp now) {
  if (state_.shut_down) return;
  state_.now = now;
  send_motion(MotionCommand{}, now);  // stop, whatever the state: a zero 0x111 never hurts
  state_.shut_down = true;
  state_.mode_switch_phase = ModeSwitchPhase::kIdle;
  state_.mode_switch_target.reset();
  state_.limited = BodyTwist{};
}

// ---- the periodic state machine ---------------------------------------------------------------

void ChassisController::tick(Timestamp now) {
  if (state_.shut_down) return;
  state_.now = now;
  update_link(now);
  run_control_mode(now);
  run_ultrasonic(now);
  run_motion(now);
  update_faults();
}

Timestamp ChassisController::next_tick_due() const {
  Timestamp due = state_.now + config_.keep_alive_period;
  auto earlier = [&due](Timestamp t) { due = std::min(due, t); };
  if (state_.control_mode == ControlMode::kCan) earlier(next_keep_alive_);
  if (state_.awaiting_command_mode) earlier(next_control_request_);
  if (state_.link == LinkState::kConnected) earlier(last_status_time_ + config_.link_timeout);
  if (state_.has_command && !state_.cmd_timed_out) {
    earlier(state_.last_command_time + config_.cmd_timeout);
  }
  if (state_.ultrasonic_requested) earlier(ultrasonic_sent_ + config_.ultrasonic_confirm_timeout);
  if (state_.mode_switch_phase == ModeSwitchPhase::kAwaitingConfirmation) {
    earlier(mode_switch_sent_ + config_.mode_switch_timeout);
  }
  return std::max(due, state_.now);
}

void ChassisController::update_link(Timestamp now) {
  if (state_.link == LinkState::kConnected && now - last_status_time_ > config_.link_timeout) {
    state_.link = LinkState::kStale;
    ++state_.counters.link_losses;
    state_.awaiting_command_mode = false;
    selector_.reset();
    cancel_mode_switch();
    command_changed_ = true;
  }
}

void ChassisController::run_control_mode(Timestamp now) {
  if (!config_.auto_command_mode || state_.link != LinkState::kConnected) return;
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

MotionRefusal ChassisController::evaluate_refusal(Timestamp) const {
  if (state_.link != LinkState::kConnected) return MotionRefusal::kLinkLost;
  if (state_.control_mode == ControlMode::kRemote) return MotionRefusal::kRemote;
  if (state_.control_mode != ControlMode::kCan) return MotionRefusal::kStandby;
  if (state_.estop) return MotionRefusal::kEstop;
  if (state_.critical_error) return MotionRefusal::kCriticalError;
  if (state_.low_battery) return MotionRefusal::kLowBattery;
  if (!state_.motion_mode) return MotionRefusal::kModeUnknown;
  if (state_.cmd_timed_out) return MotionRefusal::kCmdTimeout;
  return MotionRefusal::kNone;
}

bool ChassisController::at_standstill(Timestamp now) const {
  const ChassisFeedback& fb = state_.feedback;
  auto fresh = [&](Timestamp received) { return now - received <= config_.link_timeout; };
  if (fb.wheel_speeds && fresh(fb.wheel_speeds->received)) {
    const auto& speeds = fb.wheel_speeds->value.speeds;
    return std::all_of(speeds.begin(), speeds.end(),
                       [&](double s) { return std::fabs(s) <= config_.standstill_speed; });
  }
  if (fb.motion && fresh(fb.motion->received)) {
    return std::fabs(fb.motion->value.speed) <= config_.standstill_speed;
  }
  return false;  // no fresh feedback: standstill cannot be confirmed
}

void ChassisController::cancel_mode_switch() {
  state_.mode_switch_phase = ModeSwitchPhase::kIdle;
  state_.mode_switch_target.reset();
  state_.mode_switch_attempts = 0;
}

void ChassisController::run_motion(Timestamp now) {
  // 1. The caller's command timeout.
  if (state_.has_command && !state_.cmd_timed_out &&
      now - state_.last_command_time >= config_.cmd_timeout) {
    state_.cmd_timed_out = true;
    ++state_.counters.cmd_timeouts;
    command_changed_ = true;
  }

  // 2. Everything that forbids motion except a mode switch.
  MotionRefusal refusal = evaluate_refusal(now);
  const bool may_drive = refusal == MotionRefusal::kNone && state_.has_command;

  // 3. Motion-mode switching: decide the wanted mode, then stop -> 0x141 -> confirmation.
  bool send_mode_command = false;
  if (!may_drive) {
    cancel_mode_switch();  // nothing to drive (or not allowed to): no reason to switch
  } else {
    const MotionMode current = *state_.motion_mode;
    MotionMode wanted = current;
    if (state_.requested.mode) {
      wanted = *state_.requested.mode;
    } else if (state_.mode_override) {
      wanted = *state_.mode_override;
    } else {
      wanted = selector_.select(state_.requested.twist, current, now);
    }
    switch (state_.mode_switch_phase) {
      case ModeSwitchPhase::kIdle:
        if (wanted != current) {
          state_.mode_switch_phase = ModeSwitchPhase::kStopping;
          state_.mode_switch_target = wanted;
          state_.mode_switch_attempts = 0;
          command_changed_ = true;
        }
        break;
      case ModeSwitchPhase::kStopping:
        if (wanted == current) {
          cancel_mode_switch();
          command_changed_ = true;
        } else {
          state_.mode_switch_target = wanted;
        }
        break;
      case ModeSwitchPhase::kAwaitingConfirmation:
        if (now - mode_switch_sent_ >= config_.mode_switch_timeout) {
          ++state_.counters.mode_switch_timeouts;
          if (state_.mode_switch_attempts >= config_.mode_switch_max_attempts) {
            state_.mode_switch_failed = true;
          }
          send_mode_command = true;  // retry at the timeout's (bounded) rate
        }
        break;
    }
    if (state_.mode_switch_phase == ModeSwitchPhase::kStopping && at_standstill(now)) {
      state_.mode_switch_phase = ModeSwitchPhase::kAwaitingConfirmation;
      send_mode_command = true;
    }
  }
  if (refusal == MotionRefusal::kNone &&
      (state_.chassis_switching || state_.mode_switch_phase != ModeSwitchPhase::kIdle)) {
    refusal = MotionRefusal::kSwitching;
  }
  if (refusal != state_.refusal) command_changed_ = true;
  state_.refusal = refusal;

  // 4. The 0x111 to send: the limited request in the chassis's mode, or zero.
  MotionCommand command{};
  if (refusal == MotionRefusal::kNone && state_.has_command) {
    const double dt = limiter_started_ ? seconds(now - last_limit_time_) : 0.0;
    const BodyTwist& target = state_.requested.twist;
    const BodyTwist previous = state_.limited;
    state_.limited = BodyTwist{limiter_vx_.limit(target.vx, previous.vx, dt),
                               limiter_vy_.limit(target.vy, previous.vy, dt),
                               limiter_wz_.limit(target.wz, previous.wz, dt)};
    Result<KinematicsSolution> solution =
        selector_.solve(state_.limited, *state_.motion_mode, config_.geometry, config_.limits);
    if (solution) {
      command = solution->command;
      state_.last_solution = *solution;
    } else {
      state_.last_error = solution.error().message;
      state_.limited = BodyTwist{};
    }
  } else {
    state_.limited = BodyTwist{};  // refusals stop at once; the limiter restarts from zero
  }
  limiter_started_ = true;
  last_limit_time_ = now;

  // 5. Keep-alive / prompt send, only while the chassis is (last known) in CAN command mode:
  // in standby it ignores 0x111, and under remote control the host stays silent.
  if (state_.control_mode == ControlMode::kCan) {
    const bool scheduled = now >= next_keep_alive_;
    const bool prompt =
        command_changed_ && now - state_.last_motion_command_time >= config_.min_command_interval;
    if (scheduled || prompt || !state_.last_motion_command) {
      send_motion(command, now);
      command_changed_ = false;
      next_keep_alive_ = scheduled && next_keep_alive_ + config_.keep_alive_period > now
                             ? next_keep_alive_ + config_.keep_alive_period
                             : now + config_.keep_alive_period;
    }
  }

  // 6. The mode command goes after the zero 0x111 of this tick.
  if (send_mode_command && state_.mode_switch_target) {
    ++state_.mode_switch_attempts;
    ++state_.counters.mode_switch_requests;
    mode_switch_sent_ = now;
    send(MotionModeCommand{*state_.mode_switch_target}, now);
  }
}

// ---- output and bookkeeping --------------------------------------------------------------------

bool ChassisController::send(const Message& message, Timestamp now) {
  Result<CanFrame> frame = encode(message);
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
  return true;
}

void ChassisController::send_motion(const MotionCommand& command, Timestamp now) {
  state_.last_motion_command = command;
  state_.last_motion_command_time = now;
  if (send(command, now)) ++state_.counters.motion_commands_sent;
}

void ChassisController::update_faults() {
  // Rebuilt only when an input changes: 0x211 arrives 50 times a second.
  const std::uint64_t signature =
      static_cast<std::uint64_t>(state_.error_bits) |
      (static_cast<std::uint64_t>(state_.link == LinkState::kStale) << 32) |
      (static_cast<std::uint64_t>(state_.estop) << 33) |
      (static_cast<std::uint64_t>(state_.vehicle_status == protocol::VehicleStatus::kAbnormal)
       << 34) |
      (static_cast<std::uint64_t>(state_.low_battery) << 35) |
      (static_cast<std::uint64_t>(state_.mode_switch_failed) << 36) |
      (static_cast<std::uint64_t>(state_.ultrasonic_failed) << 37) |
      (static_cast<std::uint64_t>(state_.feedback.system_status.has_value() &&
                                  !state_.vehicle_status.has_value())
       << 38);
  if (faults_valid_ && signature == faults_signature_) return;
  faults_valid_ = true;
  faults_signature_ = signature;
  std::vector<std::string> faults;
  if (state_.link == LinkState::kStale) faults.emplace_back("link_lost");
  if (state_.estop) faults.emplace_back("emergency_stop");
  if (state_.vehicle_status == protocol::VehicleStatus::kAbnormal) {
    faults.emplace_back("vehicle_abnormal");
  }
  if (state_.feedback.system_status && !state_.vehicle_status) {
    faults.emplace_back("vehicle_status_unknown");
  }
  for (std::string& name : protocol::error_bit_names(state_.error_bits)) {
    faults.push_back(std::move(name));
  }
  if (state_.low_battery) faults.emplace_back("low_battery");
  if (state_.mode_switch_failed) faults.emplace_back("motion_mode_switch_failed");
  if (state_.ultrasonic_failed) faults.emplace_back("ultrasonic_setting_unconfirmed");
  state_.faults = std::move(faults);
}

}  // namespace ranger
