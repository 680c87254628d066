// The chassis controller: the driver's state machine between a caller that wants a body twist
// and a RANGER chassis on a Bus.
//
// Single-threaded and clock-free: the owner feeds received frames (on_frame), wanted motion
// (set_command) and the time (every call takes `now`, from the owner's monotonic clock), and
// calls tick(now) at next_tick_due() (or more often); tick sends whatever is due. Nothing inside
// sleeps, spawns threads or reads a clock. The owner serialises calls (control/driver.hpp does).
// The Bus must outlive the controller. Every frame it sends is reported to the send observer,
// the stop on shutdown included.
//
// Behaviour:
//  * Link: connected while 0x211 arrives; stale after `link_timeout` without it, or at once when
//    the bus reports bus-off; reconnects by itself when 0x211 returns.
//  * Control mode: while 0x211 reports standby, requests CAN command mode (0x421 = 0x01) at most
//    every `control_mode_retry_period` until 0x211 confirms (unless auto_command_mode = false).
//    Remote control is never fought and is final: once the chassis has reported remote mode
//    (0x03), the controller never requests CAN mode by itself again (unless
//    auto_reclaim_after_remote); control comes back by resume(), or when the operator hands back
//    with SWB (the chassis reports CAN mode itself) — and motion then still needs the re-arm.
//  * Re-arm (rearm.hpp): after any stop the commander did not ask for (e-stop, remote takeover,
//    a critical error, the low-battery cut-off, link loss, a failed mode switch, implausible
//    feedback) motion stays refused (kRearmRequired) until resume() after the cause has cleared
//    (a zero twist too only with the opt-in rearm_on_zero_twist).
//  * Keep-alive: while the chassis is in CAN command mode, 0x111 goes out every
//    `keep_alive_period` (zero whenever motion is refused), on a fixed-rate schedule. A changed
//    command goes out at once, at most one per `min_command_interval` (keep-alives do not count).
//  * Command timeout: no set_command for `cmd_timeout` -> zero command, reported
//    (kCmdTimeout); the next set_command resumes (the commander's own stop: no re-arm needed).
//  * Motion-mode switch (0x141) only at standstill (mode_switch.hpp).
//  * Steer first: in Ackermann and oblique mode, while the measured wheel angles (0x271) are
//    further than `steer_first_threshold` from the commanded ones, the speed is scaled down (to
//    zero at twice the threshold) and the new steering is commanded: a sideways request never
//    rolls the chassis forwards while its wheels turn.
//  * A twist below the chassis's resolution is refused by name (kBelowMinimum), never dropped
//    silently; a twist with a NaN or an infinity in any of its six components is refused by name
//    (kInvalidCommand) and stops the chassis, for as long as such twists keep coming.
//  * Faults: named in state().faults; those that stop the chassis are the refusal reason.
//  * Shutdown (or destruction): a zero 0x111 before the bus is released.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/mode_selector.hpp"
#include "ranger_can/control/mode_switch.hpp"
#include "ranger_can/control/rearm.hpp"
#include "ranger_can/control/speed_limiter.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "ranger_can/wire/vehicle_spec.hpp"

namespace ranger {

// The three components of a full twist a planar base cannot drive (a ROS Twist's linear.z,
// angular.x, angular.y): ignored, except that a NaN or an infinity in one of them refuses the
// whole request like one in the planar twist (the caller's bug all the same).
struct OutOfPlaneTwist {
  double vz = 0.0;  // m/s (linear.z)
  double wx = 0.0;  // rad/s (angular.x)
  double wy = 0.0;  // rad/s (angular.y)
};

// What the caller wants: a REP-103 body twist, optionally in a forced motion mode.
struct MotionRequest {
  MotionRequest() = default;
  MotionRequest(const BodyTwist& twist_, std::optional<protocol::MotionMode> mode_ = std::nullopt,
                const OutOfPlaneTwist& out_of_plane_ = {})
      : twist(twist_), mode(mode_), out_of_plane(out_of_plane_) {}

  BodyTwist twist;
  std::optional<protocol::MotionMode> mode;  // nullopt: automatic (ModeSelector)
  OutOfPlaneTwist out_of_plane;              // checked for NaN/inf only
  // How old the command was when it was handed over (a stamped twist: the front end's clock now
  // minus its stamp); nullopt: unstamped, or a zero stamp ("now"). Older than cmd_timeout: not
  // obeyed (MotionRefusal::kStaleCommand), as a command that old must not drive.
  std::optional<std::chrono::nanoseconds> age;
};

// kNotFinite naming the first component (by its twist name, "linear.z", "angular.x", ...) that
// is NaN or infinite, in the order linear x, y, z, angular x, y, z; ok otherwise.
Status check_finite(const MotionRequest& request);

// Why the chassis is not being commanded the requested motion, most fundamental first.
enum class MotionRefusal {
  kNone,              // commanding the request (or idle: nothing was ever requested)
  kLinkLost,          // no 0x211 within link_timeout (or never)
  kRemote,            // the remote control has the chassis (0x211 control mode 0x03)
  kEstop,             // 0x211 vehicle status emergency stop
  kCriticalError,     // a 0x211 error bit that stops the chassis
  kLowBattery,        // BMS SOC below low_battery_soc: the chassis cuts the drives
  kModeSwitchFailed,  // a motion-mode switch was never confirmed
  kImplausible,       // the chassis's feedback contradicts the protocol settings
  kRearmRequired,     // an involuntary stop happened: resume() re-arms (rearm.hpp)
  kStandby,           // not in CAN mode: standby (CAN mode requested, or auto_command_mode =
                      // false) or UART control (agx_v2)
  kModeUnknown,       // no valid 0x291 yet: the meaning of 0x111 depends on the motion mode
  kSwitching,         // motion-mode switch in progress (ours or the remote's)
  kCmdTimeout,        // no set_command within cmd_timeout
  // The latest request was refused (ControllerState::invalid_command says why: a NaN or an
  // infinity in a component): the chassis is commanded to stop until a valid one comes.
  kInvalidCommand,
  // The latest request was stamped longer ago than cmd_timeout (MotionRequest::age;
  // ControllerState::stale_command says how old): the chassis is commanded to stop until a fresh
  // one comes.
  kStaleCommand,
  kBelowMinimum,  // the twist is below what the chassis can express (1 mm/s)
  // The driver holds motion for a purpose of its own: the protocol settings are not decided yet
  // (DriverConfig::identification: `auto`; ControllerState::identifying gives the phase), or the
  // commissioning's standstill probe runs (ControllerState::standstill_probe). No speed is
  // commanded; only the zero-speed steering probe goes out. While the identification listens
  // (quiet: the driver withholds every frame from the controller on purpose) it comes first, in
  // place of kLinkLost; otherwise after the stop causes, standby and an unknown mode (the probe
  // needs CAN mode and a known motion mode).
  kIdentifying,
  // The commander asked for park (request_park): the chassis is held in (or brought to) park
  // mode and motion is refused until park is released. After the stop causes and standby.
  kParked,
};
inline constexpr auto kMotionRefusalNames = text::enum_names<MotionRefusal>({
    {MotionRefusal::kNone, "none"},
    {MotionRefusal::kLinkLost, "link_lost"},
    {MotionRefusal::kRemote, "remote"},
    {MotionRefusal::kEstop, "estop"},
    {MotionRefusal::kCriticalError, "critical_error"},
    {MotionRefusal::kLowBattery, "low_battery"},
    {MotionRefusal::kModeSwitchFailed, "mode_switch_failed"},
    {MotionRefusal::kImplausible, "implausible_feedback"},
    {MotionRefusal::kRearmRequired, "rearm_required"},
    {MotionRefusal::kStandby, "standby"},
    {MotionRefusal::kModeUnknown, "mode_unknown"},
    {MotionRefusal::kSwitching, "switching"},
    {MotionRefusal::kCmdTimeout, "cmd_timeout"},
    {MotionRefusal::kInvalidCommand, "invalid_command"},
    {MotionRefusal::kStaleCommand, "stale_command"},
    {MotionRefusal::kBelowMinimum, "below_minimum"},
    {MotionRefusal::kIdentifying, "identifying"},
    {MotionRefusal::kParked, "parked"},
});
inline std::string_view to_string(MotionRefusal r) {
  return kMotionRefusalNames.name(r);
}

enum class LinkState { kNeverConnected, kConnected, kStale };
inline constexpr auto kLinkStateNames = text::enum_names<LinkState>({
    {LinkState::kNeverConnected, "never_connected"},
    {LinkState::kConnected, "connected"},
    {LinkState::kStale, "stale"},
});
inline std::string_view to_string(LinkState s) {
  return kLinkStateNames.name(s);
}

// The faults the controller names itself in ControllerState::faults, beside the chassis's 0x211
// faults (the fault table's names, protocol::kFaultTable, and "reserved_bit_N").
enum class ControllerFault {
  kLinkLost,               // no 0x211 within link_timeout
  kEmergencyStop,          // 0x211 vehicle status emergency stop
  kVehicleAbnormal,        // 0x211 vehicle status abnormal
  kVehicleStatusUnknown,   // a 0x211 vehicle status outside the table
  kLowBattery,             // BMS SOC below low_battery_soc
  kModeSwitchFailed,       // a motion-mode switch was never confirmed
  kImplausibleFeedback,    // the feedback contradicts the protocol settings
  kUltrasonicUnconfirmed,  // the ultrasonic setting was not confirmed by 0x45A
};
inline constexpr auto kControllerFaultNames = text::enum_names<ControllerFault>({
    {ControllerFault::kLinkLost, "link_lost"},
    {ControllerFault::kEmergencyStop, "emergency_stop"},
    {ControllerFault::kVehicleAbnormal, "vehicle_abnormal"},
    {ControllerFault::kVehicleStatusUnknown, "vehicle_status_unknown"},
    {ControllerFault::kLowBattery, "low_battery"},
    {ControllerFault::kModeSwitchFailed, "motion_mode_switch_failed"},
    {ControllerFault::kImplausibleFeedback, "implausible_feedback"},
    {ControllerFault::kUltrasonicUnconfirmed, "ultrasonic_setting_unconfirmed"},
});
inline std::string_view to_string(ControllerFault f) {
  return kControllerFaultNames.name(f);
}

struct ControllerConfig {
  VehicleGeometry geometry;
  KinematicsLimits limits;
  ModeSelectorConfig mode_selection;
  ProtocolProfile profile;  // the chassis's protocol interpretations (wire/profile.hpp)
  SpeedLimits limit_vx;     // acceleration/velocity limiting per axis, ros_controllers semantics
  SpeedLimits limit_vy;
  SpeedLimits limit_wz;

  bool auto_command_mode = true;  // request CAN command mode by itself (at start-up)
  // shutdown() also hands control back: 0x421 standby after the stop (`ranger_can commission`).
  bool release_control_on_shutdown = false;
  bool auto_reclaim_after_remote = false;  // request CAN mode by itself when the remote hands back
  // A zero twist re-arms too, once every stop cause has cleared (rearm.hpp), as resume() does.
  // Off by default: a navigation stack publishes zero twists by itself (at a goal, in recovery),
  // so a released e-stop would restart the robot without anyone deciding to. For teleop-only
  // robots whose operator sees the robot.
  bool rearm_on_zero_twist = false;
  bool listen_only = false;  // never send anything (monitoring, log replay)
  std::chrono::nanoseconds link_timeout = std::chrono::milliseconds(100);
  std::chrono::nanoseconds control_mode_retry_period = std::chrono::milliseconds(100);
  std::chrono::nanoseconds keep_alive_period = std::chrono::milliseconds(20);
  std::chrono::nanoseconds min_command_interval = std::chrono::milliseconds(5);
  std::chrono::nanoseconds cmd_timeout = std::chrono::milliseconds(500);
  std::chrono::nanoseconds mode_switch_timeout = std::chrono::milliseconds(1500);
  int mode_switch_max_attempts = 3;
  // A switch completes when the wheels (0x271) stand still (two frames within 0.005 rad) within
  // this of the new mode's angles, or mode_switch_blind_time after its 0x141 (mode_switch.hpp:
  // never on 0x291 alone).
  double mode_switch_wheel_tolerance = deg_to_rad(2.0);
  std::chrono::nanoseconds mode_switch_blind_time = std::chrono::milliseconds(580);
  std::chrono::nanoseconds mode_switch_min_time =
      std::chrono::milliseconds(100);  // at the earliest
  double standstill_speed = 0.02;      // m/s, every wheel slower than this = standstill
  // rad: full speed while every wheel is within this of its commanded angle, zero beyond twice
  // it, linear in between (0 disables steer-first).
  double steer_first_threshold = deg_to_rad(10.0);
  std::chrono::nanoseconds ultrasonic_confirm_timeout = std::chrono::milliseconds(500);
  int ultrasonic_max_attempts = 3;
  double low_battery_soc = vehicle_spec::kLowBatteryCutoffSoc;  // %: the chassis cuts the drives

  // Checks every field (durations positive, keep_alive_period < 500 ms, attempts >= 1, the
  // nested configs); the message names the field.
  Status validate() const;
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
  std::uint64_t rearms = 0;  // latch cleared by resume() (or a zero twist: rearm_on_zero_twist)
  std::uint64_t invalid_commands = 0;  // set_command refused (NaN or inf in a component)
  std::uint64_t light_commands = 0;    // 0x121
  std::uint64_t version_requests = 0;  // 0x4A1
};

struct ControllerState {
  Timestamp now{0};  // time of the last call

  // Link and control mode
  LinkState link = LinkState::kNeverConnected;
  std::optional<protocol::ControlMode> control_mode;  // last reported by 0x211
  std::uint8_t control_mode_raw = 0;
  bool awaiting_command_mode = false;  // CAN mode requested, 0x211 not yet confirming it
  bool reclaim_blocked = false;        // remote control had the chassis: no 0x421 until resume()

  // Motion mode
  std::optional<protocol::MotionMode> motion_mode;  // last valid 0x291
  bool chassis_switching = false;                   // 0x291 switching bit
  ModeSwitchStatus mode_switch;
  std::optional<protocol::MotionMode> mode_override;  // request_motion_mode()
  // The last 0x291's mode whatever it is, park and side slip included (motion_mode holds only
  // the modes this driver can command in).
  std::optional<protocol::MotionMode> chassis_mode;
  // Park (request_park): wanted by the commander; the chassis reports park (0x291, not switching).
  bool park_requested = false;
  bool parked() const { return chassis_mode == protocol::MotionMode::kPark && !chassis_switching; }

  // Vehicle status, faults and the re-arm latch
  std::optional<protocol::VehicleStatus> vehicle_status;
  std::uint32_t error_bits = 0;
  std::optional<double> battery_soc;  // % from BMS 0x361 (whole pack)
  StopCauses active_causes = 0;       // involuntary stop causes active now
  StopCauses latched_causes = 0;      // causes since the last re-arm (motion needs a re-arm)
  bool zero_twist_rearms = false;     // ControllerConfig::rearm_on_zero_twist (for the words)
  // Every active fault by stable snake_case name: the controller's own (ControllerFault) and the
  // 0x211 error bits' (protocol::error_bit_names of the profile's layout).
  std::vector<std::string> faults;

  // Commanding
  MotionRefusal refusal = MotionRefusal::kLinkLost;
  bool cmd_timed_out = false;
  bool has_command = false;  // set_command was called at least once
  MotionRequest requested;   // the last accepted request
  // Why the latest request was refused ("linear.z is NaN"), "" once a valid one came: the
  // refusal kInvalidCommand while it lasts.
  std::string invalid_command;
  // How old the latest request was and the limit ("stamped 0.8 s ago, older than cmd_vel_timeout
  // 0.5 s"), "" once a fresh one came: the refusal kStaleCommand while it lasts.
  std::string stale_command;
  Timestamp last_command_time{0};
  BodyTwist limited;  // requested twist after the speed limiters (what is driven)
  // 1 = full speed; below 1 the speed is held back until the wheels reach the commanded angle.
  double steer_first_factor = 1.0;
  std::optional<KinematicsSolution> last_solution;  // for the last motion 0x111
  // KinematicsFlag bits of the command driven now (0 while nothing is driven): how it differs
  // from the request. A component dropped only until the mode switch the selector is about to
  // make (a rotation asked of Ackermann at standstill, on its way to spin) is left out.
  std::uint32_t adjustments = 0;
  std::optional<MotionCommand> last_motion_command;  // last 0x111 sent (zero when refused)
  Timestamp last_motion_command_time{0};

  // Ultrasonic avoidance setting
  std::optional<bool> ultrasonic_enabled;    // from 0x45A
  std::optional<bool> ultrasonic_requested;  // pending set_ultrasonic target
  bool ultrasonic_failed = false;            // not confirmed after the attempts

  // Identification (set_identifying): its phase while the settings are not decided (kFailed
  // stays: the robot stays at rest), nullopt once decided or when they were given. The words for
  // it are the identification's (DriverSnapshot::identification->message), written at the edge.
  std::optional<IdentificationPhase> identifying;
  bool standstill_probe = false;  // the commissioning's standstill probe (set_standstill_probe)
  bool quiet = false;             // nothing is sent at all (set_quiet)
  std::optional<MotionCommand> probe;  // the zero-speed steering probe being commanded
  // Why the settings were found contradicted (set_implausible), naming the setting and the value
  // to try; empty otherwise.
  std::string implausible_reason;

  bool shut_down = false;
  ControllerCounters counters;
  std::string last_error;  // last send/decode error message, for diagnostics

  bool estop() const { return has(active_causes, StopCause::kEstop); }
  bool low_battery() const { return has(active_causes, StopCause::kLowBattery); }
  bool critical_error() const { return has(active_causes, StopCause::kCriticalError); }
  bool rearm_required() const { return latched_causes != 0; }
};

// Whether a twist can be driven in `mode` under `profile`: ackermann, oblique, spin, and side slip
// where the profile's mode numbering has it (MINI V1, agx_v2); never park. The controller's rule
// (ChassisController::can_drive_in), for a front end to refuse a mode by name before asking.
bool can_drive_in(protocol::MotionMode mode, const ProtocolProfile& profile);

// A frame the controller has just sent (for cmd_vel_out, latency figures and wire audits).
struct SentFrame {
  CanFrame frame;   // as on the wire (stamp = the controller's `now`)
  Message message;  // what it encodes
  // 0x111 only: the twist it realises (REP-103; zero for a stop) and the solution behind it.
  BodyTwist achieved;
  std::optional<KinematicsSolution> solution;
  // 0x111 only: how the command differs from the request (ControllerState::adjustments at the
  // send: KinematicsFlag bits, none for a mode switch's stopgap) and the request's twist.
  std::uint32_t adjustments = 0;
  BodyTwist requested;
  bool shutdown = false;  // the stop sent by shutdown()
};

// The modes can_drive_in allows under `profile`, in protocol::MotionMode's order.
std::vector<protocol::MotionMode> drivable_modes(const ProtocolProfile& profile);
// kInvalidArgument unless can_drive_in(mode, profile), naming the mode, the profile's revision
// and the modes it drives ("side_slip: unsupported by protocol manual (it drives ackermann,
// oblique, spin)").
Status check_drivable(protocol::MotionMode mode, const ProtocolProfile& profile);

class ChassisController {
 public:
  using SendObserver = std::function<void(const SentFrame&)>;

  // `bus` must outlive the controller. The config should pass validate(); the ROS node and CLI
  // check it first.
  explicit ChassisController(Bus& bus, ControllerConfig config = {});
  ~ChassisController();  // shutdown() at the last known time if not done yet

  ChassisController(const ChassisController&) = delete;
  ChassisController& operator=(const ChassisController&) = delete;

  // Called after every successful send, on the caller's thread; must not call back in.
  void set_send_observer(SendObserver observer) { observer_ = std::move(observer); }

  // Feeds a received frame (any ID; error and unknown frames are counted and ignored).
  void on_frame(const CanFrame& frame, Timestamp now);
  // Feeds an already decoded message (`stamp` = its frame's timestamp).
  void on_message(const Message& message, Timestamp stamp, Timestamp now);

  // Runs the state machine and sends what is due (0x421 retries, 0x111 keep-alive or a changed
  // command, 0x141, 0x451 retries). Call at next_tick_due() (or more often).
  void tick(Timestamp now);
  // When tick() next has something to do: keep-alive, a changed command that may go now, retries,
  // timeouts (at most keep_alive_period away; `now` itself when something is due already).
  Timestamp next_tick_due() const;

  // The motion wanted from now on; refreshes the command timeout. A non-finite component (any of
  // the six: check_finite) is refused with kNotFinite, the controller stops and says so
  // (kInvalidCommand, state().invalid_command) until a valid request comes (a NaN is a caller
  // bug, not a command to keep driving). A request older than cmd_timeout (MotionRequest::age) is
  // refused with kTimeout the same way (kStaleCommand, state().stale_command). A zero twist re-arms
  // after an involuntary stop whose cause has cleared only with rearm_on_zero_twist. Sent at the
  // next tick().
  Status set_command(const MotionRequest& request, Timestamp now);
  Status set_command(const BodyTwist& twist, Timestamp now) {
    return set_command(MotionRequest{twist, std::nullopt}, now);
  }

  // Whether a twist can be driven in `mode` under the profile (the free function below).
  bool can_drive_in(protocol::MotionMode mode) const;
  // Forces every later command into `mode` (nullopt: automatic selection again); a mode
  // can_drive_in refuses is ignored.
  void request_motion_mode(std::optional<protocol::MotionMode> mode, Timestamp now);

  // Sends 0x421 once (for auto_command_mode = false, or to hand control back with kStandby).
  // kInvalidArgument for kRemote (the host cannot set it).
  Status request_control_mode(protocol::ControlMode mode, Timestamp now);

  // Sends 0x441 with `code` (protocol::ErrorClearCode, 0x00..0x10); kInvalidArgument otherwise.
  Status clear_errors(std::uint8_t code, Timestamp now);
  // Sends 0x423 (the motor drivers' drive mode, the RANGER MINI 3.0's); kInvalidArgument, naming
  // the reading, where the profile has no drive modes. 0x291 byte 2 reports the mode.
  Status set_drive_mode(protocol::DriveMode mode, Timestamp now);

  // Sends 0x451; confirmed when 0x45A reports the same, resent up to ultrasonic_max_attempts.
  Status set_ultrasonic(bool enable, Timestamp now);

  // Park (agx_v2: motion mode 0x03). on: motion is refused (kParked), the chassis is brought to
  // rest and switched to park; off: motion is allowed again and the chassis is switched out of
  // park (to the forced mode, else Ackermann) at once. kInvalidArgument ("unsupported by ...",
  // nothing changes), for on and off alike, when the profile's mode numbering has no park
  // (manual, MINI V1): a request the chassis cannot honour is never answered with success.
  Status request_park(bool on, Timestamp now);
  // Sends 0x121 once (the counter in byte 7 is the controller's). The chassis reports what it
  // does in 0x231 (feedback().light_state); a profile without lights is the caller's to refuse.
  Status set_lights(const LightCommand& lights, Timestamp now);
  // Sends the 0x4A1 version request (DLC 1) and forgets the previous answer
  // (feedback().version starts empty again).
  Status request_version(Timestamp now);

  // The explicit re-arm: clears the latch and lifts the remote's hold on CAN mode requests.
  // Refused (kInvalidArgument, naming it) while a cause is still active — nothing is sent then.
  Status resume(Timestamp now);

  // Marks the protocol settings as contradicted by the chassis's feedback (`reason` for the
  // faults list), or clears that mark (empty reason): a stop cause like any other.
  void set_implausible(std::string reason);

  // ---- identification (control/identification.hpp; the driver calls these) ----
  // While `phase` is set (the identification's phase until it decides; kFailed stays), motion is
  // refused with kIdentifying; nullopt ends it. Idempotent.
  void set_identifying(std::optional<IdentificationPhase> phase);
  // While true, motion is refused with kIdentifying for the commissioning's standstill probe
  // (set_probe gives the probe). Idempotent.
  void set_standstill_probe(bool active);
  // quiet = true: nothing at all is sent (no 0x421, no keep-alive): the identification listens
  // before it speaks. The state machine goes on; quiet = false resumes at the next tick.
  void set_quiet(bool quiet);
  // While identifying: the zero-speed probe to command instead of a stop. `mode` is switched to
  // first (at standstill, as any switch), then 0x111 goes out with zero speeds and the probe's
  // steering (manual signs, as MotionCommand). nullopt: back to the plain stop.
  void set_probe(std::optional<protocol::MotionMode> mode, std::optional<MotionCommand> command);
  // The protocol settings from now on (decided by the identification): the codec, the kinematics
  // and the error-word layout use them at once. Refused (kInvalidArgument) if they do not
  // validate; the old ones stay then.
  Status set_profile(const ProtocolProfile& profile);

  // Sends a zero 0x111 and stops commanding; later calls send nothing. Idempotent.
  void shutdown(Timestamp now);

  const ControllerState& state() const { return state_; }
  const ChassisFeedback& feedback() const { return feedback_; }
  const ControllerConfig& config() const { return config_; }

 private:
  // kInvalidArgument "FEATURE: unsupported by protocol REVISION (why)" for a command the
  // profile's chassis lacks (unsupported_feature), else ok.
  Status refuse_unsupported(const Message& command) const;
  bool send(const Message& message, Timestamp now, const KinematicsSolution* solution = nullptr,
            bool shutdown = false);
  void send_motion(const MotionCommand& command, const KinematicsSolution* solution, Timestamp now,
                   bool shutdown = false);
  void on_system_status(const SystemStatus& m, Timestamp now);
  void on_motion_mode(const MotionModeFeedback& m);
  void update_link(Timestamp now);
  void lose_link();
  void update_causes();
  void update_faults();
  MotionRefusal evaluate_refusal() const;
  bool at_standstill(Timestamp now) const;
  double steer_first_factor(const KinematicsSolution& solution, Timestamp now) const;
  std::uint32_t adjustments(const KinematicsSolution& solution) const;
  void run_control_mode(Timestamp now);
  void run_ultrasonic(Timestamp now);
  // run_motion's numbered steps (controller.cpp).
  struct MotionGate;
  void run_motion(Timestamp now);
  void check_command_timeout(Timestamp now);
  MotionGate gate_motion() const;
  protocol::MotionMode wanted_mode(const MotionGate& gate, protocol::MotionMode current,
                                   Timestamp now);
  std::optional<protocol::MotionMode> switch_mode(const MotionGate& gate, Timestamp now);
  MotionRefusal settle_refusal(MotionRefusal refusal);
  const KinematicsSolution* motion_command(MotionRefusal refusal, bool probing, Timestamp now,
                                           MotionCommand& command);
  void steer_first(KinematicsSolution& solved, Timestamp now);
  void keep_alive(const MotionCommand& command, const KinematicsSolution* solution, Timestamp now);

  Bus& bus_;
  ControllerConfig config_;
  ControllerState state_;
  ChassisFeedback feedback_;
  ModeSelector selector_;
  ModeSwitchSequencer mode_switch_;
  // Completes a confirmed switch once the wheels are at the new mode's angles (0x271), or after
  // the chassis's switch time without 0x271.
  void settle_switch(Timestamp now);
  std::optional<bool> wheels_at_switch_target(Timestamp now) const;
  std::optional<std::array<double, 4>> previous_wheel_angles_;  // the 0x271 before the last
  bool wheels_still_ = false;  // the last two 0x271 within 0.005 rad of each other
  RearmLatch latch_;
  SpeedLimiter limiter_vx_, limiter_vy_, limiter_wz_;
  SendObserver observer_;

  Timestamp last_status_time_{0};      // last 0x211 (controller clock)
  Timestamp next_control_request_{0};  // earliest time for the next 0x421 retry
  Timestamp next_keep_alive_{0};       // fixed-rate 0x111 schedule
  Timestamp last_prompt_send_{0};      // last 0x111 sent because the command changed
  bool prompt_sent_ = false;
  Timestamp last_limit_time_{0};  // previous speed-limiter step
  bool limiter_started_ = false;
  bool command_changed_ = false;  // a new request (or a new refusal) not yet sent
  Timestamp ultrasonic_sent_{0};
  int ultrasonic_attempts_ = 0;
  std::string implausible_reason_;
  std::optional<protocol::MotionMode> probe_mode_;
  bool leave_park_ = false;         // park released: switch out of it even without a command
  std::uint8_t light_counter_ = 0;  // 0x121 byte 7
  bool faults_valid_ = false;       // state_.faults matches faults_signature_
  std::uint64_t faults_signature_ = 0;
};

}  // namespace ranger
