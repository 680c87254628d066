// What `ranger_can monitor` knows about a chassis and how it shows it: the latest of every
// feedback message, the commands other nodes sent, frame rates per ID over a sliding window, and
// a text (ANSI) or JSON rendering. No bus and no clock in here: the sub-command feeds frames with
// its own time, and tests feed them from a virtual chassis.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "ranger_can/control/driver.hpp"  // RemoteState, describe(lights)
#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/frame_stats.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::cli {

class ChassisMonitor {
 public:
  // Frames are decoded under `profile` (the chassis's protocol: units, signs, the error word).
  explicit ChassisMonitor(std::chrono::nanoseconds rate_window = std::chrono::seconds(1),
                          ProtocolProfile profile = manual_profile())
      : profile_(std::move(profile)), stats_(rate_window) {}

  // A frame received at `now` (the monitor's clock).
  void on_frame(const CanFrame& frame, Timestamp now);

  // The full view; `color` adds ANSI colours. Lines end with '\n'.
  std::string render_text(std::string_view iface, const BusStatus& bus, Timestamp now,
                          bool color) const;
  // The same content as one JSON object (no newline). Angles and speeds as on the wire (SI units,
  // the manual's signs), like `ranger_can decode --json`.
  std::string render_json(std::string_view iface, const BusStatus& bus, Timestamp now) const;

  // Frames per second of `id` over the window ending at `now`.
  double rate(std::uint32_t id, Timestamp now) const;
  std::uint64_t frames() const { return stats_.total(); }
  // True once any chassis feedback frame decoded.
  bool heard_chassis() const { return fb_.heard(); }
  const ChassisFeedback& feedback() const { return fb_; }

 private:
  template <typename T>
  struct Seen {
    T value;
    Timestamp received{0};
  };

  // render_text's parts, each one or more lines ending with '\n'.
  std::string text_header(std::string_view iface, const BusStatus& bus, Timestamp now,
                          bool color) const;
  std::string text_chassis(Timestamp now, bool color) const;
  std::string text_motion(bool color) const;
  std::string text_host(Timestamp now, bool color) const;
  std::string text_wheels(bool color) const;
  std::string text_wheel(int wheel, bool color) const;
  std::string text_batteries(bool color) const;
  std::string text_ultrasonic() const;
  std::string text_vendor() const;
  std::string text_rates(Timestamp now, bool color) const;

  ProtocolProfile profile_;
  ChassisFeedback fb_;
  std::optional<Seen<MotionCommand>> motion_command_;  // commands from other nodes (the host)
  std::optional<Seen<MotionModeCommand>> motion_mode_command_;
  std::optional<Seen<ControlModeCommand>> control_mode_command_;
  std::optional<Seen<ErrorClearCommand>> error_clear_command_;
  FrameStats stats_;
  std::uint64_t decode_errors_ = 0;
  std::uint64_t error_frames_ = 0;
};

}  // namespace ranger::cli
