// The driver's safety rules checked on the wire: a passive observer that sees every frame on the
// bus in order (host and chassis alike) and records each frame that breaks a rule. Every fault
// test feeds it the whole trace and ends by asserting that it found nothing: the same oracle the
// controller fuzzer (libranger_can/fuzz/fuzz_controller.cpp) applies in-process, here applied to
// what actually crossed the bus.
//
// Rules (controller.hpp's behaviour, judged only from frames and their bus timestamps):
//  1. A 0x111 with non-zero motion (linear or spin speed) goes out only while the last 0x211 is
//     at most `link_timeout` old and said CAN command mode, no e-stop and no critical error bit,
//     the last 0x291 named a known mode and was not switching, and the last BMS pack frame (if
//     any) reported a SOC at or above the cut-off.
//  2. No 0x421 asks for CAN mode while the last 0x211 said remote control (never fight the remote).
//  3. Every host frame (0x111, 0x141, 0x421, 0x441, 0x451) decodes: no wrong DLC, no NaN field.
//  4. No moving 0x111 after an involuntary stop until a re-arm: once the wire showed an e-stop,
//     remote control, a critical error bit, a low battery or a silent chassis (no 0x211 for
//     longer than link_timeout), motion is a violation until the caller re-armed (resume,
//     reported by the rig through on_rearm_attempt: a zero twist is no re-arm) at a time the wire
//     showed none of those any more.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::faults {

class WireAudit {
 public:
  // `stamp_slack`: how much later than the observer the driver may have received a frame (0 in
  // lock-step rigs; a few ms where the driver and the observer are separate sockets).
  explicit WireAudit(const ControllerConfig& config = {},
                     std::chrono::nanoseconds stamp_slack = std::chrono::nanoseconds{0})
      : config_(config), slack_(stamp_slack) {}

  void on_frame(const CanFrame& f) {
    if (f.is_error) {
      ++error_frames_;
      return;
    }
    ++counts_[f.id];
    const auto message = decode(f);
    if (!message) {
      if (is_host_id(f.id)) violation(f, "host frame does not decode: " + message.error().message);
      return;
    }
    if (status_ && f.stamp - status_stamp_ > config_.link_timeout + slack_ && !blind_) {
      latched_ = true;  // the chassis fell silent: an involuntary stop
    }
    if (const auto* s = std::get_if<SystemStatus>(&*message)) {
      status_ = *s;
      status_stamp_ = f.stamp;
      if (cause_active()) latched_ = true;
    } else if (const auto* m = std::get_if<MotionModeFeedback>(&*message)) {
      mode_ = *m;
    } else if (const auto* b = std::get_if<BmsData>(&*message)) {
      if (b->battery == 0) soc_ = b->soc;
      if (cause_active()) latched_ = true;
    } else if (const auto* c = std::get_if<MotionCommand>(&*message)) {
      check_motion(f, *c);
    } else if (const auto* r = std::get_if<ControlModeCommand>(&*message)) {
      if (r->mode == protocol::ControlMode::kCan && status_ &&
          status_->control_mode_raw == static_cast<std::uint8_t>(protocol::ControlMode::kRemote)) {
        violation(f, "0x421 requests CAN mode while the remote control has the chassis");
      }
    }
  }

  // The caller asked for a re-arm at `t` (resume): it counts if the wire shows no
  // involuntary-stop cause at that time.
  void on_rearm_attempt(Timestamp t) {
    if (!cause_active() && !(status_ && t - status_stamp_ > config_.link_timeout + slack_)) {
      latched_ = false;
    }
  }
  bool latched() const { return latched_; }

  // The observer itself lost the bus (its interface went down): what it knew may be stale and
  // it may miss frames the driver sees. Motion is not judged again until the observer has seen a
  // fresh 0x211 and 0x291.
  void forget() {
    status_.reset();
    mode_.reset();
    blind_ = true;
  }

  const std::vector<std::string>& violations() const { return violations_; }
  std::uint64_t count(std::uint32_t id) const {
    const auto it = counts_.find(id);
    return it == counts_.end() ? 0 : it->second;
  }
  std::uint64_t error_frames() const { return error_frames_; }
  std::uint64_t moving_commands() const { return moving_commands_; }

 private:
  static bool is_host_id(std::uint32_t id) {
    return id == protocol::kMotionCommandId || id == protocol::kMotionModeCommandId ||
           id == protocol::kControlModeCommandId || id == protocol::kErrorClearCommandId ||
           id == protocol::kUltrasonicSettingId;
  }

  bool cause_active() const {
    if (soc_ && *soc_ < config_.low_battery_soc) return true;
    if (!status_) return false;
    return status_->control_mode_raw == static_cast<std::uint8_t>(protocol::ControlMode::kRemote) ||
           status_->vehicle_status_raw ==
               static_cast<std::uint8_t>(protocol::VehicleStatus::kEmergencyStop) ||
           protocol::is_critical_error(status_->error_bits);
  }

  void check_motion(const CanFrame& f, const MotionCommand& c) {
    if (c.linear_speed == 0.0 && c.spin_speed == 0.0) return;
    ++moving_commands_;
    if (blind_) {
      if (!status_ || !mode_) return;
      blind_ = false;
    }
    if (!status_) return violation(f, "motion before any 0x211");
    if (f.stamp - status_stamp_ > config_.link_timeout + slack_) {
      return violation(f, "motion while the last 0x211 is stale");
    }
    if (status_->control_mode_raw != static_cast<std::uint8_t>(protocol::ControlMode::kCan)) {
      return violation(f, "motion while the chassis is not in CAN command mode");
    }
    if (status_->vehicle_status_raw ==
        static_cast<std::uint8_t>(protocol::VehicleStatus::kEmergencyStop)) {
      return violation(f, "motion during an emergency stop");
    }
    if (protocol::is_critical_error(status_->error_bits)) {
      return violation(f, "motion with a critical error bit set");
    }
    if (!mode_ || mode_->mode_raw > static_cast<std::uint8_t>(protocol::MotionMode::kSpin)) {
      return violation(f, "motion while the motion mode is unknown");
    }
    if (mode_->switching) return violation(f, "motion while the chassis is switching modes");
    if (soc_ && *soc_ < config_.low_battery_soc) return violation(f, "motion on a low battery");
    if (latched_) return violation(f, "motion after an involuntary stop without a re-arm");
  }

  void violation(const CanFrame& f, const std::string& what) {
    char head[64];
    std::snprintf(head, sizeof head,
                  "t=%.3f s 0x%03X: ", std::chrono::duration<double>(f.stamp).count(), f.id);
    violations_.push_back(head + what);
  }

  ControllerConfig config_;
  std::chrono::nanoseconds slack_;
  std::optional<SystemStatus> status_;
  Timestamp status_stamp_{0};
  std::optional<MotionModeFeedback> mode_;
  std::optional<double> soc_;
  bool blind_ = false;
  bool latched_ = false;  // an involuntary stop seen on the wire, not yet re-armed
  std::map<std::uint32_t, std::uint64_t> counts_;
  std::uint64_t error_frames_ = 0;
  std::uint64_t moving_commands_ = 0;
  std::vector<std::string> violations_;
};

}  // namespace ranger::faults
