// Identification: which protocol settings a chassis speaks, decided from its own frames before
// anything moves.
//
// ChassisIdentifier is pure and clock-free, like the controller: the owner feeds every received
// frame (on_frame) and the time (tick), reads what to command (request()) and the result
// (status()). Nothing here sends, sleeps or reads a clock; the driver (driver.hpp, DriverConfig::
// identification) forwards the request to the controller, and `ranger_can identify`, `commission`,
// `decode` and `odom` use the same class (the last two on a log, passively: identify_log()).
//
// 1. Listening (nothing is sent): the chassis's periodic frames say what they can at rest —
//    * IDs only the vendor's revision has (0x231 light state, 0x241 remote control, 0x311
//      odometer, 0x4A1 version answers): the agx_v2 preset, else the manual's;
//    * frames longer than their layout (padding): tx_dlc 8;
//    * 0x211 byte 7 rising by one per frame: a counter, so the error word is agx16 (under the
//      manual's 32-bit word it would be a changing set of phantom motor faults); a constant byte 7
//      keeps the preset's layout;
//    * 0x211 control mode 2 (UART) and a 0x291 mode value above 2: the vendor's revision;
//    * the BMS voltage (0x361) against 0x211's battery voltage (0.1 V in both revisions): the
//      scale under which they agree (a 48 V pack reads 4.8 V under the wrong one);
//    * while the wheels roll (a log, or a remote control driving): under which 0x271 unit and sign
//      the four wheels' angles and speeds form one rigid-body motion (fit_body_twist residuals).
//    Under the remote control (0x211 control mode remote) the identification then waits for CAN
//    command mode without a timeout (counted from the hand-back instead), and goes on learning
//    the 0x271 reading from the remote's driving: the rigid-body fit as above, or the spin
//    position (below) while the remote spins. status().message says what it has and what it
//    still lacks (the 0x111 readings, probed when CAN command mode is granted);
//    wheel_angles_known() tells the driver when joint states and wheel odometry are no guess.
//    Listening ends after `listen_time` with at least `min_status_frames` 0x211 frames.
// 2. Steering probe (at standstill, zero speed, in CAN mode): what rest cannot tell.
//    * spin check (optional): after a switch to spin mode every wheel stands at
//      +-atan(wheelbase/track) (57.8 deg on a RANGER: 5780 in 0.01 deg, 1009 in 0.001 rad) with a
//      known sign pattern (REP-103: RF +, RR -, LR +, LF -): the 0x271 unit and sign;
//    * a steering angle (`probe_angle`, to the left under the proposed settings) in Ackermann mode:
//      the four 0x271 angles that come back fit exactly one combination of the 0x111 unit and sign
//      and the steering reference (the inner front wheel at the commanded angle, or the front
//      wheels' mean) — 0.01 deg and 0.001 rad differ by a factor 5.7, a wrong sign steers the other
//      way, the inner wheel stands about 6 % further out than the mean; 0x221's angle then gives
//      its own unit and sign. An answer 5.7 times smaller than asked is probed once more in the
//      corrected unit, so that the reference is judged at a useful angle;
//    * back to Ackermann, wheels straight: decided.
//    A first answer too small to judge (0.01 deg read where 0.001 rad was meant, or the reverse) is
//    probed once more in the unit it suggests.
//    Steps that get no settled 0x271 answer within `step_timeout`, or answers no combination
//    explains, fail the identification, as does `timeout` overall: the robot stays at rest and
//    status().message names the parameters to set and the commissioning command.
// Settings no frame at rest or at standstill can tell (spin field and sign, 0x221's speed
// reading, vehicle status 0x01, BMS current sign, driver status bit 6) keep the chosen preset's
// value and are listed in status().undecided; the plausibility monitors (plausibility.hpp) watch
// them while driving and `ranger_can commission` decides most of them on blocks.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

struct IdentificationConfig {
  // Listening before the first frame is sent: long enough for two BMS frames (500 ms period).
  std::chrono::nanoseconds listen_time = std::chrono::milliseconds(1200);
  int min_status_frames = 20;  // 0x211 frames heard before deciding anything (byte 7 counter)
  // The whole identification (the node's parameter `identify_timeout`): past it the robot stays
  // at rest, refused with a message that names what to set.
  std::chrono::nanoseconds timeout = std::chrono::seconds(10);
  // One probe step (a mode switch, then the wheels turning and settling) without an answer.
  std::chrono::nanoseconds step_timeout = std::chrono::seconds(3);
  // 0x271 unchanged (within one wire unit) for this long: the wheels stand.
  std::chrono::nanoseconds settle_time = std::chrono::milliseconds(300);
  // The probe's steering angle, rad (REP-103: to the left). 6 deg stays within the 40 deg
  // Ackermann range even when the chassis reads it 5.7 times larger (0.001 rad for 0.01 deg).
  double probe_angle = deg_to_rad(6.0);
  bool spin_check = true;  // switch to spin mode at standstill to read the 0x271 unit and sign
  // Accepted when the best combination explains every wheel within this (rad, plus 10 % of the
  // angle) and the second best is at least `margin` times worse.
  double angle_tolerance = deg_to_rad(2.0);
  double margin = 3.0;

  Status validate() const;  // durations > 0, probe angle in (1, 7] deg, tolerances > 0
};

enum class IdentificationPhase {
  kListening,        // nothing sent; gathering the frames' evidence
  kAwaitingControl,  // settings proposed; waiting for CAN command mode and a known motion mode
  kSpinCheck,        // spin mode at standstill: the 0x271 unit and sign
  kSteerProbe,       // a zero-speed steering angle in Ackermann mode: 0x111 unit, sign, reference
  kReturning,        // back to Ackermann, wheels straight
  kDecided,
  kFailed,
};
inline constexpr auto kIdentificationPhaseNames = text::enum_names<IdentificationPhase>({
    {IdentificationPhase::kListening, "listening"},
    {IdentificationPhase::kAwaitingControl, "awaiting_control"},
    {IdentificationPhase::kSpinCheck, "spin_check"},
    {IdentificationPhase::kSteerProbe, "steer_probe"},
    {IdentificationPhase::kReturning, "returning"},
    {IdentificationPhase::kDecided, "decided"},
    {IdentificationPhase::kFailed, "failed"},
});
inline std::string_view to_string(IdentificationPhase p) {
  return kIdentificationPhaseNames.name(p);
}

// One decided (or kept) setting and why.
struct IdentifiedSetting {
  std::string name;      // "steering_unit_271"
  std::string value;     // "millirad"
  std::string evidence;  // "spin position read 1009 1009 1009 1009: 0.001 rad"
};

struct IdentificationStatus {
  IdentificationPhase phase = IdentificationPhase::kListening;
  // The decision (kDecided), else the current proposal (the preset and what was seen so far).
  ProtocolProfile profile;
  std::string revision;  // the preset it started from: "manual" or "agx_v2"
  // Human-readable evidence, one line per observation, in the order found (for logs).
  std::vector<std::string> evidence;
  std::vector<IdentifiedSetting> decided;  // settings the evidence decided
  std::vector<std::string> undecided;      // settings kept at the preset's value
  // 0..1: the weakest margin of the decisions (1 - best/second residual; 1 for a signature that
  // admits one reading only).
  double confidence = 0.0;
  // kFailed: why, and what to set (names the parameters and the commissioning command). Else
  // one line on what is going on ("listening (0.4 s of 1.2 s)").
  std::string message;
  Timestamp started{0};   // first call (frame or tick)
  Timestamp finished{0};  // decided or failed

  bool done() const {
    return phase == IdentificationPhase::kDecided || phase == IdentificationPhase::kFailed;
  }
  bool decided_ok() const { return phase == IdentificationPhase::kDecided; }
  std::chrono::nanoseconds elapsed() const { return finished - started; }
};

// What the identification wants the controller to do now.
struct IdentificationRequest {
  bool quiet = true;  // send nothing at all (listening)
  // The settings to send with (from the end of listening on); nullopt while listening.
  std::optional<ProtocolProfile> profile;
  std::optional<protocol::MotionMode> mode;  // the mode to switch to (at standstill)
  std::optional<MotionCommand> probe;        // zero speed and a steering angle (manual signs)
};

class ChassisIdentifier {
 public:
  // `forced_revision`: start from that preset ("manual", "agx_v2") instead of deciding it; the
  // rest is identified all the same. `read_only`: a log or a listen-only bus: no probe, the
  // decision comes from the frames alone (at listen_time, or at finish()).
  explicit ChassisIdentifier(IdentificationConfig config = {}, VehicleGeometry geometry = {},
                             std::optional<std::string> forced_revision = std::nullopt,
                             bool read_only = false);

  // A received frame (any ID; error frames are ignored) at `now`.
  void on_frame(const CanFrame& frame, Timestamp now);
  // Advances the phases at `now`.
  void tick(Timestamp now);
  // For logs: decides now from whatever was seen (or fails when nothing was).
  void finish(Timestamp now);

  const IdentificationStatus& status() const { return status_; }
  IdentificationRequest request() const;
  // The owner's word on whether the probe may start: non-empty while the controller refuses
  // motion for a cause of the commander's (a re-arm pending after the remote control or a stop,
  // an e-stop). Meanwhile the identification stays in kAwaitingControl without a timeout, its
  // message saying why, instead of judging a probe that was never sent.
  void hold_probe(std::string reason) { probe_hold_ = std::move(reason); }
  // Whether the 0x271 reading (unit and sign) is decided: by the rigid-body fit of rolling wheels,
  // the spin position, or the decision. Until then joint states and wheel odometry would be
  // guesses.
  bool wheel_angles_known() const { return verdict_271_.has_value() || status_.decided_ok(); }

  // After the decision: a setting the identification could not decide (one of
  // status().undecided) found out while driving (the plausibility monitors), e.g. spin_sign = cw
  // from a spin that turned the other way. Moves it to status().decided with `evidence`; false
  // (nothing changes) for a setting that was decided, or an invalid value.
  bool adopt(std::string_view name, std::string_view value, std::string evidence);

 private:
  struct Hypothesis271 {
    AngleUnit unit;
    SteeringSign sign;
  };
  void start(Timestamp now);
  // The passive evidence, frame by frame: what only agx_v2 sends and padding (every chassis
  // frame), 0x211, 0x291, 0x361 and the rolling wheels (0x271 + 0x281).
  void observe_passive(const CanFrame& frame);
  void observe_origin(const CanFrame& frame);
  void observe_status(const CanFrame& frame);
  void observe_bms(const CanFrame& frame);
  void observe_rolling(const CanFrame& frame);
  void observe_probe(const CanFrame& frame, Timestamp now);
  // The phases, tick by tick; why the identification timed out in the phase it is in.
  std::string timeout_reason() const;
  void tick_listening(Timestamp now);
  void tick_awaiting_control(Timestamp now);
  void tick_step(Timestamp now);
  void decide_passive(Timestamp now);
  void begin_step(IdentificationPhase phase, Timestamp now);
  bool settled(Timestamp now) const;
  void evaluate_spin(Timestamp now);
  // The 0x271 reading from the spin position / the rigid-body fit of the rolling wheels; true
  // when decided (verdict_271_ set). `quiet_if_unclear`: no evidence line for an unclear result
  // (checked again and again under the remote control).
  bool judge_spin_position(const std::string& context, bool quiet_if_unclear);
  bool judge_rigid_body(bool quiet_if_unclear);
  bool under_remote() const;  // 0x211 says the remote control has the chassis
  // Under the remote control, awaiting CAN command mode: what the remote's driving tells.
  void observe_remote_driving(Timestamp now);
  void evaluate_steer(Timestamp now);
  void fail(std::string why, Timestamp now);
  void decide(Timestamp now);
  void set(ProtocolSetting setting, std::string_view value, std::string evidence);
  void note(std::string line);
  std::optional<std::array<double, 4>> wheel_angles(const CanFrame& frame, AngleUnit unit,
                                                    SteeringSign sign) const;

  IdentificationConfig config_;
  VehicleGeometry geometry_;
  std::optional<std::string> forced_revision_;
  bool read_only_;
  IdentificationStatus status_;
  bool started_ = false;
  double min_margin_ = 1.0;

  // ---- passive evidence
  std::uint64_t status_frames_ = 0;
  Timestamp first_status_{0};
  std::vector<std::string> agx_signatures_;  // what only agx_v2 sends
  std::vector<std::uint32_t> padded_ids_;    // chassis frames longer than their layout
  std::optional<std::uint8_t> last_byte7_;
  int byte7_steps_ = 0;       // consecutive 0x211 pairs
  int byte7_increments_ = 0;  // ... where byte 7 rose by one
  int byte7_changes_ = 0;     // ... where it changed at all
  bool uart_seen_ = false;
  int max_mode_raw_ = -1;
  std::optional<double> status_voltage_;  // 0x211, V
  int bms_agree_001_ = 0, bms_agree_01_ = 0, bms_frames_ = 0;
  std::optional<CanFrame> last_angles_frame_;  // 0x271
  Timestamp last_angles_time_{0};
  // rigid-body fits per 0x271 hypothesis (centideg/millirad x right/left positive)
  std::array<double, 4> rigid_residual_{};
  std::array<int, 4> rigid_impossible_{};
  int rigid_samples_ = 0;

  // ---- probe state
  IdentificationPhase step_ = IdentificationPhase::kListening;
  Timestamp step_started_{0};
  Timestamp timeout_from_{0};  // the timeout counts from here (start; the remote's hand-back)
  std::string probe_hold_;     // hold_probe()
  std::optional<std::uint8_t> control_mode_raw_;  // 0x211 byte 1
  std::optional<protocol::MotionMode> mode_;      // 0x291 under the proposal's numbering
  bool switching_ = false;
  std::optional<CanFrame> angles_;  // latest 0x271 during the step
  Timestamp angles_changed_{0};     // when its raw content last changed
  std::optional<CanFrame> motion_;  // latest 0x221 during the step
  std::optional<Hypothesis271> verdict_271_;
  double probe_wire_angle_ = 0.0;  // the probe's steering as sent (manual sign, rad, in the
                                   // proposal's unit and sign)
  int steer_probes_ = 0;
};

// Identification of a recorded log (decode, odom): every frame, then finish() at the last stamp.
// The result is status().profile; `forced_revision` as for ChassisIdentifier.
IdentificationStatus identify_log(const std::vector<CanFrame>& frames,
                                  const VehicleGeometry& geometry = {},
                                  const IdentificationConfig& config = {},
                                  std::optional<std::string> forced_revision = std::nullopt);

// The message for a chassis that could not be identified: the reason, then what to set
// (`protocol: manual` / `steering_unit_111: millirad`, the parameter `identify_timeout`) and the
// commissioning command.
std::string unidentified_message(const std::string& reason, std::chrono::nanoseconds timeout);

}  // namespace ranger
