#include "cli_session.hpp"

#include <time.h>

#include <algorithm>

#include "cli_signals.hpp"

namespace ranger::cli {

using namespace std::chrono_literals;

namespace {
// A source whose buses are only listened to: the driver treats it as a replayed log.
class ListenOnlySource final : public BusSource {
 public:
  explicit ListenOnlySource(std::shared_ptr<BusSource> source) : source_(std::move(source)) {}
  Result<std::unique_ptr<Bus>> open() override { return source_->open(); }
  std::string name() const override { return source_->name(); }
  bool read_only() const override { return true; }

 private:
  std::shared_ptr<BusSource> source_;
};
}  // namespace

Result<std::unique_ptr<DriverSession>> DriverSession::open(const std::string& spec,
                                                           DriverConfig config, bool listen_only) {
  std::unique_ptr<DriverSession> s(new DriverSession());
  auto kind = bus_kind(spec);
  if (!kind) return kind.error();
  sim::SimSourceOptions options;
  if (*kind == BusKind::kSim) {
    s->manual_ = std::make_unique<ManualClock>(Timestamp(1s));
    s->clock_ = s->manual_.get();
    options.lock_step = true;
  } else {
    s->steady_ = std::make_unique<SteadyClock>();
    s->clock_ = s->steady_.get();
  }
  auto source = sim::open_bus_source(spec, *s->clock_, options);
  if (!source) return source.error();
  s->source_ = *source;
  if (*kind == BusKind::kSim) s->sim_ = std::static_pointer_cast<sim::SimBusSource>(s->source_);
  if (listen_only) s->source_ = std::make_shared<ListenOnlySource>(s->source_);
  s->driver_ = std::make_unique<Driver>(std::move(config), s->source_, *s->clock_);
  return s;
}

DriverSession::~DriverSession() {
  stop();
}

void DriverSession::stop() {
  if (driver_) driver_->stop();
}

void DriverSession::restart(DriverConfig config) {
  driver_->stop();
  step();  // let the chassis hear the stop
  driver_ = std::make_unique<Driver>(std::move(config), source_, *clock_);
}

bool DriverSession::interrupted() const {
  return StopSignals::requested();
}

void DriverSession::command(std::optional<MotionRequest> request) {
  request_ = std::move(request);
  next_publish_ = clock_->now();
}

void DriverSession::step() {
  if (manual_) {
    manual_->advance(1ms);
  } else {
    const Timestamp due = std::min(driver_->next_due(), clock_->now() + 5ms);
    const auto wait = due - clock_->now();
    if (wait.count() > 0) {
      const timespec ts{0, static_cast<long>(wait.count())};
      ::nanosleep(&ts, nullptr);
    }
  }
  const Timestamp now = clock_->now();
  if (request_ && now >= next_publish_) {
    (void)driver_->command(*request_);
    next_publish_ = now + 50ms;
  }
  if (sim_) sim_->step(now);
  driver_->step(now);
}

bool DriverSession::run_until(const std::function<bool(const DriverSnapshot&)>& done,
                              std::chrono::nanoseconds timeout) {
  const Timestamp end = clock_->now() + timeout;
  while (!done(*driver_->snapshot())) {
    if (clock_->now() >= end || interrupted()) return false;
    step();
  }
  return true;
}

void DriverSession::run_for(std::chrono::nanoseconds d) {
  const Timestamp end = clock_->now() + d;
  run_until([&](const DriverSnapshot&) { return clock_->now() >= end; }, d + 1s);
}

}  // namespace ranger::cli
