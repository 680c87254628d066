#include "ranger_can/sim/virtual_chassis_runner.hpp"

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
}

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
      auto frame = bus_.receive(wait);
      if (!frame && frame.error().code != Errc::kTimeout) {
        // The bus reopens a lost interface by itself; do not spin meanwhile.
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      std::lock_guard<std::mutex> lock(mutex_);
      if (frame) chassis_->on_frame(*frame, clock_.now());
      chassis_->step(clock_.now());
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
