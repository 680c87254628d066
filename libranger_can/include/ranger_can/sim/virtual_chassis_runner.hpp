// Runs a VirtualChassis on a thread of its own against a real clock: what `ranger_can sim` and
// the end-to-end tests on vcan use. The chassis logic stays in VirtualChassis (deterministic,
// driven by injected time); this class only supplies the loop: wait for a frame or the next
// deadline, hand frames over, step.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"

namespace ranger::sim {

class VirtualChassisRunner {
 public:
  // Boots the chassis at clock.now() and starts the thread. `bus` and `clock` must outlive the
  // runner.
  VirtualChassisRunner(Bus& bus, const VirtualChassisConfig& config, const Clock& clock);
  ~VirtualChassisRunner();  // stops and joins
  VirtualChassisRunner(const VirtualChassisRunner&) = delete;
  VirtualChassisRunner& operator=(const VirtualChassisRunner&) = delete;

  // Stops the thread (idempotent). The chassis object stays readable.
  void stop();
  bool running() const { return running_.load(); }
  // Why the thread ended early, if it did (empty otherwise).
  std::string failure() const;

  // Runs `f(VirtualChassis&)` with the loop held off: fault injection, snapshots, events.
  template <typename F>
  auto with_chassis(F&& f) {
    std::lock_guard<std::mutex> lock(mutex_);
    return f(*chassis_);
  }

 private:
  void loop();

  Bus& bus_;
  const Clock& clock_;
  mutable std::mutex mutex_;
  std::unique_ptr<VirtualChassis> chassis_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::string failure_;
  std::thread thread_;
};

}  // namespace ranger::sim
