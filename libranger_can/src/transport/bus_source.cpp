#include "ranger_can/transport/bus_source.hpp"

#include <net/if.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <mutex>
#include <utility>
#include <vector>

#include "bus_internal.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

constexpr std::string_view kReplayPrefix = "replay:";
constexpr std::string_view kSimName = "sim";
const char* const kForms =
    "give a SocketCAN interface (can0), replay:FILE (a candump log) or sim[:VARIANT] (the "
    "virtual chassis)";

class SocketCanSource final : public BusSource {
 public:
  SocketCanSource(std::string name, const Clock& clock) : name_(std::move(name)), clock_(clock) {}
  Result<std::unique_ptr<Bus>> open() override {
    SocketCanOptions options;
    options.clock = &clock_;
    auto bus = SocketCanBus::open(name_, options);
    if (!bus) return bus.error();
    return std::unique_ptr<Bus>(std::move(*bus));
  }
  std::string name() const override { return name_; }

 private:
  std::string name_;
  const Clock& clock_;
};

// A candump log as a bus: frames become receivable at their offset from the first one.
class ReplayBus final : public Bus {
 public:
  ReplayBus(std::string name, std::vector<CanFrame> frames, const Clock& clock)
      : name_(std::move(name)), frames_(std::move(frames)), clock_(clock), start_(clock.now()) {
    status_.detail = "replaying " + std::to_string(frames_.size()) + " frames (read-only)";
  }

  Status send(const CanFrame&) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++status_.stats.tx_frames;  // discarded: a log cannot be commanded
    return ok_status();
  }

  Result<CanFrame> receive(std::chrono::nanoseconds timeout) override {
    std::unique_lock<std::mutex> lock(mutex_);
    if (next_ >= frames_.size()) {
      status_.detail = "replay finished: " + std::to_string(frames_.size()) + " frames";
      lock.unlock();
      if (timeout > 0ns) wait(timeout);
      return Error{Errc::kTimeout, name_ + ": replay finished"};
    }
    const auto due = start_ + frames_[next_].stamp;
    const Timestamp now = clock_.now();
    if (now < due) {
      lock.unlock();
      if (timeout > 0ns) wait(std::min(timeout, due - now));
      lock.lock();
      if (clock_.now() < due) return Error{Errc::kTimeout, name_ + ": no frame within the timeout"};
    }
    CanFrame f = frames_[next_++];
    f.stamp = due;
    if (filter_.accepts(f.id)) {
      ++status_.stats.rx_frames;
      return f;
    }
    return Error{Errc::kTimeout, name_ + ": frame filtered"};
  }

  int fd() const override { return -1; }  // time-driven: poll with a timeout
  BusStatus status() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }
  void set_filter(const std::vector<std::uint32_t>& ids) override {
    std::lock_guard<std::mutex> lock(mutex_);
    filter_.set(ids);
  }
  std::string name() const override { return name_; }

 private:
  void wait(std::chrono::nanoseconds d) const {
    // A replay on a ManualClock never sleeps; on a real clock this paces the loop.
    if (dynamic_cast<const ManualClock*>(&clock_) != nullptr) return;
    const timespec ts{static_cast<time_t>(d.count() / 1'000'000'000),
                      static_cast<long>(d.count() % 1'000'000'000)};
    ::nanosleep(&ts, nullptr);
  }

  const std::string name_;
  const std::vector<CanFrame> frames_;  // stamp = offset from the first frame
  const Clock& clock_;
  const Timestamp start_;
  mutable std::mutex mutex_;
  std::size_t next_ = 0;
  bus_internal::IdFilter filter_;
  BusStatus status_;
};

class ReplaySource final : public BusSource {
 public:
  ReplaySource(std::string spec, std::string path, const Clock& clock)
      : spec_(std::move(spec)), path_(std::move(path)), clock_(clock) {}
  Result<std::unique_ptr<Bus>> open() override { return open_replay_bus(path_, clock_); }
  std::string name() const override { return spec_; }
  bool read_only() const override { return true; }

 private:
  std::string spec_, path_;
  const Clock& clock_;
};

}  // namespace

Result<BusKind> bus_kind(std::string_view spec) {
  if (spec.empty()) return Error{Errc::kInvalidArgument, std::string("empty bus name: ") + kForms};
  if (spec.substr(0, kReplayPrefix.size()) == kReplayPrefix) {
    if (spec.size() == kReplayPrefix.size()) {
      return Error{Errc::kInvalidArgument, "replay: needs a file, e.g. replay:drive.log"};
    }
    return BusKind::kReplay;
  }
  if (spec == kSimName || spec.substr(0, kSimName.size() + 1) == "sim:") return BusKind::kSim;
  if (spec.size() >= IFNAMSIZ) {
    return Error{Errc::kInvalidArgument,
                 "'" + std::string(spec) + "' is not an interface name (at most " +
                     std::to_string(IFNAMSIZ - 1) + " characters): " + kForms};
  }
  return BusKind::kSocketCan;
}

Result<std::unique_ptr<BusSource>> open_bus_source(std::string_view spec, const Clock& clock) {
  auto kind = bus_kind(spec);
  if (!kind) return kind.error();
  switch (*kind) {
    case BusKind::kReplay: {
      const std::string path(spec.substr(kReplayPrefix.size()));
      return std::unique_ptr<BusSource>(
          std::make_unique<ReplaySource>(std::string(spec), path, clock));
    }
    case BusKind::kSim:
      return Error{Errc::kInvalidArgument,
                   "'" + std::string(spec) +
                       "' is the virtual chassis, which this program was built without "
                       "(sim::open_bus_source in ranger_can_sim provides it)"};
    case BusKind::kSocketCan:
      break;
  }
  return std::unique_ptr<BusSource>(std::make_unique<SocketCanSource>(std::string(spec), clock));
}

Result<std::unique_ptr<Bus>> open_replay_bus(const std::string& path, const Clock& clock) {
  std::ifstream in(path);
  if (!in) {
    return Error{Errc::kIoError, "replay: cannot read '" + path + "'"};
  }
  std::vector<CanFrame> frames;
  std::string line;
  Timestamp first{0}, last{0};
  bool have_first = false;
  while (std::getline(in, line)) {
    auto entry = parse_candump_line(line);
    if (!entry) continue;  // blank, comment, malformed or foreign lines: not RANGER frames
    CanFrame f = entry->frame;
    Timestamp t = entry->has_timestamp ? f.stamp : last + 1ms;
    if (!have_first) {
      first = t;
      have_first = true;
    }
    if (t < last) t = last;  // never backwards
    last = t;
    f.stamp = t - first;
    frames.push_back(f);
  }
  if (frames.empty()) {
    return Error{Errc::kInvalidArgument, "replay: '" + path + "' holds no CAN frame"};
  }
  return std::unique_ptr<Bus>(
      std::make_unique<ReplayBus>("replay:" + path, std::move(frames), clock));
}

}  // namespace ranger
