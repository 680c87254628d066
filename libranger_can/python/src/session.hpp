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
#include "ranger_can/control/driver.hpp"
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
  std::condition_variable changed_;
  std::uint64_t sequence_ = 0;   // of the newest snapshot, guarded by mutex_
  std::deque<SentMotion> sent_;  // bounded, guarded by mutex_
  bool stop_sent_ = false;       // guarded by mutex_
};

}  // namespace ranger::python
