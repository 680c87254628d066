// The node's CAN side: one thread that owns the bus, libranger_can's ChassisController, the
// odometry and the joint tracker. It wakes when the controller's next tick is due (at most every
// 20 ms) or when a command arrives, feeds every frame received meanwhile to the controller and
// the odometry, and ticks the controller. ROS callbacks never touch the bus: they post commands
// through the mutex-protected API below (the controller only records them; the CAN thread sends)
// and read copies of the state through snapshot().
//
// port_name "sim" runs the in-process virtual chassis (ranger::sim::VirtualChassis) on a
// LoopbackNetwork, on its own thread (VirtualChassisRunner), so the node is usable without
// hardware and without kernel CAN support.
//
// A CAN interface that is missing at start-up is retried every reconnect_interval; one that
// disappears later is reopened by the bus itself. Neither stops the node: snapshot() reports it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <ranger_can/transport/bus.hpp>
#include <ranger_can/clock.hpp>
#include <ranger_can/control/controller.hpp>
#include <ranger_can/transport/loopback_bus.hpp>
#include <ranger_can/control/odometry.hpp>
#include <ranger_can/result.hpp>
#include <ranger_can/sim/virtual_chassis.hpp>
#include <ranger_can/sim/virtual_chassis_runner.hpp>

#include "ranger_base/wheel_joints.hpp"

namespace ranger_base {

struct ChassisLinkOptions {
  std::string port_name = "can0";
  ranger::ControllerConfig controller;
  ranger::OdometryConfig odometry;
  std::chrono::nanoseconds reconnect_interval = std::chrono::seconds(1);
  // Set: run the in-process virtual chassis with this configuration (port_name is then only a
  // label).
  std::optional<ranger::sim::VirtualChassisConfig> sim;
  std::uint32_t sim_error_bits = 0;  // injected into the virtual chassis at boot
};

// A 0x111 the controller has just sent, for cmd_vel_out and latency measurements.
struct MotionCommandEvent {
  std::chrono::system_clock::time_point sent;          // wall time right after the send
  ranger::MotionCommand command;                       // as on the wire (manual signs)
  std::optional<ranger::KinematicsSolution> solution;  // mode and achieved twist (REP-103)
};

// A consistent copy of everything the ROS side publishes.
struct LinkSnapshot {
  ranger::Timestamp now{0};  // the link's clock at the time of the copy
  std::string port_name;
  bool bus_open = false;
  std::string bus_error;  // why the bus could not be opened (while !bus_open)
  ranger::BusStatus bus;
  bool has_controller = false;
  ranger::ControllerState controller;
  ranger::OdometryState odometry;
  WheelJoints joints;
  std::map<std::uint32_t, std::uint64_t> frames_by_id;  // data frames received, per ID
  std::uint64_t frames_received = 0;
  std::uint64_t loop_iterations = 0;
  std::optional<ranger::sim::ChassisSnapshot> sim;  // ground truth (port_name = sim)
  std::string sim_failure;
};

class ChassisLink {
 public:
  using CommandObserver = std::function<void(const MotionCommandEvent&)>;

  // `clock` (the controller's monotonic time) must outlive the link.
  explicit ChassisLink(ChassisLinkOptions options, const ranger::Clock& clock);
  ~ChassisLink();  // stop()
  ChassisLink(const ChassisLink&) = delete;
  ChassisLink& operator=(const ChassisLink&) = delete;

  // Starts the CAN thread. `observer` is called on that thread (outside the lock) after each
  // 0x111; it must not block.
  void start(CommandObserver observer = {});
  // Sends a stop (zero 0x111 via ChassisController::shutdown) and joins the thread. Idempotent.
  void stop();

  // ---- commands (any thread; they never wait for the bus) ----
  // kNotFinite for NaN/inf (the controller then commands zero); kInterfaceDown before the bus
  // was ever opened.
  ranger::Status set_command(const ranger::MotionRequest& request);
  void request_motion_mode(std::optional<ranger::protocol::MotionMode> mode);
  ranger::Status clear_errors(std::uint8_t code);
  ranger::Status set_ultrasonic(bool enable);

  LinkSnapshot snapshot() const;
  bool is_sim() const { return options_.sim.has_value(); }

  // Runs `f` on the virtual chassis with its loop held off (fault injection in tests). False when
  // there is no virtual chassis.
  bool with_sim(const std::function<void(ranger::sim::VirtualChassis&)>& f);
  // The in-process network of the virtual chassis (link down/up, error frames in tests); null
  // when not in sim mode.
  ranger::LoopbackNetwork* sim_network() { return network_.get(); }

 private:
  void loop();
  void try_open(ranger::Timestamp now);                                     // lock held
  void drain_and_tick(ranger::Timestamp now);                               // lock held
  void handle_frame(const ranger::CanFrame& frame, ranger::Timestamp now);  // lock held
  void wake();
  void wait(std::chrono::nanoseconds timeout);  // until a command wakes us, at most `timeout`

  const ChassisLinkOptions options_;
  const ranger::Clock& clock_;
  CommandObserver observer_;

  // Declaration order = reverse destruction order: the controller (which sends a stop from its
  // destructor) goes first, the buses and the network last.
  std::unique_ptr<ranger::LoopbackNetwork> network_;
  std::unique_ptr<ranger::Bus> sim_bus_;
  std::unique_ptr<ranger::sim::VirtualChassisRunner> runner_;

  mutable std::mutex mutex_;  // guards everything below
  std::unique_ptr<ranger::Bus> bus_;
  std::unique_ptr<ranger::ChassisController> controller_;
  ranger::Odometry odometry_;
  WheelJointTracker joints_;
  std::optional<std::optional<ranger::protocol::MotionMode>> pending_mode_;  // before connect
  std::string bus_error_;
  ranger::Timestamp next_open_attempt_{0};
  std::map<std::uint32_t, std::uint64_t> frames_by_id_;
  std::uint64_t frames_received_ = 0;
  std::uint64_t loop_iterations_ = 0;
  std::uint64_t motion_commands_seen_ = 0;
  std::vector<MotionCommandEvent> pending_events_;

  int wake_fd_ = -1;  // eventfd: commands wake the CAN thread so a new 0x111 goes out at once
  std::atomic<bool> stop_requested_{false};
  bool stopped_ = false;
  std::thread thread_;
};

}  // namespace ranger_base
