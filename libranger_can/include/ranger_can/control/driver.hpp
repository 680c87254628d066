// The driver runtime: everything between a program that wants a body twist and a RANGER on a bus,
// with no ROS in it. The ROS 1 node and nodelet (ranger_base), `ranger_can scenario`, `identify`,
// `commission` and `monitor` (read-only), and libranger_can/examples/ use it as it is.
//
// One thread owns the bus, the controller, the odometry, the joint tracker and the frame
// statistics; nothing else touches them. Everything that comes in — a twist, a mode request,
// clear-errors, ultrasonic, resume — is a message in a mailbox the thread drains; everything that
// goes out is an immutable snapshot (DriverSnapshot) that other threads read without waiting for
// the driver, events (driver_events.hpp: every transition, with a severity, in a ring readers
// take from), plus a callback for every frame sent (the stop on shutdown included). The thread
// wakes on a mailbox message or when the controller's next_tick_due() comes; received frames are
// handled in a batch at each wake-up (odometry integrates over the frames' own timestamps, so
// batching changes no estimate).
//
// Its parts, each a class of its own: the mailbox, the snapshot's publication and the thread's
// sleep (driver_runtime.hpp), the request book (request_book.hpp), the vendor's features
// (vendor_features.hpp), the identification and plausibility wiring (settings_supervisor.hpp)
// and the event tracker (event_tracker.hpp); this class runs them in order.
//
// Time comes from an injected Clock. Without start(), the owner drives the same runtime in
// lock-step: step(now) does one iteration (`ranger_can scenario`, tests, no sleeps anywhere);
// its events are then as deterministic as the rest.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/control/driver_runtime.hpp"
#include "ranger_can/control/driver_snapshot.hpp"
#include "ranger_can/control/event_tracker.hpp"
#include "ranger_can/control/frame_stats.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/joint_tracker.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/control/request_book.hpp"
#include "ranger_can/control/settings_supervisor.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/transport/bus_source.hpp"
// The pack's facts (chemistry, voltage range), for programs that include nothing from wire/.
#include "ranger_can/wire/vehicle_spec.hpp"

namespace ranger {

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

// A frame the driver sent, as the observer sees it.
struct SentEvent {
  SentFrame sent;                              // frame, message, achieved twist, shutdown flag
  std::chrono::system_clock::time_point wall;  // wall time right after the send (see
                                               // set_sent_observer)
};

class Driver {
 public:
  using SentObserver = std::function<void(const SentEvent&)>;
  using FrameTap = std::function<void(const CanFrame&)>;
  using EventObserver = std::function<void(const DriverEvent&)>;

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
  // Called on the driver thread (or in step()) with every event, in order, after the iteration
  // that made it (and after stop()'s), outside the driver's locks; the same rules as the step
  // observer. The events are in the ring (events_since) before it is called. Set before start().
  void set_event_observer(EventObserver observer) { event_observer_ = std::move(observer); }

  // Starts the thread. Without it the owner calls step() instead.
  void start();
  // Sends the stop (a zero 0x111, seen by the observer), then ends the thread. Idempotent; the
  // snapshot and the events stay readable.
  void stop();

  // ---- the mailbox (any thread; never waits for the bus) ----
  // The motion wanted from now on. kNotFinite for NaN/inf in any of the six components, named
  // (the driver then commands zero and the snapshot says why: MotionRefusal::kInvalidCommand);
  // kInterfaceDown while the bus was never opened (the message says why). A refusal is also an
  // event (kCommandRefused, the reports spaced).
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
  // Drive mode (0x423, the RANGER MINI 3.0's: the motor drivers' current or voltage loop).
  // Answered once 0x291 reports it; failed, naming the reading, where the profile has no drive
  // modes ("drive modes: unsupported by protocol agx_v2 ..."), or when 0x291 reports another
  // after request_answer_timeout.
  std::uint64_t set_drive_mode(protocol::DriveMode mode);
  // Asks for the firmware version again (it is asked once by itself); answered with the text.
  std::uint64_t request_firmware_version();
  // While set (after the identification, if any): speed is refused (kIdentifying, with
  // ControllerState::standstill_probe) and the probe is commanded; nullopt ends it.
  void standstill_probe(std::optional<StandstillProbe> probe);

  // Blocks the calling thread until request `id` is answered or failed, `timeout` passes, or
  // the driver stops ("the driver stopped"); then the outcome as it stands. Only with start(); in
  // lock-step read the snapshot instead.
  RequestOutcome wait_for(std::uint64_t id, std::chrono::nanoseconds timeout);
  // How long a request of `kind` may take to settle: the driver's own timeouts for it (the
  // chassis's answer, the ultrasonic's attempts, a park switch's attempts after coming to rest,
  // the wait for the vendor frames) and a margin for its next iteration. What a front end waits
  // for at most.
  std::chrono::nanoseconds answer_budget(RequestOutcome::Kind kind) const;

  // The latest snapshot (never null). Cheap: a shared pointer copy under a short lock.
  std::shared_ptr<const DriverSnapshot> snapshot() const { return snapshots_.latest(); }

  // ---- events (any thread) ----
  // The events numbered after `after`, oldest first, appended to `out`; returns how many of them
  // the ring (the last 256) no longer holds. A reader that keeps up misses none: it passes the
  // last sequence number it saw.
  std::uint64_t events_since(std::uint64_t after, std::vector<DriverEvent>& out) const {
    return events_.read(after, out);
  }
  std::uint64_t last_event_sequence() const { return events_.last_sequence(); }

  // ---- lock-step ----
  // One iteration at `now`: open the bus if due, drain it, apply the mailbox, tick, publish.
  void step(Timestamp now);
  // When step() next has something to do (the controller's next tick, or the next open attempt).
  Timestamp next_due() const;

 private:
  void loop();
  void try_open(Timestamp now);
  void apply_mail(Timestamp now);
  void apply_action(const DriverMail::Action& a, Timestamp now);
  void handle_frame(const CanFrame& frame, Timestamp now);
  void use_profile(const ProtocolProfile& profile, bool reset_odometry);
  void settle_requests(Timestamp now);
  void publish(Timestamp now);
  void finish(Timestamp now);  // the stop, its events, the last snapshot
  void deliver();              // the sent frames and the events of the iteration
  std::uint64_t post(RequestOutcome::Kind kind, std::string what, bool on, std::uint8_t code);

  const DriverConfig config_;
  const std::shared_ptr<BusSource> source_;
  const std::string bus_name_;  // source_->name(), for every snapshot
  const Clock& clock_;
  SentObserver sent_observer_;
  bool sent_wall_time_ = true;
  FrameTap frame_tap_;
  StepObserver step_observer_;
  EventObserver event_observer_;

  // ---- owned by the driver thread (or the lock-step caller) ----
  std::unique_ptr<Bus> bus_;
  std::unique_ptr<ChassisController> controller_;
  ProtocolProfile profile_;  // the settings in use (decoding, odometry, monitors)
  SettingsSupervisor settings_;
  Odometry odometry_;
  bool odometry_fed_ = false;  // the odometry has integrated frames (a new profile keeps its pose)
  // The frames' clock minus the driver's (the latest stamped frame's): the commands the odometry
  // is told of go on the frames' clock.
  std::chrono::nanoseconds frame_clock_offset_{0};
  WheelJointTracker joints_;
  FrameStats frames_;
  VendorFeatures vendor_;
  DriverEventTracker tracker_;
  std::string bus_error_;
  Timestamp next_open_attempt_{0};
  std::uint64_t loop_iterations_ = 0;
  bool resumed_ = false;                    // a resume went through in this iteration
  std::vector<SentEvent> sent_;             // sent during this iteration, delivered after it
  std::vector<DriverEvent> step_events_;    // made during this iteration, delivered after it
  std::vector<Result<CanFrame>> received_;  // this iteration's frames (capacity kept)
  bool stopped_ = false;
  std::atomic<bool> finished_{false};  // the stop is sent: waiters stop waiting

  // ---- shared with the callers' threads (each locks itself) ----
  DriverMailbox mailbox_;
  RequestBook requests_;
  SnapshotPublisher snapshots_;
  EventLog events_;
  LoopWaker waker_;
  std::thread thread_;
};

}  // namespace ranger
