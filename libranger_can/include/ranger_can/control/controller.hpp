// The chassis controller: the driver's state machine between a caller that wants a body twist
// and a RANGER chassis on a Bus.
//
// Single-threaded and clock-free: the owner feeds received frames (on_frame), wanted motion
// (set_command) and the time (every call takes `now`, from the owner's monotonic clock, e.g.
// SteadyClock or a ManualClock in tests), and calls tick(now) from its loop; tick sends whatever
// is due. Nothing inside sleeps, spawns threads or reads a clock. The owner serialises calls (one
// thread, or a mutex around the controller). The Bus must outlive the controller.
//
// Behaviour (issue 4):
//  * Link: connected while 0x211 arrives; stale after `link_timeout` without it; reconnects by
//    itself when 0x211 returns.
//  * Control mode: while 0x211 reports standby (including right after connecting), requests CAN
//    command mode (0x421 = 0x01) at most every `control_mode_retry_period` until 0x211 confirms
//    (unless auto_command_mode = false). Remote control (0x03) is never fought: nothing but the
//    request after it hands back, and no 0x111 while the chassis is not in CAN mode.
//  * Keep-alive: while the chassis is in CAN command mode, 0x111 goes out every
//    `keep_alive_period` (zero whenever motion is refused), on a fixed-rate schedule; call tick()
//    at least twice per period or at next_tick_due(). A changed command goes out at the next
//    tick at least `min_command_interval` after the previous 0x111 (low latency, bounded rate).
//  * Command timeout: no set_command for `cmd_timeout` -> zero command, reported
//    (MotionRefusal::kCmdTimeout); the next set_command resumes.
//  * Motion-mode switch (0x141) only at standstill: command zero, wait until the wheel speeds
//    (0x281, else 0x221) are below `standstill_speed`, send 0x141, send only zero 0x111 until
//    0x291 reports the target with switching = 0; resend every `mode_switch_timeout`, and report
//    failure after `mode_switch_max_attempts`.
//  * Faults: e-stop, abnormal status, every 0x211 error bit, low battery (BMS SOC below
//    `low_battery_soc`), a failed mode switch or ultrasonic setting: named in state().faults;
//    those that stop the chassis are the MotionRefusal reason.
//  * Shutdown (or destruction): a zero 0x111 before the bus is released.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/control/speed_limiter.hpp"

namespace ranger {

// What the caller wants: a REP-103 body twist, optionally in a forced motion mode.
struct MotionRequest {
  BodyTwist twist;
  std::optional<protocol::MotionMode> mode;  // nullopt: automatic (ModeSelector)
};

// Why the chassis is not being commanded the requested motion, most fundamental first.
enum class MotionRefusal {
  kNone,           // commanding the request (or idle: nothing was ever requested)
  kLinkLost,       // no 0x211 within link_timeout (or never)
  kRemote,         // the remote control has the chassis (0x211 control mode 0x03)
  kStandby,        // chassis in standby (CAN mode requested, or auto_command_mode = false)
  kEstop,          // 0x211 vehicle status emergency stop
  kCriticalError,  // a 0x211 error bit that stops the chassis (protocol::is_critical_error)
  kLowBattery,     // BMS SOC below low_battery_soc: the chassis cuts the drives
  kModeUnknown,    // no 0x291 yet: the meaning of 0x111 depends on the motion mode
  kSwitching,      // motion-mode switch in progress (ours or the remote's)
  kCmdTimeout,     // no set_command within cmd_timeout
};
std::string_view to_string(MotionRefusal r);  // "none", "link_lost", "remote", ...

enum class LinkState { kNeverConnected, kConnected, kStale };
std::string_view to_string(LinkState s);  // "never_connected", "connected", "stale"

enum class ModeSwitchPhase {
  kIdle,                  // chassis in the wanted mode
  kStopping,              // commanding zero, waiting for standstill before sending 0x141
  kAwaitingConfirmation,  // 0x141 sent, waiting for 0x291: target mode, switching = 0
};
std::string_view to_string(ModeSwitchPhase p);  // "idle", "stopping", "awaiting_confirmation"

struct ControllerConfig {
  VehicleGeometry geometry;
  KinematicsLimits limits;
  ModeSelectorConfig mode_selection;
  SpeedLimits limit_vx;  // acceleration/velocity limiting per axis, ros_controllers semantics
  SpeedLimits limit_vy;
  SpeedLimits limit_wz;

  bool auto_command_mode = true;  // request CAN command mode by itself
  std::chrono::nanoseconds link_timeout = std::chrono::milliseconds(100);
  std::chrono::nanoseconds control_mode_retry_period = std::chrono::milliseconds(100);
  std::chrono::nanoseconds keep_alive_period = std::chrono::milliseconds(20);
  std::chrono::nanoseconds min_command_interval = std::chrono::milliseconds(5);
  std::chrono::nanoseconds cmd_timeout = std::chrono::milliseconds(500);
  std::chrono::nanoseconds mode_switch_timeout = std::chrono::milliseconds(1500);
  int mode_switch_max_attempts = 3;
  double standstill_speed = 0.02;  // m/s, every wheel slower than this = standstill
  std::chrono::nanoseconds ultrasonic_confirm_timeout = std::chrono::milliseconds(500);
  int ultrasonic_max_attempts = 3;
  double low_battery_soc = 10.0;  // %, manual: below 10 % the chassis cuts the drives

  // Checks every field (durations positive, keep_alive_period < 500 ms, attempts >= 1, the
  // nested configs); the message names the field.
  Status validate() const;
};

// A feedback message with the controller time it arrived at and the frame's own timestamp.
template <typename T>
struct Stamped {
  T value;
  Timestamp received{0};  // controller clock (`now` passed to on_frame)
  Timestamp stamp{0};     // CanFrame::stamp (bus clock)
};

// The last value of every kind of feedback the chassis sends.
struct ChassisFeedback {
  std::optional<Stamped<SystemStatus>> system_status;              // 0x211
  std::optional<Stamped<MotionFeedback>> motion;                   // 0x221
  std::optional<Stamped<MotionModeFeedback>> motion_mode;          // 0x291
  std::optional<Stamped<SteeringAnglesFeedback>> steering_angles;  // 0x271
  std::optional<Stamped<WheelSpeedsFeedback>> wheel_speeds;        // 0x281
  std::array<std::optional<Stamped<MotorHighSpeedFeedback>>, protocol::kMotorCount>
      motor_high_speed;  // 0x251..0x258, index motor - 1
  std::array<std::optional<Stamped<MotorLowSpeedFeedback>>, protocol::kMotorCount>
      motor_low_speed;  // 0x261..0x268, index motor - 1
  std::array<std::optional<Stamped<BmsData>>, protocol::kBatteryCount + 1> bms;  // 0 = pack
  std::array<std::optional<Stamped<BmsAlarm>>, protocol::kBatteryCount + 1> bms_alarm;
  std::array<std::optional<Stamped<UltrasonicFeedback>>, 2> ultrasonic;  // 0x342, 0x343
  std::optional<Stamped<UltrasonicSettingFeedback>> ultrasonic_setting;  // 0x45A
};

struct ControllerCounters {
  std::uint64_t frames_received = 0;        // data frames passed to on_frame
  std::uint64_t decode_errors = 0;          // frames the codec rejected (unknown ID, bad DLC)
  std::uint64_t error_frames = 0;           // bus error frames
  std::uint64_t frames_sent = 0;            // successful bus sends, all IDs
  std::uint64_t send_failures = 0;          // bus send or encode failed
  std::uint64_t motion_commands_sent = 0;   // 0x111
  std::uint64_t control_mode_requests = 0;  // 0x421
  std::uint64_t mode_switch_requests = 0;   // 0x141
  std::uint64_t mode_switch_timeouts = 0;
  std::uint64_t link_losses = 0;
  std::uint64_t cmd_timeouts = 0;
  std::uint64_t error_clear_requests = 0;  // 0x441
  std::uint64_t ultrasonic_requests = 0;   // 0x451
};

struct ControllerState {
  Timestamp now{0};  // time of the last call

  // Link and control mode
  LinkState link = LinkState::kNeverConnected;
  std::optional<protocol::ControlMode> control_mode;  // last reported by 0x211
  std::uint8_t control_mode_raw = 0;
  bool awaiting_command_mode = false;  // CAN mode requested, 0x211 not yet confirming it

  // Motion mode
  std::optional<protocol::MotionMode> motion_mode;  // last reported by 0x291
  bool chassis_switching = false;                   // 0x291 switching bit
  ModeSwitchPhase mode_switch_phase = ModeSwitchPhase::kIdle;
  std::optional<protocol::MotionMode> mode_switch_target;
  int mode_switch_attempts = 0;                       // 0x141 sent for the current target
  bool mode_switch_failed = false;                    // attempts exhausted without confirmation
  std::optional<protocol::MotionMode> mode_override;  // request_motion_mode()

  // Vehicle status and faults
  std::optional<protocol::VehicleStatus> vehicle_status;
  std::uint32_t error_bits = 0;
  bool estop = false;
  bool critical_error = false;
  std::optional<double> battery_soc;  // % from BMS 0x361 (whole pack)
  bool low_battery = false;
  // Every active fault by stable snake_case name: 0x211 error bit names
  // (protocol::error_bit_names), "emergency_stop", "vehicle_abnormal", "low_battery",
  // "link_lost", "motion_mode_switch_failed", "ultrasonic_setting_unconfirmed".
  std::vector<std::string> faults;

  // Commanding
  MotionRefusal refusal = MotionRefusal::kLinkLost;
  bool cmd_timed_out = false;
  bool has_command = false;  // set_command was called at least once
  MotionRequest requested;   // the last accepted request
  Timestamp last_command_time{0};
  BodyTwist limited;  // requested twist after the speed limiters (what is driven)
  std::optional<KinematicsSolution> last_solution;   // for the last motion 0x111
  std::optional<MotionCommand> last_motion_command;  // last 0x111 sent (zero when refused)
  Timestamp last_motion_command_time{0};

  // Ultrasonic avoidance setting
  std::optional<bool> ultrasonic_enabled;    // from 0x45A
  std::optional<bool> ultrasonic_requested;  // pending set_ultrasonic target
  bool ultrasonic_failed = false;            // not confirmed after the attempts

  bool shut_down = false;
  ChassisFeedback feedback;
  ControllerCounters counters;
  std::string last_error;  // last send/decode error message, for diagnostics
};

class ChassisController {
 public:
  // `bus` must outlive the controller. The config should pass validate(); the ROS node and CLI
  // check it first.
  explicit ChassisController(Bus& bus, ControllerConfig config = {});
  ~ChassisController();  // shutdown() at the last known time if not done yet

  ChassisController(const ChassisController&) = delete;
  ChassisController& operator=(const ChassisController&) = delete;

  // Feeds a received frame (any ID; error and unknown frames are counted and ignored).
  void on_frame(const CanFrame& frame, Timestamp now);
  // Feeds an already decoded message (`stamp` = its frame's timestamp).
  void on_message(const Message& message, Timestamp stamp, Timestamp now);

  // Runs the state machine and sends what is due (0x421 retries, 0x111 keep-alive, 0x141,
  // 0x451 retries). Call at least every keep_alive_period / 2, or at next_tick_due().
  void tick(Timestamp now);
  // When tick() next has something periodic to do (at most keep_alive_period away).
  Timestamp next_tick_due() const;

  // The motion wanted from now on; refreshes the command timeout. A non-finite component is
  // refused with kNotFinite and the controller stops (a NaN is a caller bug, not a command to
  // keep driving). Sent at the next tick().
  Status set_command(const MotionRequest& request, Timestamp now);
  Status set_command(const BodyTwist& twist, Timestamp now) {
    return set_command(MotionRequest{twist, std::nullopt}, now);
  }

  // Forces every later command into `mode` (nullopt: automatic selection again).
  void request_motion_mode(std::optional<protocol::MotionMode> mode, Timestamp now);

  // Sends 0x421 once (for auto_command_mode = false, or to hand control back with kStandby).
  // kInvalidArgument for kRemote (the host cannot set it).
  Status request_control_mode(protocol::ControlMode mode, Timestamp now);

  // Sends 0x441 with `code` (protocol::ErrorClearCode, 0x00..0x10); kInvalidArgument otherwise.
  Status clear_errors(std::uint8_t code, Timestamp now);

  // Sends 0x451; confirmed when 0x45A reports the same, resent up to ultrasonic_max_attempts.
  Status set_ultrasonic(bool enable, Timestamp now);

  // Sends a zero 0x111 and stops commanding; later calls send nothing. Idempotent.
  void shutdown(Timestamp now);

  const ControllerState& state() const { return state_; }
  const ControllerConfig& config() const { return config_; }

 private:
  bool send(const Message& message, Timestamp now);
  void send_motion(const MotionCommand& command, Timestamp now);
  void update_link(Timestamp now);
  void update_faults();
  MotionRefusal evaluate_refusal(Timestamp now) const;
  bool at_standstill(Timestamp now) const;
  void run_control_mode(Timestamp now);
  void run_ultrasonic(Timestamp now);
  void run_motion(Timestamp now);
  void cancel_mode_switch();

  Bus& bus_;
  ControllerConfig config_;
  ControllerState state_;
  ModeSelector selector_;
  SpeedLimiter limiter_vx_, limiter_vy_, limiter_wz_;

  Timestamp last_status_time_{0};      // last 0x211 (controller clock)
  Timestamp next_control_request_{0};  // earliest time for the next 0x421 retry
  Timestamp next_keep_alive_{0};       // fixed-rate 0x111 schedule
  Timestamp last_limit_time_{0};       // previous speed-limiter step
  bool limiter_started_ = false;
  bool command_changed_ = false;   // a new request not yet sent
  Timestamp mode_switch_sent_{0};  // last 0x141
  Timestamp ultrasonic_sent_{0};
  int ultrasonic_attempts_ = 0;
  bool faults_valid_ = false;  // state_.faults matches faults_signature_
  std::uint64_t faults_signature_ = 0;
};

}  // namespace ranger
