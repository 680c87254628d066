#include "session.hpp"

#include <algorithm>

#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/text.hpp"

#include "views.hpp"

namespace ranger::python {
namespace {

// The frames sent are kept this long at most when nobody takes them (50 s of keep-alives).
constexpr std::size_t kMaxSent = 2500;

const Clock& driver_clock() {
  static const SteadyClock clock;
  return clock;
}
const Clock& bus_clock() {
  static const SystemClock clock;
  return clock;
}

}  // namespace

Session::Session(Setup setup) : setup_(std::move(setup)) {}

Result<std::unique_ptr<Session>> Session::open(const Setup& setup) {
  auto source = sim::open_bus_source(setup.node.port_name, bus_clock(), setup.node.sim);
  if (!source) {
    return Error{source.error().code,
                 "port \"" + setup.node.port_name + "\": " + source.error().message};
  }
  std::unique_ptr<Session> s(new Session(setup));
  s->source_ = *source;
  s->sim_ = std::dynamic_pointer_cast<sim::SimBusSource>(s->source_);
  s->driver_ = std::make_unique<Driver>(s->setup_.node.driver, s->source_, driver_clock());
  Session* self = s.get();
  s->driver_->set_step_observer(
      [self](const std::shared_ptr<const DriverSnapshot>& snap) { self->on_step(snap); });
  // The send's wall time only for cmd_vel_out (one clock read per frame otherwise saved).
  s->driver_->set_sent_observer([self](const SentEvent& e) { self->on_sent(e); },
                                s->setup_.record_sent);
  return s;
}

Session::~Session() {
  stop();
}

void Session::start() {
  if (started_ || stopped_) return;
  started_ = true;
  driver_->start();
}

void Session::stop() {
  if (stopped_) return;
  stopped_ = true;
  driver_->stop();
  changed_.notify_all();
  motion_.notify_all();
}

void Session::on_step(const std::shared_ptr<const DriverSnapshot>& s) {
  const Timestamp estimate = std::max(s->odometry.stamp, joints_stamp(s->feedback));
  bool wake = false;  // a new estimate, and wait_motion waits for one (not merely for its time)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sequence_ = s->sequence;
    if (estimate > estimate_stamp_) {
      estimate_stamp_ = estimate;
      ++estimates_;
      wake = estimate_awaited_;
    }
  }
  changed_.notify_all();
  if (wake) motion_.notify_all();
}

void Session::on_sent(const SentEvent& e) {
  if (e.sent.frame.id != protocol::kMotionCommandId) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (e.sent.shutdown) stop_sent_ = true;
    if (!setup_.record_sent) return;
    if (sent_.size() >= kMaxSent) sent_.pop_front();
    sent_.push_back(SentMotion{e.sent.achieved,
                               std::chrono::duration<double>(e.wall.time_since_epoch()).count(),
                               e.sent.shutdown});
  }
  changed_.notify_all();
  motion_.notify_all();
}

std::shared_ptr<const DriverSnapshot> Session::wait_snapshot(std::uint64_t sequence,
                                                             std::chrono::nanoseconds timeout) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return sequence_ > sequence || stopped_; });
  }
  return driver_->snapshot();
}

std::vector<SentMotion> Session::take_sent() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SentMotion> out(sent_.begin(), sent_.end());
  sent_.clear();
  return out;
}

std::vector<SentMotion> Session::wait_sent(std::chrono::nanoseconds timeout) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return !sent_.empty() || stopped_; });
  }
  return take_sent();
}

MotionUpdate Session::wait_motion(std::chrono::nanoseconds period,
                                  std::chrono::nanoseconds timeout) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + timeout;
  MotionUpdate out;
  std::unique_lock<std::mutex> lock(mutex_);
  // The library's pacing (frontend/publication.hpp), as the ROS 1 node's publication thread.
  const auto steady_period = std::chrono::duration_cast<SteadyDuration>(period);
  if (!pacer_) {
    pacer_.emplace(steady_period);
    pacer_->start(Clock::now());
  } else {
    pacer_->set_period(steady_period);
  }
  while (!stopped_) {
    out.sent.assign(sent_.begin(), sent_.end());
    sent_.clear();
    const auto now = Clock::now();
    bool waiting = false;  // due, and the latest snapshot has nothing new: the next estimate
    if (pacer_->due(now)) {
      auto s = driver_->snapshot();
      const MotionDecision decision = pacer_->decide(*s, now);
      out.odometry = decision.odometry;
      out.joints = decision.joints;
      if (decision.publish()) {
        out.snapshot = std::move(s);
        return out;
      }
      waiting = decision.wait_for_estimate;
    }
    if (!out.sent.empty() || now >= deadline) return out;
    const std::uint64_t estimates = estimates_;
    estimate_awaited_ = waiting;
    motion_.wait_until(lock, waiting ? deadline : std::min(deadline, pacer_->wake_at()), [&] {
      return stopped_ || !sent_.empty() || (waiting && estimates_ != estimates);
    });
    estimate_awaited_ = false;
  }
  out.sent.assign(sent_.begin(), sent_.end());
  sent_.clear();
  return out;
}

std::vector<DiagnosticGroup> Session::diagnostics(const std::string& ns) {
  const auto s = driver_->snapshot();
  std::lock_guard<std::mutex> lock(diagnostics_mutex_);
  if (!diagnostics_ || diagnostics_->context().ns != ns) {
    diagnostics_.emplace(DiagnosticContext{setup_.node.port_name, setup_.node.protocol.source, ns});
  }
  return diagnostics_->report(*s);
}

std::string Session::hardware_id(const std::string& ns) const {
  return ranger::hardware_id(ns, setup_.node.port_name);
}

bool Session::stop_sent() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stop_sent_;
}

Result<std::string> Session::inject(const std::string& line) {
  if (!sim_) {
    return Error{Errc::kInvalidArgument, "inject: port " + setup_.node.port_name +
                                             " is no virtual chassis (use sim or sim:VARIANT)"};
  }
  auto action = sim::parse_chassis_command(line);
  if (!action) {
    return Error{action.error().code,
                 "inject \"" + line + "\": " + action.error().message +
                     " (valid commands: " + text::join(sim::chassis_command_names()) + ")"};
  }
  return sim_->with_chassis(*action);
}

}  // namespace ranger::python
