#include "ranger_can/control/driver_runtime.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

namespace ranger {
namespace {

using namespace std::chrono_literals;

// ThreadSanitizer does not model the acquire fence blank() relies on to reuse a snapshot: under
// it every snapshot is a new one.
#if defined(__has_feature)  // clang
#if __has_feature(thread_sanitizer)
#define RANGER_UNDER_TSAN 1
#endif
#endif
#if defined(__SANITIZE_THREAD__) || defined(RANGER_UNDER_TSAN)  // gcc, clang
constexpr bool kReuseSnapshots = false;
#else
constexpr bool kReuseSnapshots = true;
#endif

bool finite(const BodyTwist& t) {
  return std::isfinite(t.vx) && std::isfinite(t.vy) && std::isfinite(t.wz);
}
bool is_zero(const BodyTwist& t) {
  return t.vx == 0.0 && t.vy == 0.0 && t.wz == 0.0;
}

timespec to_timespec(std::chrono::nanoseconds d) {
  return timespec{static_cast<time_t>(d.count() / 1'000'000'000),
                  static_cast<long>(d.count() % 1'000'000'000)};
}

void drain(int fd) {
  std::uint64_t value;
  [[maybe_unused]] const auto n = ::read(fd, &value, sizeof value);
}

}  // namespace

// ---- DriverMailbox ----------------------------------------------------------------------------

Status DriverMailbox::post_command(const MotionRequest& request, const std::string& bus) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<Error> refused;
  if (!opened_once_) {
    refused = Error{Errc::kInterfaceDown, "not connected to " + (bus.empty() ? "a bus" : bus) +
                                              (open_error_.empty() ? "" : ": " + open_error_)};
  } else if (!finite(request.twist)) {
    refused =
        Error{Errc::kNotFinite,
              "command refused (NaN or infinite component): the chassis is commanded to stop"};
  }
  if (refused) {
    ++mail_.refused;
    mail_.refusal = refused;
    if (refused->code == Errc::kInterfaceDown) return *refused;
  }
  if (mail_.command && is_zero(mail_.command->twist)) mail_.zero_seen = true;
  mail_.command = request;
  return refused ? Status(*refused) : ok_status();
}

void DriverMailbox::post(const std::function<void(DriverMail&)>& edit) {
  std::lock_guard<std::mutex> lock(mutex_);
  edit(mail_);
}

DriverMail DriverMailbox::take() {
  DriverMail mail;
  std::lock_guard<std::mutex> lock(mutex_);
  std::swap(mail, mail_);
  return mail;
}

std::uint64_t DriverMailbox::take_refused(std::optional<Error>& last) {
  std::lock_guard<std::mutex> lock(mutex_);
  last = std::move(mail_.refusal);
  mail_.refusal.reset();
  return std::exchange(mail_.refused, 0);
}

void DriverMailbox::set_open(bool opened, const std::string& error) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (opened) opened_once_ = true;
  open_error_ = error;
}

void DriverMailbox::request_stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stop_requested_ = true;
}

bool DriverMailbox::stop_requested() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stop_requested_;
}

// ---- SnapshotPublisher ------------------------------------------------------------------------

SnapshotPublisher::SnapshotPublisher(std::shared_ptr<const DriverSnapshot> first)
    : latest_(first ? std::move(first) : std::make_shared<const DriverSnapshot>()) {}

std::shared_ptr<DriverSnapshot> SnapshotPublisher::blank() {
  if (kReuseSnapshots && spare_ && spare_.use_count() == 1) {
    // No reader holds it: the last one's reads happened before its release of the count.
    std::atomic_thread_fence(std::memory_order_acquire);
    return std::move(spare_);
  }
  return std::make_shared<DriverSnapshot>();
}

void SnapshotPublisher::publish(std::shared_ptr<DriverSnapshot> s) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s->sequence = latest_->sequence + 1;
    latest_ = s;
  }
  spare_ = std::move(published_);
  published_ = std::move(s);
  changed_.notify_all();
}

std::shared_ptr<const DriverSnapshot> SnapshotPublisher::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

std::shared_ptr<const DriverSnapshot> SnapshotPublisher::wait_until(
    const std::function<bool(const DriverSnapshot&)>& done,
    std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_until(lock, deadline, [&] { return done(*latest_); });
  return latest_;
}

// ---- LoopWaker -------------------------------------------------------------------------------

LoopWaker::LoopWaker(const Clock& clock) : clock_(clock) {
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (clock_.monotonic()) timer_fd_ = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
}

LoopWaker::~LoopWaker() {
  if (wake_fd_ >= 0) ::close(wake_fd_);
  if (timer_fd_ >= 0) ::close(timer_fd_);
}

void LoopWaker::wake() {
  if (wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  // A full counter (EAGAIN) means a wake-up is pending anyway.
  [[maybe_unused]] const auto n = ::write(wake_fd_, &one, sizeof one);
}

void LoopWaker::sleep_for(std::chrono::nanoseconds timeout) {
  const timespec ts = to_timespec(std::clamp<std::chrono::nanoseconds>(timeout, 0ns, 1s));
  if (wake_fd_ < 0) {
    ::nanosleep(&ts, nullptr);
    return;
  }
  pollfd fd{wake_fd_, POLLIN, 0};
  if (::ppoll(&fd, 1, &ts, nullptr) > 0 && (fd.revents & POLLIN)) drain(wake_fd_);
}

bool LoopWaker::arm(Timestamp due) {
  if (due == timer_armed_) return true;
  itimerspec spec{};
  spec.it_value = to_timespec(std::max<std::chrono::nanoseconds>(due, 1ns));  // 0 would disarm it
  if (::timerfd_settime(timer_fd_, TFD_TIMER_ABSTIME, &spec, nullptr) != 0) return false;
  timer_armed_ = due;
  return true;
}

void LoopWaker::sleep_until(Timestamp due) {
  if (timer_fd_ < 0 || wake_fd_ < 0 || !arm(due)) {
    sleep_for(due - clock_.now());
    return;
  }
  // No timeout: the kernel reads no clock for this wait (under emulation a clock read can cost
  // more than the rest of an iteration).
  pollfd fds[2] = {{wake_fd_, POLLIN, 0}, {timer_fd_, POLLIN, 0}};
  if (::ppoll(fds, 2, nullptr, nullptr) <= 0) return;
  if (fds[0].revents & POLLIN) drain(wake_fd_);
  // An expired timer is not read: arming it again (the next instant is a later one) clears it.
  if (fds[1].revents & POLLIN) timer_armed_ = Timestamp{-1};
}

}  // namespace ranger
