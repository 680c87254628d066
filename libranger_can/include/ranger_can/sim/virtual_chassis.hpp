// A virtual RANGER chassis: the chassis side of every frame in the protocol, over any Bus.
//
// Deterministic core: the owner feeds received frames with on_frame(frame, now) and calls
// step(now) often (every few ms); the chassis advances its physics (chassis_model.hpp) to `now`
// and sends every feedback frame that fell due at its period (the frame-rate schedule,
// frame_schedule.hpp), each computed from the state at its due time. No clock is read and no thread
// is started here; VirtualChassisRunner (virtual_chassis_runner.hpp) adds both for the CLI and
// tests on a real interface.
//
// Behaviour (manual section 3.2; readings of the manual's gaps are marked "reading"):
//  * Boots in standby (or in remote mode if configured). In standby it obeys 0x421 only. In remote
//    mode it ignores every CAN command, 0x421 included: the remote has the highest priority.
//    In CAN command mode it obeys 0x111, 0x141, 0x421, 0x441 and 0x451.
//  * It speaks the protocol of its profile (config.profile, wire/profile.hpp): commands are decoded
//    and feedback encoded with it (units, signs, the error-word layout and its counter, the BMS
//    scale, the mode numbering, the DLC of what it sends), and its physics applies the profile's
//    geometric readings: the angle 0x111 steers and 0x221 reports in Ackermann mode
//    (steering_reference), what 0x221's speed is (feedback_speed), where the spin comes from
//    (spin_field: a wheel speed in 0x111 bytes 4-5, or a yaw rate in bytes 2-3; the other field is
//    ignored in spin mode, so the wheels turn to the spin position and nothing moves) and its sign
//    (spin_sign). Error bits are set by meaning (protocol::fault_bit of the profile's layout).
//    What a chassis sends beyond the codec is the config's too (vendor_frames, ...): the variants
//    of sim_bus_source.hpp are made of both.
//  * 0x111 acts per the current motion mode, with the signs and units of interpretation.hpp.
//    Reading: the Ackermann/oblique linear speed is the speed of the body centre.
//  * Command watchdog: 500 ms after the last 0x111 the chassis stops by itself and sets error
//    byte 6 bit 1 (host communication lost). Reading: the watchdog arms with the first 0x111 in
//    CAN mode (a host that only switched modes has not lost anything); the bit describes the link,
//    so it clears when 0x111 resumes (that 0x111 is obeyed) or on 0x441 code 0x00, which also
//    disarms the watchdog until the next 0x111.
//  * Park (agx_v2 mode 3) and side slip (MINI V1 mode 3, agx_v2 mode 4) are modes like the others
//    (chassis_model.hpp). A 0x141 park is obeyed only at standstill (reading); while parked a
//    0x111 keeps the watchdog fed and moves nothing. In side slip 0x111's lateral speed is read
//    from bytes 4-5 with the spin sign (the MINI V1's negated field), and 0x221 reports it in
//    bytes 0-1, left positive, with 90 deg as the angle (reading).
//  * Lights: chassis_lights.hpp (0x121 in CAN mode, the remote's SWA while it has the chassis).
//  * 0x141 starts a switch: the body brakes to rest, then the wheels turn to the new mode's angles
//    (over `mode_switch_duration`, or at the field's slew rate); speed commands are ignored
//    meanwhile. What 0x291 reports of it is the switch model's (switch_model.hpp: the mode being
//    left with switching = 1 throughout, the manual's reading; or the new mode at once with the
//    flag on some switches, the field's). A 0x141 naming the current mode changes nothing.
//  * 0x111's linear speed is the body centre's (interpretation point 7).
//  * 0x221: Ackermann — the front angle of the profile's steering_reference ((alpha+beta)/2 or the
//    inner wheel's) and the speed of its feedback_speed (the mean of the four wheel speeds, point
//    8, or the body centre's); oblique — the mean of the four wheel angles and of the four speeds;
//    spin — the mean of the absolute wheel angles and (point 9, as the vendor's driver expects)
//    the signed tangential wheel speed, counter-clockwise positive (spin_field wheel_speed), or
//    the yaw rate in bytes 2-3 (spin_field yaw_rate, which then carries the body's yaw rate in
//    every mode). Spin values carry the profile's spin_sign.
//  * With vendor_frames (the vendor's revision has them, the manual does not): 0x231 light state
//    (what the last 0x121 set) and 0x241 remote-control state every 20 ms, each with a counter in
//    byte 7, and an answer to every 0x4A1 version request (`version`, 8 characters a frame).
//  * It sends only the frames its profile's frame layout has (the frame table's column: a MINI
//    3.0 sends no ultrasonic frames, no battery slots 1-4) and obeys only the commands it has (the
//    others are rejected as not this chassis's).
//  * With odometer_frames (the MINI 3.0): 0x311 and 0x312, the front and the rear wheels' left
//    and right odometers (each wheel's signed rolled distance since power-on, in the profile's
//    odometer unit) every 20 ms (reading: no source gives a period).
//  * Drive modes (a frame layout with 0x423, the MINI 3.0): 0x423 in CAN mode sets the drive mode
//    (current at power-on: reading), 0x291 byte 2 reports it; the physics does not change with it.
//  * A fault word with an e-stop bit (the MINI 3.0's) sets it while the e-stop is pressed.
//  * Under the remote control (control mode remote) the operator drives, per the manual's section
//    2.3 (RemoteInput below): SWD up is dual Ackermann (left stick the speed, right stick the
//    steering) and, with the left stick centred, spin (the right stick its direction); SWD down is
//    oblique (left stick the speed, right stick the direction of travel, full deflection the
//    chassis's oblique limit: 90 deg, lateral, on a RANGER). Full deflection is the chassis's own
//    limit (MotionLimits): max_linear_speed, max_ackermann_angle, max_oblique_angle,
//    max_spin_speed; a stick within kRemoteStickDeadband of centre reads as centred. A mode the
//    sticks ask for is switched to as 0x141 would (brake to rest, turn the wheels), and the
//    chassis drives the same model as under 0x111, so 0x221/0x271/0x281/0x291 report it as they
//    report CAN driving. SWA down under the remote switches the lights off (0x231 reports both
//    lights off), up on (ChassisLights);
//    SWC in the middle enables the ultrasonic obstacle avoidance, up or down disables it. 0x241
//    (vendor_frames) reports the switches and the sticks (int8, +-100 = full deflection; stick
//    up and stick right positive).
//  * Motion is refused (the chassis brakes to rest and ignores 0x111's motion) while: not in CAN
//    mode, e-stop, a critical error bit (protocol::is_critical_error), battery under-voltage
//    (set whenever SOC < 10 %, latched until 0x441 0x09 / 0x00 finds the SOC back at >= 10 %),
//    ultrasonic avoidance triggered, host communication lost, or switching.
//  * Vehicle status (0x211 byte 0): e-stop -> emergency stop, any error bit -> abnormal.
//  * 0x45A goes out after every 0x451 and whenever the setting changes otherwise.
//
// Not thread-safe: one thread drives it (VirtualChassisRunner serialises access).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/sim/chassis_lights.hpp"
#include "ranger_can/sim/chassis_model.hpp"
#include "ranger_can/sim/drivetrain_model.hpp"
#include "ranger_can/sim/frame_schedule.hpp"
#include "ranger_can/sim/switch_model.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

// A stick within this of centre reads as centred (a real stick's dead band).
inline constexpr double kRemoteStickDeadband = 0.05;
// 0x241's int8 stick value at full deflection.
inline constexpr double kRemoteStickFullScale = 100.0;

// The remote control as its operator holds it (manual section 2.3).
struct RemoteInput {
  protocol::RemoteSwitch swa = protocol::RemoteSwitch::kUp;  // lights: up on, down off
  protocol::RemoteSwitch swc = protocol::RemoteSwitch::kUp;  // middle: ultrasonic avoidance on
  protocol::RemoteSwitch swd = protocol::RemoteSwitch::kUp;  // up: Ackermann + spin; down: oblique
  double left = 0.0;                                         // left stick, -1..1: + forward, - back
  double right = 0.0;  // right stick, -1..1: + pushed right, - pushed left
};

struct VirtualChassisConfig {
  VehicleGeometry geometry;
  MotionLimits limits;
  // How the chassis speaks and which readings its physics follows (the manual's by default).
  ProtocolProfile profile;
  // What it sends beyond the profile's codec, a chassis's signature:
  bool vendor_frames = false;                // 0x231, 0x241 every 20 ms and 0x4A1 answers (agx_v2)
  std::string version = "ranger_sim 0.1.0";  // the 0x4A1 answer (vendor_frames only)
  bool steering_angles_frame = true;         // 0x271 (false: never sent)
  bool odometer_frames = false;     // 0x311 / 0x312 front and rear wheel odometers every 20 ms
  bool spin_angle_reported = true;  // 0x221's angle in spin mode (false: 0, as at rest)
  DrivetrainConfig drivetrain;
  std::chrono::nanoseconds mode_switch_duration = std::chrono::milliseconds(500);  // fixed_duration
  // How a switch is reported and how the wheels turn (the manual's reading by default; the
  // field's for the MINI 3.0: chassis_for_model, sim_bus_source.hpp).
  SwitchModelConfig switch_model;
  // The period of each group of feedback frames (frame_schedule.hpp: the manual's by default; the
  // field's for the MINI 3.0).
  FrameRates frame_rates = manual_frame_rates();
  std::chrono::nanoseconds command_timeout =
      std::chrono::milliseconds(protocol::kChassisCommandTimeoutMs);
  double initial_soc = 90.0;         // %
  bool boot_in_remote_mode = false;  // remote control switched on with SWB in remote position
  // Ultrasonic sensors 1..8 (raw: >= 0 distance in mm, < 0 a protocol::UltrasonicCode).
  std::array<std::int16_t, protocol::kUltrasonicCount> ultrasonic{3000, 3000, 3000, 3000,
                                                                  3000, 3000, 3000, 3000};
  bool ultrasonic_enabled = false;
  std::int16_t ultrasonic_stop_distance_mm = 300;  // avoidance triggers below this (if enabled)
  std::uint32_t garbage_seed = 1;                  // the garbage-frame generator is deterministic
  // The chassis keeps its own timeline: stepped late (its thread not run for a while), it sends
  // the frames that fell due meanwhile, each stamped with its due time, as a real chassis's
  // frames wait in the kernel's queue with their reception times. A stall longer than this is
  // not replayed: the schedule resumes from now (a chassis that was truly silent, or a lock-step
  // owner that jumped its clock). Zero: five periods of each frame.
  std::chrono::nanoseconds replay_window{0};
};

// Something the chassis did that a person watching would want to know.
struct SimEvent {
  Timestamp time{0};
  std::string text;
};

// Everything observable about the chassis, for the CLI and tests.
struct ChassisSnapshot {
  Timestamp time{0};
  protocol::ControlMode control_mode = protocol::ControlMode::kStandby;
  protocol::MotionMode motion_mode = protocol::MotionMode::kAckermann;
  bool switching = false;
  protocol::MotionMode switch_target = protocol::MotionMode::kAckermann;
  protocol::VehicleStatus vehicle_status = protocol::VehicleStatus::kNormal;
  std::uint32_t error_bits = 0;
  bool emergency_stop = false;
  bool host_link_lost = false;
  bool motion_allowed = false;        // would a 0x111 move the chassis now?
  std::string motion_refused_reason;  // empty when allowed
  bool silent = false;
  bool ultrasonic_enabled = false;
  RemoteInput remote;   // the remote control's switches and sticks
  MotionTarget target;  // REP-103
  double speed = 0.0;   // model speed (see MotionTarget)
  double steering = 0.0;
  BodyTwist twist;
  WheelStates wheels{};
  Pose2D pose;                      // ground truth
  double distance_travelled = 0.0;  // m, path length of the body centre since boot
  double yaw_travelled = 0.0;       // rad, total |rotation| since boot
  BatteryTelemetry battery;
  LightState lights;  // what 0x231 reports (agx_v2 only sends it)
  protocol::DriveMode drive_mode = protocol::DriveMode::kCurrent;  // 0x291 byte 2 (mini_v3)
  // Each wheel's signed rolled distance since power-on, m (0x311/0x312), wheel order RF, RR, LR,
  // LF.
  std::array<double, 4> wheel_distance{};
};

struct VirtualChassisCounters {
  std::uint64_t frames_received = 0;  // frames handed to on_frame
  std::uint64_t frames_ignored = 0;   // valid commands the current mode does not accept
  std::uint64_t frames_rejected = 0;  // unknown IDs, bad DLC, feedback IDs, error frames
  std::uint64_t frames_sent = 0;
  std::uint64_t send_failures = 0;    // bus refused a frame (e.g. queue full)
  std::uint64_t motion_commands = 0;  // 0x111 obeyed
};

class VirtualChassis {
 public:
  // `bus` must outlive the chassis. `boot_time` is the time of power-on in the caller's clock.
  VirtualChassis(Bus& bus, const VirtualChassisConfig& config, Timestamp boot_time);

  // Handles one frame received at `now` (advancing to `now` first). Frames that are not RANGER
  // commands are counted and ignored.
  void on_frame(const CanFrame& frame, Timestamp now);
  // Advances to `now` and sends the feedback that fell due. Time never runs backwards: an
  // earlier `now` is treated as the last one.
  void step(Timestamp now);
  // Convenience: hands every frame waiting on the bus to on_frame, then steps to `now`. false when
  // the bus reported an error (other than "nothing waiting") instead of a frame.
  bool poll(Timestamp now);
  // The earliest time at which step() has something to do (a feedback frame or a timeout).
  Timestamp next_deadline() const;
  Timestamp now() const { return now_; }

  ChassisSnapshot snapshot() const;
  const ChassisModel& motion() const { return motion_; }
  const DrivetrainModel& drivetrain() const { return drivetrain_; }
  const VirtualChassisCounters& counters() const { return counters_; }
  // Events since the last call, oldest first (bounded: the oldest are dropped beyond 1000).
  std::vector<SimEvent> take_events();

  // ---- fault injection (each takes effect at the current time; call step() to see frames) ----
  // The remote control takes over (SWB to remote): control mode remote, CAN commands ignored.
  void remote_takeover();
  // SWB back up hands control to CAN command mode; `to_standby` instead models the remote being
  // switched off (standby, the host must request CAN mode again).
  void remote_hand_back(bool to_standby = false);
  // Remote control lost-connection protection: standby, error byte 7 bit 2.
  void remote_signal_lost();
  void set_emergency_stop(bool on);
  // Sets (or clears) any 0x211 error bit, by position in the error word of the profile's layout
  // (32 bits under manual32, 16 under agx16; others are ignored).
  void set_error_bit(int index, bool on);
  // The same by meaning; false (nothing changes) when the layout has no such bit.
  bool set_fault(protocol::Fault fault, bool on, int motor = 0);
  const ProtocolProfile& profile() const { return config_.profile; }
  void set_error_bits(std::uint32_t bits);  // replaces the injected set entirely
  void set_battery_soc(double soc_percent);
  // Stops sending anything (frames that fall due are skipped) until resumed / for a while.
  void set_silent(bool silent);
  void silence_for(std::chrono::nanoseconds duration);
  // Sends `count` frames a driver must reject (unknown IDs, RANGER IDs with a wrong DLC) at the
  // next step.
  void inject_garbage(int count);
  // While set, a motion-mode switch never completes (0x291 keeps switching = 1).
  void set_mode_switch_stuck(bool stuck);
  // Does what 0x441 with `code` does (0x00..0x10); false for an unknown code.
  bool clear_errors(std::uint8_t code);
  void set_ultrasonic(int sensor, std::int16_t raw);  // sensor 1..8
  void set_ultrasonic_enabled(bool enabled);          // the remote's SWC switch (no 0x451 involved)
  // The remote control's switches and sticks (RemoteInput). They drive the chassis while the
  // control mode is remote; SWC acts in every control mode (as it moves), SWA only under the
  // remote (manual).
  // Sticks are clamped to -1..1; a non-finite value reads as centred (the parsers refuse both).
  void set_remote_swa(protocol::RemoteSwitch position);
  void set_remote_swc(protocol::RemoteSwitch position);
  void set_remote_swd(protocol::RemoteSwitch position);
  void set_remote_sticks(double left, double right);
  const RemoteInput& remote() const { return remote_; }
  void set_pose(const Pose2D& pose) { motion_.set_pose(pose); }
  // The 0x4A1 answer from now on (vendor_frames only).
  void set_version(std::string version) { config_.version = std::move(version); }
  const ChassisLights& lights() const { return lights_; }

 private:
  struct Schedule {
    std::chrono::nanoseconds period;
    Timestamp next_due;
  };
  enum ScheduleId { kFast, kUltrasonic, kSlow, kBms, kScheduleCount };

  Timestamp next_timed_event() const;  // feedback due, watchdog, end of silence
  void advance_to(Timestamp t);
  void integrate(Timestamp t);
  void send_due(ScheduleId which, Timestamp t);
  void send(const Message& message, Timestamp t);
  void send_raw(CanFrame frame, Timestamp t);
  void update_conditions(Timestamp t);
  void apply_motion_policy();
  std::string refusal_reason() const;
  std::string drive_refusal() const;  // what stops any driver, CAN or remote
  void drive_by_remote();
  protocol::MotionMode remote_mode() const;
  MotionTarget remote_target() const;
  void event(std::string text);

  void handle_motion_command(const MotionCommand& cmd);
  void handle_motion_mode(const MotionModeCommand& cmd);
  // Starts a switch to `mode` (0x141 or the remote); true when one started.
  bool begin_switch(protocol::MotionMode mode);
  void handle_control_mode(const ControlModeCommand& cmd);
  void handle_ultrasonic_setting(const UltrasonicSettingCommand& cmd);
  void handle_drive_mode(const DriveModeCommand& cmd);
  // Whether `message` is a command this chassis obeys (its frame layout has it; the vendor's
  // commands only with vendor_frames).
  bool is_own_command(const Message& message, std::uint32_t id) const;
  void send_odometers(Timestamp t);
  void send_vendor_frames(Timestamp t);  // 0x231 and 0x241, each with its counter
  void answer_version_request();
  std::uint32_t bit(protocol::Fault fault, int motor = 0) const;
  void set_control_mode(protocol::ControlMode mode, const std::string& why);

  std::uint32_t error_word() const;
  protocol::VehicleStatus vehicle_status() const;
  bool ultrasonic_triggered() const;
  Message motion_feedback() const;

  Bus& bus_;
  VirtualChassisConfig config_;
  ChassisModel motion_;
  DrivetrainModel drivetrain_;
  SwitchModel switch_;
  Timestamp now_;

  protocol::ControlMode control_mode_ = protocol::ControlMode::kStandby;
  MotionTarget commanded_;  // last obeyed 0x111 in REP-103 terms
  bool watchdog_armed_ = false;
  Timestamp last_motion_command_{0};
  bool host_link_lost_ = false;
  bool emergency_stop_ = false;
  std::uint32_t latched_errors_ = 0;  // injected faults and latched conditions
  bool ultrasonic_enabled_ = false;
  std::array<std::int16_t, protocol::kUltrasonicCount> ultrasonic_{};
  bool silent_ = false;
  std::optional<Timestamp> silent_until_;
  int garbage_pending_ = 0;
  std::mt19937 garbage_rng_;
  std::array<Schedule, kScheduleCount> schedules_;
  std::uint32_t last_reported_errors_ = 0;
  std::uint8_t status_counter_ = 0;  // 0x211 byte 7 under agx16: +1 per frame
  std::uint8_t vendor_counter_ = 0;  // 0x231 / 0x241 byte 7: +1 per frame
  ChassisLights lights_;             // what 0x231 reports (0x121, the remote's SWA)
  protocol::DriveMode drive_mode_ = protocol::DriveMode::kCurrent;
  std::array<double, 4> wheel_distance_{};  // m, per wheel (RF, RR, LR, LF)
  RemoteInput remote_;                      // the remote control's switches and sticks
  std::string last_refusal_;

  VirtualChassisCounters counters_;
  std::deque<SimEvent> events_;
};

}  // namespace ranger::sim
