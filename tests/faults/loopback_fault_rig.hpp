// The lock-step rig of the fault suite: the driver (ChassisController, as the ROS node runs it)
// and the virtual chassis on one in-process LoopbackNetwork, plus two more nodes on that bus: an
// observer that records every frame (and feeds the WireAudit) and a noise source. A ManualClock
// advances 1 ms per step; each step the noise source sends, the chassis handles what arrived and
// sends what fell due, the driver reads, decides and sends, and the observer reads. Nothing
// sleeps and nothing depends on the machine's speed: timing assertions are exact.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "wire_audit.hpp"

namespace ranger::faults {

using namespace std::chrono_literals;

class LoopbackFaultRig {
 public:
  static constexpr std::chrono::nanoseconds kStep = 1ms;
  // How often the caller (a teleop, move_base) repeats its command: 50 Hz cmd_vel.
  static constexpr std::chrono::nanoseconds kCallerPeriod = 20ms;

  explicit LoopbackFaultRig(const sim::VirtualChassisConfig& chassis_config = {},
                            const ControllerConfig& controller_config = {})
      : clock_(Timestamp{std::chrono::seconds(1000)}),
        network_(options(clock_)),
        chassis_bus_(network_.connect()),
        driver_bus_(network_.connect()),
        observer_bus_(network_.connect()),
        noise_bus_(network_.connect()),
        chassis_(*chassis_bus_, chassis_config, clock_.now()),
        controller_(std::make_unique<ChassisController>(*driver_bus_, controller_config)),
        audit_(controller_config) {
    observer_bus_->set_filter({});    // the observer hears every ID
    noise_bus_->set_filter({0x7FE});  // the noise source listens to nothing anyone sends
  }
  // The controller sends its stop when destroyed: it goes first, while its bus exists.
  ~LoopbackFaultRig() { controller_.reset(); }

  LoopbackFaultRig(const LoopbackFaultRig&) = delete;
  LoopbackFaultRig& operator=(const LoopbackFaultRig&) = delete;

  // ---- time
  Timestamp now() const { return clock_.now(); }
  void step() {
    clock_.advance(kStep);
    const Timestamp t = clock_.now();
    if (each_step) each_step(t);
    chassis_.poll(t);
    if (driver_alive_) {
      for (auto f = driver_bus_->receive(0ns); f; f = driver_bus_->receive(0ns)) {
        controller_->on_frame(*f, t);
      }
      if (request_ && t >= next_request_) {
        last_request_status_ = controller_->set_command(*request_, t);
        next_request_ = t + kCallerPeriod;
      }
      controller_->tick(t);
    }
    for (;;) {
      auto f = observer_bus_->receive(0ns);
      if (!f) {
        if (f.error().code == Errc::kInterfaceDown) audit_.forget();
        break;
      }
      trace_.push_back(*f);
      audit_.on_frame(*f);
    }
  }
  void run_for(std::chrono::nanoseconds d) {
    const Timestamp end = now() + d;
    while (now() < end)
      step();
  }
  // Steps until `done()` holds (true) or `timeout` passed (false).
  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    const Timestamp end = now() + timeout;
    while (!done()) {
      if (now() >= end) return false;
      step();
    }
    return true;
  }
  // Called at the start of every step with the step's time (noise, floods, probes).
  std::function<void(Timestamp)> each_step;

  // ---- the caller and the driver process
  // The caller wants `request` from now on, repeated every kCallerPeriod.
  void command(const BodyTwist& twist, std::optional<protocol::MotionMode> mode = std::nullopt) {
    request_ = MotionRequest{twist, mode};
    next_request_ = now();
  }
  void stop_commanding() { request_.reset(); }
  // The explicit re-arm (the node's `resume` service).
  Status resume() {
    audit_.on_rearm_attempt(now());
    return controller_->resume(now());
  }
  const Status& last_request_status() const { return last_request_status_; }
  // The driver process dies: nothing is read, decided or sent any more (no shutdown, no stop).
  void kill_driver() { driver_alive_ = false; }

  // ---- the parts
  ChassisController& controller() { return *controller_; }
  const ControllerState& state() const { return controller_->state(); }
  sim::VirtualChassis& chassis() { return chassis_; }
  sim::ChassisSnapshot snapshot() const { return chassis_.snapshot(); }
  LoopbackNetwork& network() { return network_; }
  LoopbackBus& driver_bus() { return *driver_bus_; }
  LoopbackBus& chassis_bus() { return *chassis_bus_; }
  LoopbackBus& noise_bus() { return *noise_bus_; }
  const WireAudit& audit() const { return audit_; }
  // Every frame the observer received (data and error frames), in order, stamped on delivery.
  const std::vector<CanFrame>& trace() const { return trace_; }

  // Frames on the wire with `id` stamped in [from, to).
  std::vector<CanFrame> wire(std::uint32_t id, Timestamp from,
                             Timestamp to = Timestamp::max()) const {
    std::vector<CanFrame> out;
    for (const CanFrame& f : trace_) {
      if (!f.is_error && f.id == id && f.stamp >= from && f.stamp < to) out.push_back(f);
    }
    return out;
  }

  // Brings the chassis into CAN command mode with a known motion mode and nothing refused.
  ::testing::AssertionResult connect() {
    const bool ok = run_until(
        [&] {
          return state().control_mode == protocol::ControlMode::kCan && state().motion_mode &&
                 state().refusal == MotionRefusal::kNone;
        },
        3s);
    if (ok) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "no CAN command mode after 3 s; refusal " << to_string(state().refusal);
  }
  // After an involuntary stop whose cause has cleared: the chassis stays at rest although the
  // caller still asks for `twist` (kRearmRequired, for a whole second), and after a zero twist
  // and `twist` again (a zero twist is no re-arm); resume re-arms and `twist` then drives it up
  // to `speed` again.
  ::testing::AssertionResult latched_then_rearmed_by_resume(const BodyTwist& twist, double speed) {
    command(twist);
    if (!run_until([&] { return state().refusal == MotionRefusal::kRearmRequired; }, 3s)) {
      return ::testing::AssertionFailure()
             << "no kRearmRequired; refusal " << to_string(state().refusal);
    }
    for (const BodyTwist& asked : {twist, BodyTwist{}, twist}) {
      command(asked);
      const Timestamp until = now() + std::chrono::milliseconds(500);
      while (now() < until) {
        step();
        if (snapshot().speed != 0.0) return ::testing::AssertionFailure() << "moved unasked";
        if (state().refusal != MotionRefusal::kRearmRequired) {
          return ::testing::AssertionFailure()
                 << "re-armed without resume; refusal " << to_string(state().refusal);
        }
      }
    }
    if (Status st = resume(); !st) {
      return ::testing::AssertionFailure() << "resume refused: " << st.error().message;
    }
    step();
    if (state().refusal == MotionRefusal::kRearmRequired) {
      return ::testing::AssertionFailure() << "resume did not re-arm";
    }
    command(twist);
    if (run_until([&] { return std::abs(snapshot().speed - speed) < 1e-9; }, 10s)) {
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "chassis at " << snapshot().speed << " m/s after the "
                                         << "re-arm; refusal " << to_string(state().refusal);
  }

  // connect(), then drives `twist` until the chassis moves at `speed` (exactly, the model settles).
  ::testing::AssertionResult drive(const BodyTwist& twist, double speed) {
    if (auto r = connect(); !r) return r;
    command(twist);
    if (run_until([&] { return std::abs(snapshot().speed - speed) < 1e-9; }, 10s)) {
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "chassis at " << snapshot().speed << " m/s, not "
                                         << speed << "; refusal " << to_string(state().refusal);
  }

 private:
  static LoopbackOptions options(const Clock& clock) {
    LoopbackOptions o;
    o.interface = "faults0";
    o.clock = &clock;
    return o;
  }

  ManualClock clock_;
  LoopbackNetwork network_;
  std::unique_ptr<LoopbackBus> chassis_bus_;
  std::unique_ptr<LoopbackBus> driver_bus_;
  std::unique_ptr<LoopbackBus> observer_bus_;
  std::unique_ptr<LoopbackBus> noise_bus_;
  sim::VirtualChassis chassis_;
  std::unique_ptr<ChassisController> controller_;
  WireAudit audit_;
  std::vector<CanFrame> trace_;

  std::optional<MotionRequest> request_;
  Timestamp next_request_{0};
  Status last_request_status_ = ok_status();
  bool driver_alive_ = true;
};

}  // namespace ranger::faults
