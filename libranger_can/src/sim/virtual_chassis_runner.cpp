#include "ranger_can/sim/virtual_chassis_runner.hpp"

#include <poll.h>
#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <exception>

namespace ranger::sim {

namespace {
// Upper bound on one wait, so stop() is noticed promptly even on a silent bus.
constexpr std::chrono::nanoseconds kMaxWait = std::chrono::milliseconds(5);
}  // namespace

VirtualChassisRunner::VirtualChassisRunner(Bus& bus, const VirtualChassisConfig& config,
                                           const Clock& clock)
    : bus_(bus),
      clock_(clock),
      chassis_(std::make_unique<VirtualChassis>(bus, config, clock.now())) {
  running_ = true;
  thread_ = std::thread([this] { loop(); });
}

VirtualChassisRunner::~VirtualChassisRunner() {
  stop();
}

void VirtualChassisRunner::stop() {
  stop_requested_ = true;
  if (thread_.joinable()) thread_.join();
  running_ = false;
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
}

void VirtualChassisRunner::catch_up() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!closed_) chassis_->poll(clock_.now());
}

namespace {

// Waits until `fd` is readable or `timeout` has passed (EINTR counts as a wake-up).
void wait_readable(int fd, std::chrono::nanoseconds timeout) {
  if (fd < 0) {
    std::this_thread::sleep_for(timeout);
    return;
  }
  pollfd p{fd, POLLIN, 0};
  const timespec ts{static_cast<time_t>(timeout.count() / 1'000'000'000),
                    static_cast<long>(timeout.count() % 1'000'000'000)};
  ::ppoll(&p, 1, &ts, nullptr);
}

}  // namespace

std::string VirtualChassisRunner::failure() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failure_;
}

void VirtualChassisRunner::loop() {
  // Named so that top -H and the performance script tell the simulator from the driver.
  ::pthread_setname_np(::pthread_self(), "ranger_sim");
  try {
    while (!stop_requested_.load()) {
      Timestamp deadline;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        deadline = chassis_->next_deadline();
      }
      const auto wait = std::clamp<std::chrono::nanoseconds>(deadline - clock_.now(),
                                                             std::chrono::nanoseconds(0), kMaxWait);
      // Frames are taken only with the chassis held (here or in catch_up()), so that the chassis
      // sees them in the order they came whichever thread hands them over.
      wait_readable(bus_.fd(), wait);
      bool bus_ok = true;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        bus_ok = chassis_->poll(clock_.now());
      }
      // The bus reopens a lost interface by itself; do not spin meanwhile.
      if (!bus_ok) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  } catch (const std::exception& e) {  // never let an exception escape the thread
    std::lock_guard<std::mutex> lock(mutex_);
    failure_ = std::string("virtual chassis loop failed: ") + e.what();
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    failure_ = "virtual chassis loop failed: unknown exception";
  }
  running_ = false;
}

}  // namespace ranger::sim
