// Where the driver's events (driver_events.hpp) come from: the one place that decides what is a
// transition. The driver shows it every snapshot it publishes (observe: the bus, the link, the
// control mode, the refusal, the re-arm latch, the identification, the plausibility monitors,
// the faults, park, lights, the firmware version) and tells it what happens in between (a
// refused command, a frame sent, a request settled, padding found, set_motion_mode applied);
// the tracker keeps what it last reported and appends an event only for a change, spacing the
// reports that could repeat (refused and adjusted commands). Pure and clock-free: time is the
// snapshot's, or the caller's.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/control/driver_snapshot.hpp"
#include "ranger_can/result.hpp"

namespace ranger {

struct EventTrackerConfig {
  std::string bus;         // the bus spec the events name
  bool socketcan = false;  // a SocketCAN interface: the bring-up and commissioning hints
  // Whether the driver commands the chassis: a listen-only or read-only driver (a monitor, a
  // replayed log) refuses nothing and latches nothing, so it reports neither.
  bool commands = true;
  std::chrono::nanoseconds reconnect_interval = std::chrono::seconds(1);
  std::chrono::nanoseconds link_timeout = std::chrono::milliseconds(100);
  // "still waiting for the chassis" while nothing was heard since the bus opened.
  std::chrono::nanoseconds waiting_reminder = std::chrono::seconds(30);
  // At most one report per interval: a non-finite command, another refused command, a command
  // adjusted to what the chassis can do.
  std::chrono::nanoseconds not_finite_interval = std::chrono::seconds(1);
  std::chrono::nanoseconds refused_interval = std::chrono::seconds(5);
  std::chrono::nanoseconds adjusted_interval = std::chrono::seconds(5);
};

class DriverEventTracker {
 public:
  explicit DriverEventTracker(EventTrackerConfig config) : config_(std::move(config)) {}

  // The snapshot just published; `resumed`: a resume() went through in this iteration (a re-arm
  // it caused says so). Appends the transitions since the previous snapshot to `out`.
  void observe(const DriverSnapshot& s, bool resumed, std::vector<DriverEvent>& out);

  // `count` commands refused since the last call, the last with `error`.
  void command_refused(const Error& error, std::uint64_t count, Timestamp now,
                       std::vector<DriverEvent>& out);
  // A frame the controller sent (the stop at shutdown; a motion command adjusted).
  void frame_sent(const SentFrame& sent, Timestamp now, std::vector<DriverEvent>& out);
  // The driver stopped without sending a stop, and why.
  void no_stop_sent(std::string why, Timestamp now, std::vector<DriverEvent>& out);
  void request_settled(const RequestOutcome& outcome, Timestamp now, std::vector<DriverEvent>& out);
  void motion_mode_requested(std::optional<protocol::MotionMode> mode, Timestamp now,
                             std::vector<DriverEvent>& out);
  // The first frame of `id` longer than its layout.
  void frames_padded(std::uint32_t id, Timestamp now, std::vector<DriverEvent>& out);

 private:
  void observe_bus(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_link(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_control_mode(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_identification(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_plausibility(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_refusal(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_rearm(const DriverSnapshot& s, bool resumed, std::vector<DriverEvent>& out);
  void observe_faults(const DriverSnapshot& s, std::vector<DriverEvent>& out);
  void observe_vendor(const DriverSnapshot& s, std::vector<DriverEvent>& out);

  EventTrackerConfig config_;
  // What was last reported.
  std::string bus_error_;
  bool bus_open_ = false;
  Timestamp opened_{0}, next_reminder_{0};
  std::optional<LinkState> link_;
  bool control_mode_known_ = false;
  std::optional<protocol::ControlMode> control_mode_;
  std::uint8_t control_mode_raw_ = 0;
  std::optional<MotionRefusal> refusal_;
  StopCauses latched_ = 0;
  std::shared_ptr<const IdentificationStatus> identification_;  // the status last looked at
  std::optional<IdentificationPhase> phase_;
  bool identification_reported_ = false;  // its decision or failure
  std::size_t decisions_reported_ = 0;    // decisions reported (learned ones after)
  std::set<std::string> warned_;          // plausibility warnings, by check|setting|value
  std::string stop_reported_;             // the plausibility stop, by check|setting|since
  std::uint32_t error_bits_ = 0;
  bool parked_ = false;
  std::optional<LightsState> lights_;
  std::string firmware_;
  // Spacing of repeated reports.
  Timestamp next_not_finite_{0}, next_refused_{0}, next_adjusted_{0};
  std::uint64_t unreported_not_finite_ = 0, unreported_refused_ = 0;
};

}  // namespace ranger
