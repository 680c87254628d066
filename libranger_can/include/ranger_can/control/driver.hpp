// The driver runtime: everything between a program that wants a body twist and a RANGER on a bus,
// with no ROS in it. A ROS 1 node, a ROS 2 node, `ranger_can monitor`, `ranger_can scenario` and
// libranger_can/examples/ all use it as it is.
//
// One thread owns the bus, the controller, the odometry, the joint tracker and the frame
// statistics; nothing else touches them. Everything that comes in — a twist, a mode request,
// clear-errors, ultrasonic, resume — is a message in a mailbox the thread drains; everything that
// goes out is an immutable snapshot (DriverSnapshot) that other threads read without waiting for
// the driver, plus a callback for every frame sent (the stop on shutdown included). The thread
// wakes on a mailbox message or when the controller's next_tick_due() comes; received frames are
// handled in a batch at each wake-up (odometry integrates over the frames' own timestamps, so
// batching changes no estimate).
//
// Time comes from an injected Clock. Without start(), the owner drives the same runtime in
// lock-step: step(now) does one iteration (`ranger_can scenario`, tests, no sleeps anywhere).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/frame_stats.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/joint_tracker.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/transport/bus_source.hpp"
// The pack's facts (chemistry, voltage range), for programs that include nothing from wire/.
#include "ranger_can/wire/vehicle_spec.hpp"

namespace ranger {

// Where the protocol settings come from.
enum class ProtocolChoice {
  kForced,  // controller.profile as it is (a preset, --set values, a commissioning file)
  kAuto,    // identified from the chassis before anything moves (identification.hpp)
};
std::string_view to_string(ProtocolChoice c);  // "forced" / "auto"

struct DriverConfig {
  ControllerConfig controller;  // geometry, limits, protocol profile, timeouts, ...
  // kAuto: the driver listens before it sends anything, decides the settings from the chassis's
  // frames and a zero-speed steering probe, and refuses speed (kIdentifying) until then; a
  // chassis it cannot identify within identification.timeout stays at rest, the snapshot's
  // identification.message saying what to set. controller.profile is replaced by the decision,
  // except for the settings the identification only kept from its revision's preset: where
  // controller.profile is of the decided revision (a model's profile: the MINI V1's mode
  // numbering, spin field and sign), its values stand for those. kForced (the default) as before.
  ProtocolChoice protocol = ProtocolChoice::kForced;
  // kAuto only: start from this preset ("manual", "agx_v2") instead of deciding it.
  std::optional<std::string> identify_revision;
  IdentificationConfig identification;
  // The plausibility monitors (plausibility.hpp), whatever the settings came from. kAuto: a
  // mismatch of a setting the identification could not decide at rest (the spin sign, 0x221's
  // speed reading, ...) stops the robot all the same (latched: resume re-arms),
  // and the value the monitor names is adopted, so that the re-armed robot drives right.
  PlausibilityConfig plausibility;
  // Source, timeouts and covariances; its geometry and profile are the controller's (one vehicle,
  // one reading: the driver copies them).
  OdometryConfig odometry;
  // Retry period while the bus cannot be opened (an adapter not plugged in yet).
  std::chrono::nanoseconds reconnect_interval = std::chrono::seconds(1);
  // How long clear_errors waits for the chassis's answer (a 0x211 sent after the 0x441 arrived).
  std::chrono::nanoseconds request_answer_timeout = std::chrono::milliseconds(500);
  // The vendor's features (lights 0x121/0x231, the remote state 0x241, the version 0x4A1) are
  // known present as soon as the chassis sends 0x231 or 0x241, and absent once it has been heard
  // (0x211) this long without either: light requests are then refused and the version is not
  // asked for (a manual chassis never hears a frame its protocol lacks).
  std::chrono::nanoseconds vendor_frames_wait = std::chrono::milliseconds(200);
  std::string thread_name = "ranger_driver";  // for top -H and the performance script

  Status validate() const;  // the controller's, odometry's, identification's, monitors' checks
};

// What became of a request posted through the mailbox.
struct RequestOutcome {
  enum class Kind { kClearErrors, kUltrasonic, kResume, kLights, kPark, kFirmwareVersion };
  enum class State { kPending, kSent, kAnswered, kFailed };
  std::uint64_t id = 0;
  Kind kind = Kind::kResume;
  bool on = false;   // kUltrasonic, kPark: on (true) or off
  std::string what;  // for people: "clear_errors 0x00", "ultrasonic on", "lights front on, ..."
  State state = State::kPending;
  std::string message;  // why it failed, or what the answer was
  // clear_errors: the 0x211 error word the chassis reported after it received the 0x441.
  std::optional<std::uint32_t> error_word;
  Timestamp sent{0};  // driver clock
};
std::string_view to_string(RequestOutcome::Kind k);   // "clear_errors", "ultrasonic", "resume", ...
std::string_view to_string(RequestOutcome::State s);  // "pending", "sent", "answered", "failed"

// Whether the chassis speaks the vendor's additions (0x231 light state, 0x241 remote state, 0x4A1
// version answers).
enum class VendorFrames {
  kUnknown,  // not heard long enough to tell
  kPresent,  // 0x231 or 0x241 received
  kAbsent,   // heard for DriverConfig::vendor_frames_wait without either
};
std::string_view to_string(VendorFrames v);  // "unknown", "present", "absent"

// The remote control's switches and sticks (0x241), sticks and knob normalised to -1..1
// (protocol::kRemoteAxisFullScale; saturated).
struct RemoteState {
  protocol::RemoteSwitch swa = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swb = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swc = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swd = protocol::RemoteSwitch::kUndefined;
  double left_vertical = 0.0;     // + forward
  double left_horizontal = 0.0;   // + right
  double right_vertical = 0.0;    // + forward
  double right_horizontal = 0.0;  // + right
  double knob = 0.0;              // VRA
  Timestamp received{0};          // driver clock
};
RemoteState remote_state_from(const RemoteControlState& rc, Timestamp received);

// The lights as 0x231 reports them.
struct LightsState {
  bool can_control = false;  // byte 0: the lights follow CAN (0x121) commands
  protocol::LightMode front = protocol::LightMode::kOff;
  std::uint8_t front_brightness = 0;  // custom mode's brightness, 0..100
  protocol::LightMode rear = protocol::LightMode::kOff;
  std::uint8_t rear_brightness = 0;
  Timestamp received{0};  // driver clock
};

// What set_lights asks for.
struct LightsRequest {
  protocol::LightMode front = protocol::LightMode::kOn;
  std::uint8_t front_brightness = 0;  // custom mode only: 0..100
  protocol::LightMode rear = protocol::LightMode::kOn;
  std::uint8_t rear_brightness = 0;
};
// "front on, rear custom 40"
std::string describe(protocol::LightMode front, std::uint8_t front_brightness,
                     protocol::LightMode rear, std::uint8_t rear_brightness);

// The chassis's firmware version (0x4A1), asked once the chassis is heard speaking the vendor's
// revision.
struct FirmwareVersion {
  enum class State {
    kNotAsked,     // the chassis is not heard yet, or not long enough to tell
    kAsked,        // 0x4A1 request sent, the answer not complete
    kAnswered,     // `text` is the chassis's answer
    kUnanswered,   // no answer within request_answer_timeout
    kUnsupported,  // the chassis does not speak the vendor's revision (VendorFrames::kAbsent)
  };
  State state = State::kNotAsked;
  std::string text;  // the answer's frames, in order
};
std::string_view to_string(FirmwareVersion::State s);  // "not_asked", "asked", ...

// A zero-speed probe at standstill (`ranger_can commission`): the wheels stand in `mode` at
// `steering` (REP-103 rad: the front wheels' reference angle in Ackermann, the direction of travel
// in oblique mode), nothing rolls.
struct StandstillProbe {
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  double steering = 0.0;
};

// A frame the driver sent, as the observer sees it.
struct SentEvent {
  SentFrame sent;                              // frame, message, achieved twist, shutdown flag
  std::chrono::system_clock::time_point wall;  // wall time right after the send (see
                                               // set_sent_observer)
};

// A consistent copy of the runtime's state, published after every iteration. (Driver::publish
// refills snapshots no reader holds any more: it assigns every field.)
struct DriverSnapshot {
  std::uint64_t sequence = 0;  // increases with every publication
  Timestamp now{0};            // driver clock at publication

  std::string bus_name;    // the spec: "can0", "sim", "replay:FILE"
  bool bus_open = false;   // false until the first successful open
  bool read_only = false;  // a replayed log: nothing is sent
  std::string bus_error;   // why the bus is not open (while !bus_open)
  BusStatus bus;           // state, detail, counters of the open bus

  ControllerState controller;
  ChassisFeedback feedback;
  // Odometry, TF and joint states are known only while the chassis is heard: false before the
  // first frame and while the link is lost (the pose resumes from where it was).
  bool motion_known = false;
  OdometryState odometry;
  WheelJoints joints;
  FrameStats frames;
  ProtocolProfile profile;  // the settings in use (the identification's proposal until decided)

  // Where the settings came from, and (kAuto) the identification: phase, decided profile,
  // evidence lines, confidence, and the failure message naming what to set.
  ProtocolChoice protocol = ProtocolChoice::kForced;
  // (Shared between snapshots while it does not change: after the decision it rarely does.)
  std::shared_ptr<const IdentificationStatus> identification;
  // The plausibility monitors: persistent mismatches (WARN, with the value to try) and the one
  // that stopped the robot (also ControllerState::implausible_reason).
  PlausibilityStatus plausibility;

  std::vector<RequestOutcome> requests;  // the most recent ones, oldest first (at most 16)
  std::uint64_t loop_iterations = 0;

  // The vendor's additions: whether the chassis has them, the remote control's and the lights'
  // last reported state (nullopt until received), and the firmware version.
  VendorFrames vendor_frames = VendorFrames::kUnknown;
  std::optional<RemoteState> remote;
  std::optional<LightsState> lights;
  FirmwareVersion firmware;

  // The outcome of request `id`, if it is still in the list.
  const RequestOutcome* request(std::uint64_t id) const;
};

// A lights or version request the driver thread holds until it knows whether the chassis has the
// vendor's frames (internal to Driver).
struct DriverVendorAction {
  enum class Kind { kLights, kVersion } kind = Kind::kVersion;
  std::uint64_t id = 0;
  LightsRequest lights;
};

class Driver {
 public:
  using SentObserver = std::function<void(const SentEvent&)>;
  using FrameTap = std::function<void(const CanFrame&)>;

  // `source` gives the bus (opened at the first step, retried every reconnect_interval until it
  // opens); `clock` must outlive the driver. The config should pass validate().
  Driver(DriverConfig config, std::shared_ptr<BusSource> source, const Clock& clock);
  ~Driver();  // stop()
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  // Called on the driver thread (or in step()) after every frame sent, outside the driver's
  // locks; must not block (it delays the next frame): queue the event and return. Set before
  // start(). Without `wall_time` the events' wall stamp is left at the epoch (one clock read per
  // frame saved, which under emulation is a system call).
  void set_sent_observer(SentObserver observer, bool wall_time = true) {
    sent_observer_ = std::move(observer);
    sent_wall_time_ = wall_time;
  }
  // Called with every received frame (any ID), before the driver handles it. Set before start().
  void set_frame_tap(FrameTap tap) { frame_tap_ = std::move(tap); }
  // Called on the driver thread (or in step()) with the snapshot just published, after every
  // iteration, outside the driver's locks. It runs on the thread that owns the keep-alive, so it
  // must not block, publish or serialise anything: a program that publishes the state (the ROS
  // node) does that on a thread of its own, reading snapshot(), and uses this only to wake it
  // when a new snapshot is worth reading. Must not call stop(); an exception it throws is
  // swallowed. Set before start().
  using StepObserver = std::function<void(const std::shared_ptr<const DriverSnapshot>&)>;
  void set_step_observer(StepObserver observer) { step_observer_ = std::move(observer); }

  // Starts the thread. Without it the owner calls step() instead.
  void start();
  // Sends the stop (a zero 0x111, seen by the observer), then ends the thread. Idempotent; the
  // snapshot stays readable.
  void stop();

  // ---- the mailbox (any thread; never waits for the bus) ----
  // The motion wanted from now on. kNotFinite for NaN/inf in any of the six components, named
  // (the driver then commands zero and the snapshot says why: MotionRefusal::kInvalidCommand);
  // kInterfaceDown while the bus was never opened (the message says why).
  Status command(const MotionRequest& request);
  // Forces the motion mode of later commands (nullopt: automatic). kInvalidArgument, naming the
  // modes it drives, for a mode the settings in use cannot drive (check_drivable): nothing is
  // posted then.
  Status set_motion_mode(std::optional<protocol::MotionMode> mode);
  // kInvalidArgument (nothing posted) for a code outside 0x00..0x10; else the request's id.
  Result<std::uint64_t> clear_errors(std::uint8_t code);
  std::uint64_t set_ultrasonic(bool enable);
  // Also clears a plausibility stop (the operator takes it on): the monitors start over.
  std::uint64_t resume();
  // Lights (0x121). Answered with the state 0x231 reports once it matches the request; failed
  // ("unsupported by protocol ...") on a chassis without the vendor's frames, or when 0x231
  // reports something else after request_answer_timeout. While the vendor frames are not known
  // yet, the request waits for the answer to that. kInvalidArgument (nothing posted) for a
  // brightness above 100.
  Result<std::uint64_t> set_lights(const LightsRequest& lights);
  // Park (motion mode park, 0x141 = 0x03 on agx_v2). on: motion is refused (kParked) from now
  // on, the chassis brought to rest and switched to park; answered once 0x291 reports park.
  // off: motion allowed again, answered once the chassis has left park. Failed, naming why,
  // where the mode numbering has no park (manual, MINI V1).
  std::uint64_t set_park(bool on);
  // Asks for the firmware version again (it is asked once by itself); answered with the text.
  std::uint64_t request_firmware_version();
  // While set (after the identification, if any): speed is refused (kIdentifying, with
  // ControllerState::standstill_probe) and the probe is commanded; nullopt ends it.
  void standstill_probe(std::optional<StandstillProbe> probe);

  // Blocks the calling thread until request `id` is answered or failed, or `timeout` passes
  // (then the outcome as it stands). Only with start(); in lock-step read the snapshot instead.
  RequestOutcome wait_for(std::uint64_t id, std::chrono::nanoseconds timeout);

  // The latest snapshot (never null). Cheap: a shared pointer copy under a short lock.
  std::shared_ptr<const DriverSnapshot> snapshot() const;

  // ---- lock-step ----
  // One iteration at `now`: open the bus if due, drain it, apply the mailbox, tick, publish.
  void step(Timestamp now);
  // When step() next has something to do (the controller's next tick, or the next open attempt).
  Timestamp next_due() const;

 private:
  struct Mail;
  void loop();
  void wake();
  void wait(std::chrono::nanoseconds timeout);
  void wait_until(Timestamp due);  // timer_fd_: until `due` or a wake()
  void try_open(Timestamp now);
  void apply_mail(Timestamp now);
  void handle_frame(const CanFrame& frame, Timestamp now);
  void run_identification(Timestamp now);
  ProtocolProfile with_configured_settings(const IdentificationStatus& st) const;
  void run_plausibility(Timestamp now);
  void run_standstill_probe();
  void use_profile(const ProtocolProfile& profile, bool reset_odometry = true);
  // Under protocol auto, before the decision: whether what the joint states / the odometry read
  // is decided (nothing is published that would be a guess).
  bool joints_readable() const;
  bool odometry_readable() const;
  void update_requests(Timestamp now);
  void update_vendor(Timestamp now);
  // Applies a lights or version action; false while the vendor frames are not known yet.
  bool apply_vendor_action(const DriverVendorAction& a, Timestamp now);
  void publish(Timestamp now);
  void deliver_events();
  // Records a request of `kind` (`what` says it for people); mail lock held.
  RequestOutcome& add_request(RequestOutcome::Kind kind, std::string what, bool on = false);

  const DriverConfig config_;
  const std::shared_ptr<BusSource> source_;
  const std::string bus_name_;  // source_->name(), for every snapshot
  const Clock& clock_;
  SentObserver sent_observer_;
  bool sent_wall_time_ = true;
  FrameTap frame_tap_;
  StepObserver step_observer_;

  // ---- owned by the driver thread (or the lock-step caller) ----
  std::unique_ptr<Bus> bus_;
  std::unique_ptr<ChassisController> controller_;
  ProtocolProfile profile_;  // the settings in use (decoding, odometry, monitors)
  std::optional<ChassisIdentifier> identifier_;
  // Its status as last published; copied again while the identification runs, and after a
  // change once it is done (a new identifier, a setting adopted while driving).
  std::shared_ptr<const IdentificationStatus> identification_;
  bool identification_changed_ = false;
  PlausibilityMonitor monitor_;
  std::string applied_stop_;  // the monitor's stop passed to the controller
  std::optional<StandstillProbe> probe_;
  bool probe_active_ = false;
  Odometry odometry_;
  bool odometry_fed_ = false;  // the odometry has integrated frames (a new profile keeps its pose)
  WheelJointTracker joints_;
  FrameStats frames_;
  std::string bus_error_;
  Timestamp next_open_attempt_{0};
  std::uint64_t loop_iterations_ = 0;
  std::uint64_t status_frames_ = 0;        // 0x211 received (to tell an answer from a stale frame)
  std::optional<Timestamp> first_status_;  // first 0x211 (vendor_frames_wait counts from it)
  VendorFrames vendor_frames_ = VendorFrames::kUnknown;
  std::optional<RemoteState> remote_;
  std::optional<LightsState> lights_;
  FirmwareVersion firmware_;
  Timestamp version_asked_{0};
  Timestamp last_version_frame_{0};
  std::vector<DriverVendorAction> deferred_;  // waiting for vendor_frames_ to be known
  std::vector<std::pair<std::uint64_t, LightsRequest>> sent_lights_;  // request id, what
  std::vector<SentEvent> events_;           // sent during this iteration, delivered after it
  std::vector<Result<CanFrame>> received_;  // this iteration's frames (capacity kept)
  bool stopped_ = false;

  // ---- the mailbox ----
  mutable std::mutex mail_mutex_;
  std::unique_ptr<Mail> mail_;
  std::deque<RequestOutcome> requests_;  // guarded by mail_mutex_
  std::uint64_t next_request_id_ = 1;
  bool opened_once_ = false;  // guarded by mail_mutex_
  std::string open_error_;    // guarded by mail_mutex_

  // ---- the snapshot ----
  mutable std::mutex snapshot_mutex_;
  std::condition_variable snapshot_changed_;
  std::shared_ptr<const DriverSnapshot> snapshot_;
  // Owned by the driver thread: the snapshot it published last, and the one before, which
  // publish() fills again once no reader holds it (strings and vectors keep their capacity, so a
  // steady state publishes without allocating).
  std::shared_ptr<DriverSnapshot> published_;
  std::shared_ptr<DriverSnapshot> spare_;

  // ---- the thread ----
  int wake_fd_ = -1;
  // An absolute CLOCK_MONOTONIC timer for the next due instant (a monotonic clock only), and
  // the instant it is armed for (or -1): re-armed only when that changes.
  int timer_fd_ = -1;
  Timestamp timer_armed_{-1};
  bool stop_requested_ = false;  // guarded by mail_mutex_
  std::thread thread_;
};

}  // namespace ranger
