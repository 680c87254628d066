// What the driver runtime (driver.hpp) publishes after every iteration: a consistent, immutable
// copy of its state that other threads read without waiting for the driver.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/frame_stats.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/joint_tracker.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/control/request_book.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

// Where the protocol settings come from.
enum class ProtocolChoice {
  kForced,  // controller.profile as it is (a preset, --set values, a commissioning file)
  kAuto,    // identified from the chassis before anything moves (identification.hpp)
};
inline constexpr auto kProtocolChoiceNames = text::enum_names<ProtocolChoice>({
    {ProtocolChoice::kForced, "forced"},
    {ProtocolChoice::kAuto, "auto"},
});
inline std::string_view to_string(ProtocolChoice c) {
  return kProtocolChoiceNames.name(c);
}

// A consistent copy of the runtime's state, published after every iteration. (The driver
// refills snapshots no reader holds any more: it assigns every field.)
struct DriverSnapshot {
  std::uint64_t sequence = 0;  // increases with every publication
  Timestamp now{0};            // driver clock at publication

  std::string bus_name;    // the spec: "can0", "sim", "replay:FILE"
  bool bus_open = false;   // false until the first successful open
  bool read_only = false;  // a replayed log: nothing is sent
  std::string bus_error;   // why the bus is not open (while !bus_open)
  BusStatus bus;           // state, detail, counters of the open bus

  ControllerState controller;
  ChassisFeedback feedback;
  // Odometry, TF and joint states are known only while the chassis is heard: false before the
  // first frame and while the link is lost (the pose resumes from where it was).
  bool motion_known = false;
  OdometryState odometry;
  WheelJoints joints;
  FrameStats frames;
  ProtocolProfile profile;  // the settings in use (the identification's proposal until decided)

  // Where the settings came from, and (kAuto) the identification: phase, decided profile,
  // evidence lines, confidence, and the failure message naming what to set.
  ProtocolChoice protocol = ProtocolChoice::kForced;
  // (Shared between snapshots while it does not change: after the decision it rarely does.)
  std::shared_ptr<const IdentificationStatus> identification;
  // The plausibility monitors: persistent mismatches (WARN, with the value to try) and the one
  // that stopped the robot (also ControllerState::implausible_reason).
  PlausibilityStatus plausibility;

  std::vector<RequestOutcome> requests;  // the most recent ones, oldest first (at most 16)
  std::uint64_t loop_iterations = 0;

  // The vendor's additions: whether the chassis has them, the remote control's and the lights'
  // last reported state (nullopt until received), and the firmware version.
  VendorFrames vendor_frames = VendorFrames::kUnknown;
  std::optional<RemoteState> remote;
  std::optional<LightsState> lights;
  FirmwareVersion firmware;

  // The outcome of request `id`, if it is still in the list.
  const RequestOutcome* request(std::uint64_t id) const;
};

}  // namespace ranger
