// Runs a VirtualChassis on a thread of its own against a real clock: what `ranger_can sim` and
// the end-to-end tests on vcan use. The chassis logic stays in VirtualChassis (deterministic,
// driven by injected time); this class only supplies the loop: wait for a frame or the next
// deadline, hand every waiting frame over, step.
//
// A busy host may not run that thread for a while. A real chassis would go on sending meanwhile,
// its frames waiting in the kernel's queue; here catch_up() brings the chassis to the clock's now
// from any thread (the in-process bus of sim_bus_source.hpp calls it before a reader takes what
// has arrived), and the chassis sends the frames of the time that passed stamped with their due
// times (VirtualChassisConfig::replay_window). So a slow host never looks like a silent chassis.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "ranger_can/clock.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/transport/bus.hpp"

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

  // Hands the chassis every frame waiting for it and steps it to the clock's now, on the calling
  // thread (nothing once stopped).
  void catch_up();

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
  bool closed_ = false;  // stop() was called (under mutex_): catch_up() does nothing
  std::string failure_;
  std::thread thread_;
};

}  // namespace ranger::sim
