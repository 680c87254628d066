// The lock-step rig (support/driver_sim_rig.hpp) on a bus spec (`sim` or `sim:VARIANT`) as it is,
// for the identification, plausibility, events and adversarial tests: a commander that
// republishes its twist every 50 ms (before the chassis steps), the refusals the driver went
// through (after it steps), the route of the end-to-end suite (Ackermann arc, crab, spin) with its
// odometry budget, and the time and distance until a plausibility stop.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "support/driver_sim_rig.hpp"

namespace ranger::test {

DriverConfig auto_config();
DriverConfig forced_config(const ProtocolProfile& profile);
// A protocol preset by its name (one that exists: "manual", "agx_v2", "mini_v3").
ProtocolProfile preset(const char* name);

// Each step (1 ms): the commander, the chassis, then the driver.
class IdentifyRig : public DriverSimRig {
 public:
  // `config` should pass validate() (checked).
  IdentifyRig(const std::string& spec, DriverConfig config, sim::SimSourceOptions options = {});

  // The commander wants `twist` (in `mode`) from now on (nullopt: stops publishing).
  void command(const BodyTwist& twist, std::optional<protocol::MotionMode> mode = std::nullopt);
  void command(const MotionRequest& request);  // the same with every field of the request
  void silence() { request_.reset(); }
  // CAN mode, a known motion mode, and (auto) the identification decided.
  bool wait_ready(bool allow_any_refusal = false);
  // The commander wants `twist` for `d` (and goes on wanting it); `each_step` after every step.
  // (DriverSimRig::drive, the commander of a stretch that stops at its end, is hidden.)
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
  // Drives the route and checks the odometry against the ground truth (chassis(): <= 1 % of the
  // distance, <= 1 deg of heading per turn); prints "[route] ...".
  void expect_route(const std::string& label, double min_turns = 1.0);

  bool saw_refusal(MotionRefusal r) const;
  Timestamp start() const { return start_; }
  Timestamp first_send() const;

 private:
  void chassis_stepping() override;  // the commander (or the operator's re-arm)
  void driver_stepped() override;    // the refusal, when it changed

  Timestamp start_;
  std::vector<MotionRefusal> refusals_;
  std::optional<MotionRequest> request_;
  Timestamp next_publish_{0};
  std::chrono::nanoseconds stopped_after_{0};
  bool rearm_ = false;
  int rearms_ = 0;
  bool rearming_ = false;
};

}  // namespace ranger::test
