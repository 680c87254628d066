// The driver and a virtual chassis (`sim` or `sim:VARIANT`) in lock-step under a ManualClock, for
// the identification and plausibility tests: a commander that republishes its twist every 50 ms,
// the route of the end-to-end suite (Ackermann arc, crab, spin) with its odometry budget, and the
// time and distance until a plausibility stop.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

namespace ranger::test {

DriverConfig auto_config();
DriverConfig forced_config(const ProtocolProfile& profile);

class IdentifyRig {
 public:
  IdentifyRig(const std::string& spec, DriverConfig config, sim::SimSourceOptions options = {});
  ~IdentifyRig();

  void step();  // 1 ms: the commander, the chassis, then the driver
  void run_for(std::chrono::nanoseconds d);
  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout);
  // The commander wants `twist` (in `mode`) from now on (nullopt: stops publishing).
  void command(const BodyTwist& twist, std::optional<protocol::MotionMode> mode = std::nullopt);
  void command(const MotionRequest& request);  // the same with every field of the request
  void silence() { request_.reset(); }
  // CAN mode, a known motion mode, and (auto) the identification decided.
  bool wait_ready(bool allow_any_refusal = false);
  void drive(const BodyTwist& twist, std::optional<protocol::MotionMode> mode,
             std::chrono::nanoseconds d, const std::function<void()>& each_step = {});
  // Drives until the plausibility stop (refusal kImplausible) or `timeout`; true if it stopped.
  bool drive_until_stopped(const BodyTwist& twist, std::optional<protocol::MotionMode> mode,
                           std::chrono::nanoseconds timeout);
  std::chrono::nanoseconds stopped_after() const { return stopped_after_; }
  // The operator answers a latched stop (kRearmRequired) with resume (the teleop's re-arm key),
  // then the commander goes on with its twist; counted.
  void set_rearm(bool on) { rearm_ = on; }
  int rearms() const { return rearms_; }
  // Drives the route and checks the odometry against the ground truth (<= 1 % of the distance,
  // <= 1 deg of heading per turn); prints "[route] ...".
  void expect_route(const std::string& label, double min_turns = 1.0);

  Driver& driver() { return *driver_; }
  sim::SimBusSource& sim() { return *sim_; }
  std::shared_ptr<const DriverSnapshot> snapshot() const { return driver_->snapshot(); }
  sim::ChassisSnapshot truth() { return sim_->snapshot(); }
  const std::vector<SentEvent>& sent() const { return sent_; }
  bool saw_refusal(MotionRefusal r) const;
  Timestamp start() const { return start_; }
  Timestamp first_send() const;
  Timestamp now() const { return clock_.now(); }

 private:
  ManualClock clock_{Timestamp(std::chrono::seconds(1000))};
  Timestamp start_;
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
  std::vector<SentEvent> sent_;
  std::vector<MotionRefusal> refusals_;
  std::optional<MotionRequest> request_;
  Timestamp next_publish_{0};
  std::chrono::nanoseconds stopped_after_{0};
  bool rearm_ = false;
  int rearms_ = 0;
  bool rearming_ = false;
};

}  // namespace ranger::test
