// The driver runtime's plumbing (driver.hpp): what comes in, what goes out, and when its thread
// wakes, each a small class of its own.
//  * DriverMailbox: what callers post on their threads (the twist, the mode, the requests, the
//    standstill probe, the stop), taken whole by the driver thread at each iteration.
//  * SnapshotPublisher: the latest DriverSnapshot for any thread, and the recycling of the
//    one no reader holds any more (a steady state publishes without allocating).
//  * LoopWaker: the thread's sleep until the next due instant or a wake() (an eventfd and an
//    absolute CLOCK_MONOTONIC timerfd: no clock is read for the wait itself).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/driver_snapshot.hpp"
#include "ranger_can/control/request_book.hpp"
#include "ranger_can/control/settings_supervisor.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/result.hpp"

namespace ranger {

// What callers posted since the driver last looked.
struct DriverMail {
  std::optional<MotionRequest> command;  // the latest twist
  bool zero_seen = false;  // a zero twist came before the latest (it may re-arm: opt-in)
  std::optional<std::optional<protocol::MotionMode>> mode;
  std::optional<std::optional<StandstillProbe>> probe;
  struct Action {
    RequestOutcome::Kind kind;  // kClearErrors, kUltrasonic, kPark, kResume or kDriveMode
    std::uint64_t id;
    std::uint8_t code;  // kClearErrors: the 0x441 code; kDriveMode: the drive mode
    bool enable;
  };
  std::vector<Action> actions;
  std::vector<VendorAction> vendor;  // lights, version
  // Commands refused since (non-finite, or before the bus was ever opened), the last one's error.
  std::uint64_t refused = 0;
  std::optional<Error> refusal;
};

class DriverMailbox {
 public:
  // The caller's twist. kInterfaceDown while the bus was never opened (naming `bus` and why);
  // kNotFinite for NaN/inf (posted all the same: the driver then commands zero). Refusals are
  // counted for the driver's events.
  Status post_command(const MotionRequest& request, const std::string& bus);
  // Runs `edit` on the mail under the lock.
  void post(const std::function<void(DriverMail&)>& edit);
  // Everything posted since the last take (the mailbox is empty again).
  DriverMail take();
  // Only the refused commands since the last take: their count, and the last one's error.
  std::uint64_t take_refused(std::optional<Error>& last);

  // The driver thread's word on the bus: opened (commands are taken from now on), or why not.
  void set_open(bool opened, const std::string& error);
  void request_stop();
  bool stop_requested() const;

 private:
  mutable std::mutex mutex_;
  DriverMail mail_;
  bool opened_once_ = false;
  std::string open_error_;
  bool stop_requested_ = false;
};

class SnapshotPublisher {
 public:
  // `first`: what readers see before the first publication (number 0).
  explicit SnapshotPublisher(std::shared_ptr<const DriverSnapshot> first);

  // A snapshot to fill (every field: a recycled one keeps its last publication's content and
  // capacity): the one before the last publication when no reader holds it, else a new one.
  std::shared_ptr<DriverSnapshot> blank();
  // Publishes `s` (numbered one after the last) to every reader and wakes those waiting.
  void publish(std::shared_ptr<DriverSnapshot> s);
  // The latest snapshot (never null). Cheap: a shared pointer copy under a short lock.
  std::shared_ptr<const DriverSnapshot> latest() const;
  // The snapshot just published, for the publishing thread only (no lock).
  const DriverSnapshot& published() const { return *published_; }
  // Blocks until `done` holds for the latest snapshot or `deadline` passes; returns the latest.
  std::shared_ptr<const DriverSnapshot> wait_until(
      const std::function<bool(const DriverSnapshot&)>& done,
      std::chrono::steady_clock::time_point deadline) const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::shared_ptr<const DriverSnapshot> latest_;
  // Owned by the publishing thread: the snapshot it published last, and the one before, which
  // blank() hands out again once no reader holds it.
  std::shared_ptr<DriverSnapshot> published_;
  std::shared_ptr<DriverSnapshot> spare_;
};

class LoopWaker {
 public:
  // `clock`: the driver's; the timer is used only when it is monotonic (CLOCK_MONOTONIC).
  explicit LoopWaker(const Clock& clock);
  ~LoopWaker();
  LoopWaker(const LoopWaker&) = delete;
  LoopWaker& operator=(const LoopWaker&) = delete;

  // Any thread, never blocks: the sleeping thread wakes (or the next sleep returns at once).
  void wake();
  // Sleeps until `due` (the driver clock) or a wake() (without the timer: at most 1 s).
  void sleep_until(Timestamp due);

 private:
  void sleep_for(std::chrono::nanoseconds timeout);  // without the timer
  bool arm(Timestamp due);

  const Clock& clock_;
  int wake_fd_ = -1;
  // An absolute CLOCK_MONOTONIC timer for the next due instant (a monotonic clock only), and the
  // instant it is armed for (or -1): re-armed only when that changes.
  int timer_fd_ = -1;
  Timestamp timer_armed_{-1};
};

}  // namespace ranger
