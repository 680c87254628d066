// The Python binding's owner of one driver: the bus source (a SocketCAN interface, the in-process
// virtual chassis or a replayed log), the clocks and the ranger::Driver, as the ROS node owns
// them: the driver runs on a monotonic clock, the bus source on CLOCK_REALTIME (frame stamps are
// wall time, comparable with SocketCAN's). Nothing Python runs on the driver's thread: its
// observers only queue (the frames sent) or notify (a snapshot published), and Python waits for
// them on a condition variable with the GIL released.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/diagnostics.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/frontend/publication.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

#include "options.hpp"

namespace ranger::python {

// A motion frame the driver sent (0x111), as cmd_vel_out publishes it.
struct SentMotion {
  BodyTwist achieved;  // the twist it realises (zero for a stop)
  double wall = 0.0;   // s since the Unix epoch, right after the send
  bool shutdown = false;
};

// What Session::wait_motion hands a front end that publishes the motion estimate (odom, TF,
// joint states): the snapshot it was read from, which of its parts are new, and the motion
// frames sent meanwhile.
struct MotionUpdate {
  std::shared_ptr<const DriverSnapshot> snapshot;  // nullptr: nothing new (timeout, stop, sent)
  bool odometry = false;                           // snapshot->odometry is a new estimate
  bool joints = false;                             // the joint states are new
  std::vector<SentMotion> sent;                    // with Setup::record_sent
};

class Session {
 public:
  // Opens the bus source and builds the driver (not started). Errors name the port.
  static Result<std::unique_ptr<Session>> open(const Setup& setup);
  ~Session();  // stop()
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  void start();
  // The driver's stop (a zero 0x111), then its thread ends. Idempotent.
  void stop();
  bool started() const { return started_; }
  bool stopped() const { return stopped_; }

  Driver& driver() { return *driver_; }
  const Setup& setup() const { return setup_; }
  std::shared_ptr<const DriverSnapshot> snapshot() const { return driver_->snapshot(); }
  // Blocks until a snapshot newer than `sequence` is published or `timeout` passes; the latest.
  std::shared_ptr<const DriverSnapshot> wait_snapshot(std::uint64_t sequence,
                                                      std::chrono::nanoseconds timeout);

  // The virtual chassis (port sim[:VARIANT]); nullptr otherwise.
  sim::SimBusSource* sim() const { return sim_.get(); }
  // One line of the virtual chassis's control language; what it says. kInvalidArgument for a
  // port that is no virtual chassis or a line the language refuses (the message lists the valid
  // commands).
  Result<std::string> inject(const std::string& line);

  // The motion frames sent since the last call (recorded only with Setup::record_sent).
  std::vector<SentMotion> take_sent();
  // Blocks until a motion frame was sent or `timeout` passes; then take_sent().
  std::vector<SentMotion> wait_sent(std::chrono::nanoseconds timeout);
  // Whether the shutdown's stop was sent (seen by the observer).
  bool stop_sent() const;

  // The motion publication of a front end, paced as the ROS 1 node paces it: each estimate
  // (odometry, joint states) once, at most one publication per `period` (a fixed-rate schedule,
  // up to min(5 ms, period / 4) early), and nothing while the chassis is not heard. Blocks until
  // a publication is due and the driver has a new estimate, a motion frame was sent (with
  // Setup::record_sent), the session stops, or `timeout` passes. The driver's thread wakes the
  // waiter only for a frame sent or for a new estimate it waits for (due, nothing new yet), not
  // at each of its iterations nor for estimates before the publication is due. One caller.
  MotionUpdate wait_motion(std::chrono::nanoseconds period, std::chrono::nanoseconds timeout);

  // The library's diagnostic groups (control/diagnostics.hpp) of the latest snapshot, in
  // kDiagnosticGroups' order, as the ROS 1 node reports them: the context is the port, where the
  // protocol settings came from and the namespace `ns`. One ranger::ChassisDiagnostics per
  // session keeps what the groups remember between reports (frames rejected since the last).
  std::vector<DiagnosticGroup> diagnostics(const std::string& ns);
  // The hardware_id of every group: "ranger:<ns>:<port_name>".
  std::string hardware_id(const std::string& ns) const;

 private:
  explicit Session(Setup setup);
  void on_step(const std::shared_ptr<const DriverSnapshot>& s);
  void on_sent(const SentEvent& e);

  Setup setup_;
  std::shared_ptr<BusSource> source_;
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  bool started_ = false;
  bool stopped_ = false;

  mutable std::mutex mutex_;
  std::condition_variable changed_;  // every snapshot, every frame sent, the stop
  std::condition_variable motion_;   // a new estimate, a frame sent, the stop
  std::uint64_t sequence_ = 0;       // of the newest snapshot, guarded by mutex_
  std::deque<SentMotion> sent_;      // bounded, guarded by mutex_
  bool stop_sent_ = false;           // guarded by mutex_
  // The estimate's progress (on the driver's thread) and wait_motion's schedule; by mutex_.
  Timestamp estimate_stamp_{0};       // the newest odometry or joint-state stamp seen
  std::uint64_t estimates_ = 0;       // how often it advanced
  bool estimate_awaited_ = false;     // wait_motion waits for the next estimate: wake it for one
  std::optional<MotionPacer> pacer_;  // wait_motion's schedule and what it published
  std::mutex diagnostics_mutex_;
  std::optional<ChassisDiagnostics> diagnostics_;  // by diagnostics_mutex_
};

}  // namespace ranger::python
