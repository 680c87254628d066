#include "ranger_can/sim/virtual_chassis.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <type_traits>
#include <utility>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger::sim {

namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;

using protocol::Fault;
// The 0x211 error bits the chassis drives itself, by meaning (VirtualChassis::bit gives each one's
// position in the profile's layout; 0 where the layout has no such bit).

// Driver status bits of 0x261-0x268 byte 5 (protocol.hpp).
constexpr std::uint8_t kDriverSupplyLow = protocol::driver_status::kSupplyVoltageLow;
constexpr std::uint8_t kDriverMotorOverTemp = protocol::driver_status::kMotorOverTemperature;
constexpr std::uint8_t kDriverOverCurrent = protocol::driver_status::kDriverOverCurrent;
constexpr std::uint8_t kDriverOverTemp = protocol::driver_status::kDriverOverTemperature;
constexpr std::uint8_t kDriverError = protocol::driver_status::kDriverError;
constexpr std::uint8_t kDriverDisabled = protocol::driver_status::kDriverDisabled;
// BMS alarm/warning status 1: under-voltage.
constexpr std::uint8_t kBmsUnderVoltage = protocol::bms_status::kUnderVoltage;

constexpr double kLowBatteryCutoffSoc = 10.0;   // manual: under 10 % the drivers lose power
constexpr double kLowBatteryWarningSoc = 15.0;  // manual: under 15 % the lights flash
// Reading: a 0x141 park is obeyed when the body is slower than this (m/s).
constexpr double kParkStandstillSpeed = 0.01;
constexpr std::size_t kMaxEvents = 1000;

std::string names_of(std::uint32_t bits, ErrorWordLayout layout) {
  return text::join(protocol::error_bit_names(bits, layout), ",");
}

// The 0x221 / 0x111 Ackermann angle of the profile's reading, from the mean front angle the model
// keeps (REP-103 signs).
double front_angle_from_mean(double mean, const VehicleGeometry& g, SteeringReference reference) {
  if (reference == SteeringReference::kMeanFront) return mean;
  const double k = interpretation::ackermann_curvature_from_mean_angle(mean, g.wheelbase, g.track);
  return interpretation::ackermann_front_angle(k, g.wheelbase, g.track, reference);
}

std::string format_pct(double v) {
  return text::fixed(v, 1) + "%";
}

}  // namespace

VirtualChassis::VirtualChassis(Bus& bus, const VirtualChassisConfig& config, Timestamp boot_time)
    : bus_(bus),
      config_(config),
      motion_(config.geometry, config.limits),
      drivetrain_(config.drivetrain, config.initial_soc),
      switch_(config.switch_model, seconds(config.mode_switch_duration)),
      now_(boot_time),
      ultrasonic_enabled_(config.ultrasonic_enabled),
      ultrasonic_(config.ultrasonic),
      garbage_rng_(config.garbage_seed) {
  // Each schedule sends one group of the frame-rate schedule at the chassis's period for it
  // (frame_schedule.hpp; send_due).
  schedules_[kFast] = {config.frame_rates.of(FrameGroup::kFast), boot_time};
  schedules_[kUltrasonic] = {config.frame_rates.of(FrameGroup::kUltrasonic), boot_time};
  schedules_[kSlow] = {config.frame_rates.of(FrameGroup::kSlow), boot_time};
  schedules_[kBms] = {config.frame_rates.of(FrameGroup::kBms), boot_time};
  control_mode_ = config.boot_in_remote_mode ? ControlMode::kRemote : ControlMode::kStandby;
  event(std::string("power on in ") + std::string(protocol::to_string(control_mode_)) +
        " mode, motion mode " + std::string(protocol::to_string(motion_.mode())) + ", battery " +
        format_pct(drivetrain_.soc()));
  update_conditions(now_);
  apply_motion_policy();
}

// ---- time -------------------------------------------------------------------------------------

Timestamp VirtualChassis::next_deadline() const {
  return garbage_pending_ > 0 ? now_ : next_timed_event();
}

Timestamp VirtualChassis::next_timed_event() const {
  Timestamp next = Timestamp::max();
  for (const auto& s : schedules_)
    next = std::min(next, s.next_due);
  if (watchdog_armed_ && !host_link_lost_ && control_mode_ == ControlMode::kCan) {
    next = std::min(next, last_motion_command_ + config_.command_timeout);
  }
  if (silent_until_) next = std::min(next, *silent_until_);
  return next;
}

void VirtualChassis::step(Timestamp now) {
  advance_to(now);
  while (garbage_pending_ > 0) {
    --garbage_pending_;
    CanFrame f;
    const bool unknown_id = (garbage_rng_() & 1u) != 0;
    if (unknown_id) {
      do {
        f.id = garbage_rng_() & 0x7FFu;
      } while (protocol::is_known_id(f.id));
      f.dlc = static_cast<std::uint8_t>(garbage_rng_() % 9);
    } else {
      const auto ids = protocol::all_ids();
      f.id = ids[garbage_rng_() % ids.size()];
      // Shorter than its layout (a longer frame is valid: its extra bytes are ignored).
      f.dlc = static_cast<std::uint8_t>(garbage_rng_() %
                                        protocol::layout_dlc(f.id, config_.profile.frame_layout));
    }
    for (int i = 0; i < f.dlc; ++i)
      f.data[i] = static_cast<std::uint8_t>(garbage_rng_());
    send_raw(f, now_);
  }
}

bool VirtualChassis::poll(Timestamp now) {
  bool ok = true;
  for (;;) {
    auto r = bus_.receive(std::chrono::nanoseconds(0));
    if (!r) {
      ok = r.error().code == Errc::kTimeout;
      break;
    }
    on_frame(*r, now);
  }
  step(now);
  return ok;
}

void VirtualChassis::advance_to(Timestamp t) {
  t = std::max(t, now_);
  // After a stall longer than the replay window, do not replay a burst of stale feedback: resume
  // the schedule from now.
  for (auto& s : schedules_) {
    const auto window = config_.replay_window.count() > 0 ? config_.replay_window : 5 * s.period;
    if (s.next_due + window < t) s.next_due = t;
  }
  for (;;) {
    const Timestamp next = next_timed_event();
    if (next > t) break;
    integrate(next);
    if (silent_until_ && *silent_until_ <= next) {
      silent_until_.reset();
      silent_ = false;
      event("silence over: sending again");
    }
    if (watchdog_armed_ && !host_link_lost_ && control_mode_ == ControlMode::kCan &&
        last_motion_command_ + config_.command_timeout <= next) {
      host_link_lost_ = true;
      commanded_.speed = 0.0;
      event("no 0x111 for " + std::to_string(config_.command_timeout.count() / 1000000) +
            " ms: host communication lost, stopping");
    }
    update_conditions(next);
    apply_motion_policy();
    for (int i = 0; i < kScheduleCount; ++i) {
      if (schedules_[i].next_due <= next) {
        send_due(static_cast<ScheduleId>(i), next);
        schedules_[i].next_due += schedules_[i].period;
      }
    }
  }
  integrate(t);
  update_conditions(t);
  apply_motion_policy();
}

void VirtualChassis::integrate(Timestamp t) {
  if (t <= now_) return;
  const double dt = seconds(t - now_);
  const bool was_switching = motion_.switching();
  const bool powered = !emergency_stop_ && (error_word() & bit(Fault::kBatteryUnderVoltage)) == 0;
  const WheelStates before = motion_.wheels();
  motion_.advance(dt);
  const WheelStates after = motion_.wheels();
  for (int i = 0; i < kWheelCount; ++i)
    wheel_distance_[i] += (before[i].speed + after[i].speed) / 2.0 * dt;
  drivetrain_.advance(dt, motion_, powered);
  now_ = t;
  if (was_switching && !motion_.switching()) {
    commanded_ = MotionTarget{};
    event("motion mode switch complete: " + std::string(protocol::to_string(motion_.mode())));
  }
}

// ---- conditions and policy --------------------------------------------------------------------

bool VirtualChassis::ultrasonic_triggered() const {
  if (!ultrasonic_enabled_) return false;
  return std::any_of(ultrasonic_.begin(), ultrasonic_.end(), [&](std::int16_t d) {
    return d >= 0 && d < config_.ultrasonic_stop_distance_mm;
  });
}

std::uint32_t VirtualChassis::bit(Fault fault, int motor) const {
  return protocol::fault_bit(fault, config_.profile.error_word, motor);
}

std::uint32_t VirtualChassis::error_word() const {
  return latched_errors_ | (host_link_lost_ ? bit(Fault::kHostCommunicationLost) : 0u) |
         (ultrasonic_triggered() ? bit(Fault::kUltrasonicTriggered) : 0u) |
         (emergency_stop_ ? bit(Fault::kEmergencyStop) : 0u);
}

protocol::VehicleStatus VirtualChassis::vehicle_status() const {
  if (emergency_stop_) {
    return config_.profile.vehicle_status_1_is_estop ? protocol::VehicleStatus::kEmergencyStop
                                                     : protocol::VehicleStatus::kAbnormal;
  }
  return error_word() != 0 ? protocol::VehicleStatus::kAbnormal : protocol::VehicleStatus::kNormal;
}

std::string VirtualChassis::refusal_reason() const {
  if (control_mode_ != ControlMode::kCan) {
    return std::string("control mode is ") + std::string(protocol::to_string(control_mode_));
  }
  if (std::string r = drive_refusal(); !r.empty()) return r;
  if (motion_.switching()) return "switching motion mode";
  if (motion_.mode() == MotionMode::kPark) return "parked";
  return {};
}

std::string VirtualChassis::drive_refusal() const {
  if (emergency_stop_) return "emergency stop";
  const std::uint32_t errors = error_word();
  const ErrorWordLayout layout = config_.profile.error_word;
  if (errors & bit(Fault::kBatteryUnderVoltage)) return "battery under-voltage: drive power cut";
  if (ultrasonic_triggered()) return "ultrasonic obstacle avoidance triggered";
  // The host link matters only to the host's commands.
  if (host_link_lost_ && control_mode_ == ControlMode::kCan) return "host communication lost";
  if (protocol::is_critical_error(errors, layout)) {
    return "critical error: " + names_of(errors, layout);
  }
  return {};
}

void VirtualChassis::update_conditions(Timestamp) {
  const std::uint32_t under_voltage = bit(Fault::kBatteryUnderVoltage);
  if (drivetrain_.soc() < kLowBatteryCutoffSoc && (latched_errors_ & under_voltage) == 0) {
    latched_errors_ |= under_voltage;
    event("battery at " + format_pct(drivetrain_.soc()) + " (< 10%): drive power cut");
  }
  const std::uint32_t errors = error_word();
  if (errors != last_reported_errors_) {
    const std::uint32_t raised = errors & ~last_reported_errors_;
    const std::uint32_t cleared = last_reported_errors_ & ~errors;
    const ErrorWordLayout layout = config_.profile.error_word;
    std::string text =
        "error bits " + text::hex(errors, protocol::error_word_bits(layout) == 16 ? 4 : 8);
    if (raised) text += " raised: " + names_of(raised, layout);
    if (cleared) {
      text += std::string(raised ? ";" : "") + " cleared: " + names_of(cleared, layout);
    }
    event(text);
    last_reported_errors_ = errors;
  }
}

void VirtualChassis::apply_motion_policy() {
  const bool remote = control_mode_ == ControlMode::kRemote;
  const std::string reason = remote ? drive_refusal() : refusal_reason();
  const std::string shown = remote && reason.empty() ? std::string("(remote)") : reason;
  if (shown != last_refusal_) {
    event(!reason.empty() ? "motion refused: " + reason
                          : (remote ? std::string("motion by the remote control")
                                    : std::string("motion allowed")));
    last_refusal_ = shown;
  }
  if (!reason.empty()) {
    commanded_.speed = 0.0;
    const bool power_cut =
        emergency_stop_ || (error_word() & bit(Fault::kBatteryUnderVoltage)) != 0;
    motion_.stop(power_cut);
  } else if (remote) {
    drive_by_remote();
  } else {
    motion_.set_target(commanded_);
  }
}

// ---- the remote control -----------------------------------------------------------------------

namespace {

double stick(double v) {
  if (!std::isfinite(v) || std::abs(v) < kRemoteStickDeadband) return 0.0;
  return std::clamp(v, -1.0, 1.0);
}

std::int8_t stick_wire(double v) {
  return static_cast<std::int8_t>(std::lround(stick(v) * kRemoteStickFullScale));
}

}  // namespace

MotionMode VirtualChassis::remote_mode() const {
  if (remote_.swd == protocol::RemoteSwitch::kDown) return MotionMode::kOblique;
  if (stick(remote_.left) != 0.0) return MotionMode::kAckermann;
  if (stick(remote_.right) != 0.0) return MotionMode::kSpin;
  // Both sticks centred: a spin stays a spin (at rest), anything else is Ackermann.
  const MotionMode heading = motion_.switching() ? motion_.switch_target() : motion_.mode();
  return heading == MotionMode::kSpin ? MotionMode::kSpin : MotionMode::kAckermann;
}

MotionTarget VirtualChassis::remote_target() const {
  const MotionLimits& l = motion_.limits();
  const double left = stick(remote_.left);
  const double right = stick(remote_.right);
  // Stick right steers right: a negative REP-103 angle, a clockwise spin.
  switch (motion_.mode()) {
    case MotionMode::kAckermann:
      return {left * l.max_linear_speed, -right * l.max_ackermann_angle};
    case MotionMode::kOblique:
      return {left * l.max_linear_speed, -right * l.max_oblique_angle};
    case MotionMode::kSpin:
      return {-right * l.max_spin_speed, 0.0};
    default:
      return {};
  }
}

void VirtualChassis::drive_by_remote() {
  const MotionMode want = remote_mode();
  const MotionMode heading = motion_.switching() ? motion_.switch_target() : motion_.mode();
  if (want != heading && begin_switch(want)) {
    event("remote control: switching motion mode " +
          std::string(protocol::to_string(motion_.mode())) + " -> " +
          std::string(protocol::to_string(want)));
  }
  motion_.set_target(remote_target());  // ignored while switching
}

void VirtualChassis::set_remote_swa(protocol::RemoteSwitch position) {
  if (position == remote_.swa) return;
  remote_.swa = position;
  event(
      "remote SWA " + std::string(protocol::to_string(position)) +
      (control_mode_ != ControlMode::kRemote ? " (no effect: SWB is not in remote position)" : ""));
  lights_.set_remote(control_mode_ == ControlMode::kRemote, remote_.swa);
  if (lights_.take_changed()) event("lights: " + describe_lights(lights_.report()));
}

void VirtualChassis::set_remote_swc(protocol::RemoteSwitch position) {
  if (position == remote_.swc) return;
  remote_.swc = position;
  event("remote SWC " + std::string(protocol::to_string(position)));
  set_ultrasonic_enabled(position == protocol::RemoteSwitch::kMiddle);
}

void VirtualChassis::set_remote_swd(protocol::RemoteSwitch position) {
  if (position == remote_.swd) return;
  remote_.swd = position;
  event("remote SWD " + std::string(protocol::to_string(position)));
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::set_remote_sticks(double left, double right) {
  remote_.left = std::isfinite(left) ? std::clamp(left, -1.0, 1.0) : 0.0;
  remote_.right = std::isfinite(right) ? std::clamp(right, -1.0, 1.0) : 0.0;
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::event(std::string text) {
  events_.push_back({now_, std::move(text)});
  while (events_.size() > kMaxEvents)
    events_.pop_front();
}

std::vector<SimEvent> VirtualChassis::take_events() {
  std::vector<SimEvent> out(events_.begin(), events_.end());
  events_.clear();
  return out;
}

// ---- received frames --------------------------------------------------------------------------

void VirtualChassis::on_frame(const CanFrame& frame, Timestamp now) {
  advance_to(now);
  ++counters_.frames_received;
  if (frame.is_error) {
    ++counters_.frames_rejected;
    return;
  }
  auto decoded = decode(frame, config_.profile);
  if (!decoded) {
    ++counters_.frames_rejected;
    return;
  }
  const Message& msg = *decoded;
  if (!is_own_command(msg, frame.id)) {  // feedback from another node (our echo), or not ours
    ++counters_.frames_rejected;
    return;
  }
  // A version request is a question, not a command: answered in every control mode.
  if (std::holds_alternative<VersionRequest>(msg)) {
    answer_version_request();
    return;
  }
  // Standby answers control-mode frames only; in remote mode the remote blocks CAN entirely.
  const bool accepted =
      control_mode_ == ControlMode::kCan ||
      (control_mode_ == ControlMode::kStandby && std::holds_alternative<ControlModeCommand>(msg));
  if (!accepted) {
    ++counters_.frames_ignored;
    return;
  }
  if (auto* m = std::get_if<MotionCommand>(&msg)) handle_motion_command(*m);
  if (auto* m = std::get_if<MotionModeCommand>(&msg)) handle_motion_mode(*m);
  if (auto* m = std::get_if<ControlModeCommand>(&msg)) handle_control_mode(*m);
  if (auto* m = std::get_if<ErrorClearCommand>(&msg)) {
    if (!clear_errors(m->code)) ++counters_.frames_ignored;
  }
  if (auto* m = std::get_if<UltrasonicSettingCommand>(&msg)) handle_ultrasonic_setting(*m);
  if (auto* m = std::get_if<DriveModeCommand>(&msg)) handle_drive_mode(*m);
  if (auto* m = std::get_if<LightCommand>(&msg)) {
    lights_.command(*m);
    if (lights_.take_changed()) event("lights: " + describe_lights(lights_.report()) + " (0x121)");
  }
  update_conditions(now_);
  apply_motion_policy();
}

bool VirtualChassis::is_own_command(const Message& msg, std::uint32_t id) const {
  const protocol::FrameInfo* row = protocol::find_frame(id);
  if (row == nullptr || row->direction == protocol::Direction::kFromChassis) return false;
  if (!row->in(config_.profile.frame_layout)) return false;  // another revision's command
  const bool vendor_command =
      std::holds_alternative<LightCommand>(msg) || std::holds_alternative<VersionRequest>(msg);
  return !std::holds_alternative<VersionResponse>(msg) &&
         (!vendor_command || config_.vendor_frames);
}

void VirtualChassis::handle_drive_mode(const DriveModeCommand& cmd) {
  if (!cmd.mode_known) {
    ++counters_.frames_ignored;
    event("0x423 with unknown drive mode " + std::to_string(cmd.mode_raw) + " ignored");
    return;
  }
  if (cmd.mode == drive_mode_) return;
  event("drive mode " + std::string(protocol::to_string(drive_mode_)) + " -> " +
        std::string(protocol::to_string(cmd.mode)) + " (0x423)");
  drive_mode_ = cmd.mode;
}

void VirtualChassis::handle_motion_command(const MotionCommand& cmd) {
  last_motion_command_ = now_;
  watchdog_armed_ = true;
  if (host_link_lost_) {
    host_link_lost_ = false;
    event("0x111 received again: host communication restored");
  }
  if (!refusal_reason().empty()) {
    ++counters_.frames_ignored;
    return;
  }
  const MotionMode mode = motion_.mode();
  const ProtocolProfile& p = config_.profile;
  const VehicleGeometry& g = motion_.geometry();
  if (mode == MotionMode::kPark) {  // parked: 0x111 keeps the link, it moves nothing
    ++counters_.frames_ignored;
    return;
  }
  if (mode == MotionMode::kSideSlip) {
    // Reading (MINI V1): the lateral speed is the spin field of bytes 4-5, with the spin sign.
    commanded_ = {interpretation::spin_ccw_from_wire(cmd.spin_speed, p), 0.0};
  } else if (mode == MotionMode::kSpin) {
    // Only the profile's spin field moves the chassis; the other one is ignored.
    const double wheel_speed =
        p.spin_field == SpinField::kYawRate
            ? interpretation::spin_wheel_speed_from_yaw_rate(
                  interpretation::spin_ccw_from_wire(cmd.yaw_rate, p), g.wheelbase, g.track)
            : interpretation::spin_ccw_from_wire(cmd.spin_speed, p);
    commanded_ = {wheel_speed, 0.0};
  } else if (mode == MotionMode::kAckermann) {
    // The angle of the profile's steering_reference, within the chassis's limit; the model keeps
    // the mean front angle of the same curvature. The curvature relates the wire's speed to the
    // body centre's.
    const double max_angle = motion_.limits().max_ackermann_angle;
    const double angle =
        std::clamp(interpretation::rep103_from_manual_command_steering(cmd.steering_angle),
                   -max_angle, max_angle);
    const double curvature = interpretation::ackermann_curvature_from_front_angle(
        angle, g.wheelbase, g.track, p.steering_reference);
    commanded_ = {interpretation::body_speed_from_command_speed(cmd.linear_speed, curvature,
                                                                g.wheelbase, g.track),
                  interpretation::ackermann_mean_front_angle(curvature, g.wheelbase, g.track)};
  } else {
    // Oblique: all wheels parallel, curvature 0.
    const double steering = interpretation::rep103_from_manual_command_steering(cmd.steering_angle);
    commanded_ = {
        interpretation::body_speed_from_command_speed(cmd.linear_speed, 0.0, g.wheelbase, g.track),
        steering};
  }
  ++counters_.motion_commands;
}

void VirtualChassis::handle_motion_mode(const MotionModeCommand& cmd) {
  if (!cmd.mode_known) {
    ++counters_.frames_ignored;
    event("0x141 with unknown motion mode " + std::to_string(cmd.mode_raw) + " ignored");
    return;
  }
  // Park only at standstill (reading: the wheels cannot lock a rolling chassis); a 0x141 park
  // while moving is ignored.
  if (cmd.mode == MotionMode::kPark && !motion_.switching() && motion_.mode() != cmd.mode &&
      std::abs(motion_.speed()) > kParkStandstillSpeed) {
    ++counters_.frames_ignored;
    event("0x141 park ignored: the chassis is moving");
    return;
  }
  if (begin_switch(cmd.mode)) {
    commanded_ = MotionTarget{};
    event("switching motion mode " + std::string(protocol::to_string(motion_.mode())) + " -> " +
          std::string(protocol::to_string(cmd.mode)));
  }
}

bool VirtualChassis::begin_switch(MotionMode mode) {
  if (!motion_.begin_mode_switch(mode, switch_.turn_profile())) return false;
  switch_.on_switch_started();
  return true;
}

void VirtualChassis::handle_control_mode(const ControlModeCommand& cmd) {
  if (cmd.mode == ControlMode::kStandby || cmd.mode == ControlMode::kCan) {
    set_control_mode(cmd.mode, "0x421");
  } else {
    ++counters_.frames_ignored;  // the host cannot select remote mode
  }
}

void VirtualChassis::set_control_mode(ControlMode mode, const std::string& why) {
  if (mode == control_mode_) return;
  event("control mode " + std::string(protocol::to_string(control_mode_)) + " -> " +
        std::string(protocol::to_string(mode)) + " (" + why + ")");
  control_mode_ = mode;
  lights_.set_remote(mode == ControlMode::kRemote, remote_.swa);
  if (lights_.take_changed()) event("lights: " + describe_lights(lights_.report()));
  commanded_.speed = 0.0;
  watchdog_armed_ = false;  // arms with the first 0x111 in CAN mode
}

void VirtualChassis::handle_ultrasonic_setting(const UltrasonicSettingCommand& cmd) {
  if (cmd.enable != ultrasonic_enabled_) {
    event(std::string("ultrasonic obstacle avoidance ") + (cmd.enable ? "enabled" : "disabled") +
          " (0x451)");
  }
  ultrasonic_enabled_ = cmd.enable;
  send(UltrasonicSettingFeedback{ultrasonic_enabled_}, now_);  // 0x451 is always answered
}

// ---- fault injection --------------------------------------------------------------------------

void VirtualChassis::remote_takeover() {
  set_control_mode(ControlMode::kRemote, "remote control took over");
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::remote_hand_back(bool to_standby) {
  if (control_mode_ != ControlMode::kRemote) return;
  set_control_mode(to_standby ? ControlMode::kStandby : ControlMode::kCan,
                   to_standby ? "remote control switched off" : "remote handed back to CAN");
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::remote_signal_lost() {
  latched_errors_ |= bit(Fault::kRemoteSignalLost);
  if (control_mode_ == ControlMode::kRemote) {
    set_control_mode(ControlMode::kStandby, "remote signal lost");
  }
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::set_emergency_stop(bool on) {
  if (on == emergency_stop_) return;
  emergency_stop_ = on;
  event(on ? "emergency stop pressed" : "emergency stop released");
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::set_error_bit(int index, bool on) {
  if (index < 0 || index >= protocol::error_word_bits(config_.profile.error_word)) return;
  const std::uint32_t b = 1u << index;
  if (b == bit(Fault::kHostCommunicationLost)) {
    host_link_lost_ = on;
  } else if (b == bit(Fault::kEmergencyStop)) {
    set_emergency_stop(on);  // the bit repeats the e-stop's state
  } else if (b == bit(Fault::kUltrasonicTriggered)) {
    // A condition, not a latch: injected by placing an obstacle in front of sensor 1.
    if (on) {
      ultrasonic_enabled_ = true;
      ultrasonic_[0] = static_cast<std::int16_t>(config_.ultrasonic_stop_distance_mm / 2);
    } else {
      for (auto& d : ultrasonic_) {
        if (d >= 0 && d < config_.ultrasonic_stop_distance_mm)
          d = config_.ultrasonic_stop_distance_mm;
      }
    }
  } else {
    latched_errors_ = on ? (latched_errors_ | b) : (latched_errors_ & ~b);
  }
  update_conditions(now_);
  apply_motion_policy();
}

bool VirtualChassis::set_fault(Fault fault, bool on, int motor) {
  const std::uint32_t b = bit(fault, motor);
  if (b == 0) return false;
  for (int i = 0; i < 32; ++i) {
    if (b == (1u << i)) set_error_bit(i, on);
  }
  return true;
}

void VirtualChassis::set_error_bits(std::uint32_t bits) {
  for (int i = 0; i < protocol::error_word_bits(config_.profile.error_word); ++i) {
    const bool want = (bits >> i) & 1u;
    if (want != (((error_word() >> i) & 1u) != 0)) set_error_bit(i, want);
  }
}

void VirtualChassis::set_battery_soc(double soc_percent) {
  drivetrain_.set_soc(soc_percent);
  event("battery set to " + format_pct(drivetrain_.soc()));
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::set_silent(bool silent) {
  if (silent == silent_ && !silent_until_) return;
  silent_ = silent;
  silent_until_.reset();
  event(silent ? "silent: no longer sending" : "silence over: sending again");
}

void VirtualChassis::silence_for(std::chrono::nanoseconds duration) {
  silent_ = true;
  silent_until_ = now_ + duration;
  event("silent for " + std::to_string(seconds(duration)) + " s");
}

void VirtualChassis::inject_garbage(int count) {
  if (count <= 0) return;
  garbage_pending_ += count;
  event("sending " + std::to_string(count) + " garbage frames");
}

void VirtualChassis::set_mode_switch_stuck(bool stuck) {
  motion_.hold_mode_switch(stuck);
  event(stuck ? "motion mode switches will not complete" : "motion mode switches complete again");
}

bool VirtualChassis::clear_errors(std::uint8_t code) {
  const ErrorWordLayout layout = config_.profile.error_word;
  std::uint32_t clear = 0;
  if (code == 0x00) {
    for (int i = 0; i < protocol::error_word_bits(layout); ++i) {
      const std::uint32_t b = 1u << i;
      if (!protocol::is_critical_error(b, layout)) clear |= b;
    }
    // The host link flag describes the link; 0x00 resets it and waits for the next 0x111.
    if (host_link_lost_) {
      host_link_lost_ = false;
      watchdog_armed_ = false;
    }
  } else if (code <= 0x08) {
    clear = bit(Fault::kMotorCommunication, code);
  } else if (code == 0x09) {
    clear = bit(Fault::kBatteryUnderVoltage);
  } else if (code == 0x0A) {
    clear = bit(Fault::kRemoteSignalLost);
  } else if (code <= 0x0E) {
    clear = bit(Fault::kSteeringCalibration, code - 0x0B + 5);
  } else if (code == 0x0F) {
    clear = bit(Fault::kOverCurrent);
  } else if (code == 0x10) {
    clear = bit(Fault::kOverTemperature);
  } else {
    return false;
  }
  latched_errors_ &= ~clear;
  event("clear errors " + text::hex(code, 2) + " (" + protocol::error_clear_description(code) +
        ")");
  // Clearing under-voltage "tries to restore power": the fault comes straight back if the SOC is
  // still below the cut-off (update_conditions re-latches it).
  update_conditions(now_);
  apply_motion_policy();
  return true;
}

void VirtualChassis::set_ultrasonic(int sensor, std::int16_t raw) {
  if (sensor < 1 || sensor > protocol::kUltrasonicCount) return;
  ultrasonic_[sensor - 1] = raw;
  update_conditions(now_);
  apply_motion_policy();
}

void VirtualChassis::set_ultrasonic_enabled(bool enabled) {
  if (enabled == ultrasonic_enabled_) return;
  ultrasonic_enabled_ = enabled;
  event(std::string("ultrasonic obstacle avoidance ") + (enabled ? "enabled" : "disabled"));
  send(UltrasonicSettingFeedback{enabled}, now_);
  update_conditions(now_);
  apply_motion_policy();
}

// ---- feedback ---------------------------------------------------------------------------------

void VirtualChassis::send_raw(CanFrame frame, Timestamp t) {
  if (silent_) return;
  frame.stamp = t;
  if (bus_.send(frame)) {
    ++counters_.frames_sent;
  } else {
    ++counters_.send_failures;
  }
}

void VirtualChassis::send(const Message& message, Timestamp t) {
  if (silent_) return;
  const protocol::FrameInfo* row = protocol::find_frame(id_of(message));
  if (row != nullptr && !row->in(config_.profile.frame_layout)) return;  // not this chassis's
  auto frame = encode(message, config_.profile);
  if (!frame) {
    ++counters_.send_failures;
    return;
  }
  send_raw(*frame, t);
}

Message VirtualChassis::motion_feedback() const {
  const WheelStates w = motion_.wheels();
  const VehicleGeometry& g = motion_.geometry();
  const ProtocolProfile& p = config_.profile;
  const BodyTwist twist = motion_.twist();
  MotionFeedback fb;
  switch (motion_.mode()) {
    case MotionMode::kAckermann: {
      // The front angle of the profile's reading, from where the front wheels stand (point 6),
      // and the speed of its feedback_speed reading (point 8).
      const double mean_front = (w[kRightFront].angle + w[kLeftFront].angle) / 2.0;
      fb.steering_angle = interpretation::manual_from_rep103_steering(
          front_angle_from_mean(mean_front, g, p.steering_reference));
      const double curvature = interpretation::ackermann_curvature_from_mean_angle(
          motion_.steering(), g.wheelbase, g.track);
      fb.speed = interpretation::ackermann_feedback_speed_from_body_speed(
          twist.vx, curvature, g.wheelbase, g.track, p.feedback_speed);
      break;
    }
    case MotionMode::kOblique: {
      double mean_angle = 0.0;
      for (const auto& s : w) {
        mean_angle += s.angle / kWheelCount;
        fb.speed += s.speed / kWheelCount;
      }
      fb.steering_angle = interpretation::manual_from_rep103_steering(mean_angle);
      break;
    }
    case MotionMode::kSideSlip:
      // Reading (the vendor's odometry integrates it at +90 deg): the lateral speed in bytes 0-1,
      // left positive, the wheels' 90 deg as the angle.
      fb.steering_angle = interpretation::manual_from_rep103_steering(M_PI / 2.0);
      fb.speed = twist.vy;
      break;
    default: {
      // Spin (and park, where nothing moves): the fixed angle (mean of |angles|) and (point 9) the
      // signed tangential speed, in the profile's spin field.
      if (config_.spin_angle_reported) {
        for (const auto& s : w)
          fb.steering_angle += std::abs(s.angle) / kWheelCount;
      }
      if (p.spin_field == SpinField::kWheelSpeed) {
        fb.speed = interpretation::spin_wire_from_ccw(
            interpretation::spin_feedback_speed_from_yaw_rate(twist.wz, g.wheelbase, g.track), p);
      }
      break;
    }
  }
  // A chassis with the yaw-rate field reports the body's yaw rate there in every mode.
  if (p.spin_field == SpinField::kYawRate) {
    fb.yaw_rate = interpretation::spin_wire_from_ccw(twist.wz, p);
  }
  return fb;
}

void VirtualChassis::send_vendor_frames(Timestamp t) {
  const ProtocolProfile& p = config_.profile;
  // 0x231 and 0x241, each with its counter.
  LightState light = lights_.report();
  if (p.light_modes == LightModes::kOnOff) {  // on/off only: no rear light, no brightness
    light.rear_mode = protocol::LightMode::kOff;
    light.front_custom = light.rear_custom = 0;
  }
  light.counter = vendor_counter_;
  send(light, t);
  // The remote control on, SWB up (command mode) unless the remote is in charge; the
  // sticks as the operator holds them (centred within the dead band).
  RemoteControlState rc;
  rc.swa = remote_.swa;
  rc.swb = control_mode_ == ControlMode::kRemote ? protocol::RemoteSwitch::kMiddle
                                                 : protocol::RemoteSwitch::kUp;
  rc.swc = remote_.swc;
  rc.swd = remote_.swd;
  rc.stick_left_v = stick_wire(remote_.left);
  rc.stick_right_h = stick_wire(remote_.right);
  rc.counter = vendor_counter_;
  send(rc, t);
  ++vendor_counter_;
}

void VirtualChassis::send_odometers(Timestamp t) {
  OdometerFeedback front, rear;
  front.left_distance = wheel_distance_[kLeftFront];
  front.right_distance = wheel_distance_[kRightFront];
  rear.rear = true;
  rear.left_distance = wheel_distance_[kLeftRear];
  rear.right_distance = wheel_distance_[kRightRear];
  send(front, t);
  send(rear, t);
}

void VirtualChassis::answer_version_request() {
  const std::string& text = config_.version;
  for (std::size_t i = 0; i < text.size(); i += 8) {
    VersionResponse v;
    v.length = static_cast<std::uint8_t>(std::min<std::size_t>(8, text.size() - i));
    std::copy_n(text.begin() + static_cast<std::ptrdiff_t>(i), v.length, v.text.begin());
    send(v, now_);
  }
}

void VirtualChassis::send_due(ScheduleId which, Timestamp t) {
  const auto& motors = drivetrain_.motors();
  const std::uint32_t errors = error_word();
  const ProtocolProfile& p = config_.profile;
  switch (which) {
    case kFast: {
      SystemStatus st;
      st.vehicle_status = vehicle_status();
      st.vehicle_status_raw = static_cast<std::uint8_t>(st.vehicle_status);
      st.control_mode = control_mode_;
      st.control_mode_raw = static_cast<std::uint8_t>(control_mode_);
      st.battery_voltage = drivetrain_.pack().voltage;
      st.error_bits = errors;
      if (p.error_word == ErrorWordLayout::kAgxV2_16) st.counter = status_counter_++;
      send(st, t);
      send(motion_feedback(), t);
      for (int n = 1; n <= protocol::kMotorCount; ++n) {
        const auto& m = motors[n - 1];
        send(MotorHighSpeedFeedback{n, m.rpm, m.current, m.position}, t);
      }
      const WheelStates w = motion_.wheels();
      SteeringAnglesFeedback angles;
      WheelSpeedsFeedback speeds;
      for (int i = 0; i < kWheelCount; ++i) {
        angles.angles[i] = interpretation::manual_from_rep103_wheel_angle(w[i].angle);
        speeds.speeds[i] = w[i].speed;
      }
      if (config_.steering_angles_frame) send(angles, t);
      send(speeds, t);
      MotionModeFeedback mm;
      const SwitchReportValue r = switch_.report(
          motion_.mode(), motion_.switching(), motion_.switch_target(), motion_.mode_switch_held());
      mm.mode = r.mode;
      mm.mode_raw = protocol::motion_mode_to_wire(mm.mode, p.mode_numbering).value_or(0);
      mm.switching = r.switching;
      mm.drive_mode = static_cast<std::uint8_t>(drive_mode_);  // where the layout has byte 2
      send(mm, t);
      if (config_.odometer_frames) send_odometers(t);
      if (config_.vendor_frames) send_vendor_frames(t);
      break;
    }
    case kUltrasonic: {
      UltrasonicFeedback a, b;
      a.first_sensor = 1;
      b.first_sensor = 5;
      for (int i = 0; i < 4; ++i) {
        a.raw[i] = ultrasonic_[i];
        b.raw[i] = ultrasonic_[i + 4];
      }
      send(a, t);
      send(b, t);
      break;
    }
    case kSlow: {
      const bool power_cut = emergency_stop_ || (errors & bit(Fault::kBatteryUnderVoltage)) != 0;
      const double voltage = drivetrain_.pack().voltage;
      for (int n = 1; n <= protocol::kMotorCount; ++n) {
        const auto& m = motors[n - 1];
        std::uint8_t status = 0;
        if (drivetrain_.soc() < kLowBatteryCutoffSoc) status |= kDriverSupplyLow;
        if (errors & bit(Fault::kOverTemperature)) status |= kDriverMotorOverTemp | kDriverOverTemp;
        if (errors & bit(Fault::kOverCurrent)) status |= kDriverOverCurrent;
        const std::uint32_t comm = bit(Fault::kMotorCommunication, n);
        if ((comm != 0 && (errors & comm)) || (errors & bit(Fault::kDriverStatusError))) {
          status |= kDriverError;
        }
        if (power_cut) status |= kDriverDisabled;
        send(MotorLowSpeedFeedback{n, voltage, m.driver_temperature, m.motor_temperature, status},
             t);
      }
      break;
    }
    case kBms: {
      auto send_battery = [&](int slot, const BatteryTelemetry& b) {
        // BatteryTelemetry counts a charge positive; the wire counts as the profile says.
        send(BmsData{slot, b.soc, b.soh, b.voltage, interpretation::bms_wire_current(-b.current, p),
                     b.temperature},
             t);
        BmsAlarm alarm;
        alarm.battery = slot;
        if (b.soc < kLowBatteryCutoffSoc) alarm.alarm1 |= kBmsUnderVoltage;
        if (b.soc < kLowBatteryWarningSoc) alarm.warning1 |= kBmsUnderVoltage;
        send(alarm, t);
      };
      send_battery(0, drivetrain_.pack());
      for (int slot = 1; slot <= drivetrain_.batteries(); ++slot) {
        send_battery(slot, drivetrain_.battery(slot));
      }
      break;
    }
    default:
      break;
  }
}

// ---- observation ------------------------------------------------------------------------------

ChassisSnapshot VirtualChassis::snapshot() const {
  ChassisSnapshot s;
  s.time = now_;
  s.control_mode = control_mode_;
  s.motion_mode = motion_.mode();
  s.switching = motion_.switching();
  s.switch_target = motion_.switch_target();
  s.vehicle_status = vehicle_status();
  s.error_bits = error_word();
  s.emergency_stop = emergency_stop_;
  s.host_link_lost = host_link_lost_;
  s.motion_refused_reason = refusal_reason();
  s.motion_allowed = s.motion_refused_reason.empty();
  s.silent = silent_;
  s.ultrasonic_enabled = ultrasonic_enabled_;
  s.remote = remote_;
  s.target = motion_.target();
  s.speed = motion_.speed();
  s.steering = motion_.steering();
  s.twist = motion_.twist();
  s.wheels = motion_.wheels();
  s.pose = motion_.pose();
  s.distance_travelled = motion_.distance_travelled();
  s.yaw_travelled = motion_.yaw_travelled();
  s.battery = drivetrain_.pack();
  s.lights = lights_.report();
  s.drive_mode = drive_mode_;
  s.wheel_distance = wheel_distance_;
  return s;
}

}  // namespace ranger::sim
