// Pieces shared by the Bus implementations (not installed): the status/statistics bookkeeping,
// the reopen rate limit, the receive filter and the checks on outgoing frames. Keeping them in
// one place is what makes SocketCanBus and LoopbackBus behave the same.
// None of these classes lock: their owner holds its own mutex around every call.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/transport/error_frame.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger::bus_internal {

// Owns a file descriptor.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }
  UniqueFd(UniqueFd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& o) noexcept {
    if (this != &o) {
      reset();
      fd_ = std::exchange(o.fd_, -1);
    }
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

// The receive filter: a sorted ID list; empty accepts every ID.
class IdFilter {
 public:
  void set(std::vector<std::uint32_t> ids) {
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    ids_ = std::move(ids);
  }
  bool accepts(std::uint32_t id) const {
    return ids_.empty() || std::binary_search(ids_.begin(), ids_.end(), id);
  }
  const std::vector<std::uint32_t>& ids() const { return ids_; }

 private:
  std::vector<std::uint32_t> ids_;
};

// Status, detail and counters of one bus endpoint, and the state transitions every
// implementation shares (error frames, loss of the interface, reopening).
class StatusTracker {
 public:
  explicit StatusTracker(std::string name) : name_(std::move(name)) {}

  void on_error_frame(const CanFrame& frame) {
    ++status_.stats.error_frames;
    const ErrorFrameReport r = interpret_error_frame(frame);
    if (r.controller_problem) ++status_.stats.controller_problems;
    if (r.restarted) ++status_.stats.restarts;
    // While the interface is gone its state stays kDown; error frames cannot revive it.
    if (r.new_state && status_.state != BusState::kDown) status_.state = *r.new_state;
    status_.detail = name_ + ": error frame: " + r.description;
  }
  void on_lost(const std::string& why) {
    status_.state = BusState::kDown;
    lost_reason_ = why;
    status_.detail = name_ + ": " + why + "; reopening when it is back";
  }
  void on_reopened() {
    status_.state = BusState::kActive;
    ++status_.stats.reopens;
    status_.detail = name_ + ": interface is back, reopened";
  }
  void on_reopen_failed(const std::string& why) {
    status_.detail = name_ + ": " + lost_reason_ + "; reopen failed (" + why + "); retrying";
  }

  BusStatus& status() { return status_; }
  const BusStatus& status() const { return status_; }
  BusStatistics& stats() { return status_.stats; }
  bool down() const { return status_.state == BusState::kDown; }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::string lost_reason_;
  BusStatus status_;
};

// Rate limit for reopen attempts, on the injected clock: the first attempt right after the loss
// is noticed (a short blip heals at once), then at most one per `interval`.
class ReopenSchedule {
 public:
  ReopenSchedule(const Clock& clock, std::chrono::nanoseconds interval)
      : clock_(&clock), interval_(interval) {}
  void on_lost() { next_ = clock_->now(); }
  bool due() const { return clock_->now() >= next_; }
  void on_failed() { next_ = clock_->now() + interval_; }

 private:
  const Clock* clock_;
  std::chrono::nanoseconds interval_;
  Timestamp next_{0};
};

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;

inline std::string hex_id(std::uint32_t id) {
  return text::hex(id);
}

// The checks every send() applies before a frame goes anywhere.
inline Status validate_outgoing(const CanFrame& f, const std::string& bus_name) {
  if (f.is_error) {
    return Error{Errc::kInvalidArgument,
                 bus_name + ": refusing to send an error frame (only controllers report errors)"};
  }
  if (f.id > kMaxStandardId) {
    return Error{Errc::kInvalidArgument,
                 bus_name + ": ID " + hex_id(f.id) + " is not an 11-bit standard identifier"};
  }
  if (f.dlc > CanFrame::kMaxDlc) {
    return Error{Errc::kBadDlc, bus_name + ": DLC " + std::to_string(f.dlc) +
                                    " is more than a classic CAN frame carries (8)"};
  }
  return ok_status();
}

}  // namespace ranger::bus_internal
