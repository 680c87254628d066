// Time is injected, never read inside logic: the controller, odometry and simulator take the
// current time as an argument or through a Clock, so tests drive them with a ManualClock and no
// test ever sleeps or asserts on wall-clock time.
#pragma once

#include <atomic>
#include <chrono>

#include "ranger_can/types.hpp"

namespace ranger {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual Timestamp now() const = 0;
  // True when now() reads CLOCK_MONOTONIC: a thread may then wait for one of its instants with
  // an absolute kernel timer (no clock read to turn it into a timeout).
  virtual bool monotonic() const { return false; }
};

// Monotonic time for control loops (timeouts, keep-alive).
class SteadyClock final : public Clock {
 public:
  Timestamp now() const override {
    return std::chrono::duration_cast<Timestamp>(
        std::chrono::steady_clock::now().time_since_epoch());
  }
  bool monotonic() const override { return true; }  // libstdc++'s steady_clock on Linux
};

// Same epoch as SocketCAN's SO_TIMESTAMP (CLOCK_REALTIME), for stamping frames that must be
// comparable with kernel receive timestamps.
class SystemClock final : public Clock {
 public:
  Timestamp now() const override {
    return std::chrono::duration_cast<Timestamp>(
        std::chrono::system_clock::now().time_since_epoch());
  }
};

// A clock that moves only when told to. Thread-safe so a test can advance it while a bus or
// simulator thread reads it.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(Timestamp start = Timestamp{0}) : now_(start.count()) {}
  Timestamp now() const override { return Timestamp{now_.load()}; }
  void set(Timestamp t) { now_.store(t.count()); }
  void advance(std::chrono::nanoseconds d) { now_.fetch_add(d.count()); }

 private:
  std::atomic<Timestamp::rep> now_;
};

}  // namespace ranger
