// The driver runtime for a sub-command that drives a chassis step by step (`identify`,
// `commission`): on `sim` / `sim:VARIANT` in lock-step with the virtual chassis under a simulated
// clock (deterministic, as fast as the machine), on anything else (a SocketCAN interface, a
// replayed log) on the real clock. Every wait returns early on Ctrl-C (StopSignals).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

namespace ranger::cli {

class DriverSession {
 public:
  // Opens `spec` (ranger::sim::open_bus_source) and starts a driver with `config`. `listen_only`:
  // the driver sends nothing and identifies passively, as on a replayed log (`monitor`).
  static Result<std::unique_ptr<DriverSession>> open(const std::string& spec, DriverConfig config,
                                                     bool listen_only = false);
  ~DriverSession();

  // Replaces the driver (the old one stops: a zero 0x111, and standby if its config says so).
  void restart(DriverConfig config);

  // Steps until `done(snapshot)`, `timeout` of session time, or Ctrl-C; returns done().
  bool run_until(const std::function<bool(const DriverSnapshot&)>& done,
                 std::chrono::nanoseconds timeout);
  void run_for(std::chrono::nanoseconds d);
  // The commander: `request` republished every 50 ms while stepping (nullopt: silent).
  void command(std::optional<MotionRequest> request);

  bool interrupted() const;
  bool simulated() const { return sim_ != nullptr; }
  Timestamp now() const { return clock_->now(); }
  Driver& driver() { return *driver_; }
  std::shared_ptr<const DriverSnapshot> snapshot() const { return driver_->snapshot(); }
  // Stops the driver (its stop, then nothing more is sent).
  void stop();

 private:
  DriverSession() = default;
  void step();

  std::unique_ptr<ManualClock> manual_;
  std::unique_ptr<SteadyClock> steady_;
  const Clock* clock_ = nullptr;
  std::shared_ptr<BusSource> source_;
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  std::optional<MotionRequest> request_;
  Timestamp next_publish_{0};
};

}  // namespace ranger::cli
