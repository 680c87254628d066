// How a front end paces what it publishes, made once: the ROS 1 node's publication thread, the
// binding's Session::wait_motion (the ROS 2 node's odom, /tf and joint_states) and the ROS 2
// node's states and diagnostics all follow these schedules and this decision, so both nodes
// publish alike at the same rates.
#pragma once

#include <chrono>

#include "ranger_can/control/driver.hpp"

namespace ranger {

using SteadyTime = std::chrono::steady_clock::time_point;
using SteadyDuration = std::chrono::steady_clock::duration;

// One period of a publication at `rate_hz` (> 0).
SteadyDuration publication_period(double rate_hz);
// How long before its time a publication is due: the estimates come with the driver's
// iterations, which jitter; min(5 ms, period / 4).
SteadyDuration publication_early(SteadyDuration period);

// A fixed-rate schedule: the next publication is due one period after the previous due time (so
// the average rate is the configured one), from publication_early() before it; after a stall it
// restarts from now instead of publishing a burst.
class PublicationSchedule {
 public:
  explicit PublicationSchedule(double rate_hz) : PublicationSchedule(publication_period(rate_hz)) {}
  explicit PublicationSchedule(SteadyDuration period) { set_period(period); }

  // A new rate from the next advance on (a front end whose rate parameter changes).
  void set_period(SteadyDuration period);
  void set_rate(double rate_hz) { set_period(publication_period(rate_hz)); }
  SteadyDuration period() const { return period_; }

  // The first publication is due at `now`.
  void start(SteadyTime now) { next_ = now; }
  bool due(SteadyTime now) const { return now >= wake_at(); }
  // Published (or skipped) at `now`: the next one period after this one's time.
  void advance(SteadyTime now);
  // When to look again.
  SteadyTime wake_at() const { return next_ - early_; }
  SteadyTime next() const { return next_; }

 private:
  SteadyDuration period_{};
  SteadyDuration early_{};
  SteadyTime next_{};
};

// The motion publication (odom, TF, joint states): each estimate once, at most once per period,
// and nothing while the chassis is not heard.
struct MotionDecision {
  bool odometry = false;  // the snapshot's odometry is an estimate not published yet
  bool joints = false;    // its joint states are
  // Due, heard, but nothing new yet: wait for the driver's next estimate (the schedule did not
  // advance).
  bool wait_for_estimate = false;
  bool publish() const { return odometry || joints; }
};

class MotionPacer {
 public:
  explicit MotionPacer(double rate_hz) : schedule_(rate_hz) {}
  explicit MotionPacer(SteadyDuration period) : schedule_(period) {}

  void start(SteadyTime now) { schedule_.start(now); }
  void set_rate(double rate_hz) { schedule_.set_rate(rate_hz); }
  void set_period(SteadyDuration period) { schedule_.set_period(period); }
  bool due(SteadyTime now) const { return schedule_.due(now); }
  SteadyTime wake_at() const { return schedule_.wake_at(); }
  SteadyTime next() const { return schedule_.next(); }

  // At a due time: what of `s` to publish. The schedule advances when something is new, or when
  // nothing can come (the chassis not heard); what is returned counts as published.
  MotionDecision decide(const DriverSnapshot& s, SteadyTime now);
  // Due, but nobody listens: nothing is built, the schedule advances.
  void skip(SteadyTime now) { schedule_.advance(now); }

 private:
  PublicationSchedule schedule_;
  Timestamp published_odometry_{0};
  Timestamp published_joints_{0};
};

}  // namespace ranger
