// The feedback store: the latest value of every kind of message the chassis sends, with the time
// it arrived (the owner's clock) and its frame's own timestamp (the bus's clock). The controller,
// the driver runtime, `ranger_can monitor` and the ROS node's freshness checks all read it; only
// record() writes it.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// A feedback message with the owner's time it arrived at and the frame's own timestamp.
template <typename T>
struct Stamped {
  T value;
  Timestamp received{0};  // owner's clock (`now` passed to record)
  Timestamp stamp{0};     // CanFrame::stamp (bus clock)
};

// Whether `entry` is present and arrived at most `max_age` before `now`.
template <typename T>
bool is_fresh(const std::optional<Stamped<T>>& entry, Timestamp now,
              std::chrono::nanoseconds max_age) {
  return entry && now - entry->received <= max_age;
}

struct ChassisFeedback {
  std::optional<Stamped<SystemStatus>> system_status;              // 0x211
  std::optional<Stamped<MotionFeedback>> motion;                   // 0x221
  std::optional<Stamped<MotionModeFeedback>> motion_mode;          // 0x291
  std::optional<Stamped<SteeringAnglesFeedback>> steering_angles;  // 0x271
  std::optional<Stamped<WheelSpeedsFeedback>> wheel_speeds;        // 0x281
  std::array<std::optional<Stamped<MotorHighSpeedFeedback>>, protocol::kMotorCount>
      motor_high_speed;  // 0x251..0x258, index motor - 1
  std::array<std::optional<Stamped<MotorLowSpeedFeedback>>, protocol::kMotorCount>
      motor_low_speed;  // 0x261..0x268, index motor - 1
  std::array<std::optional<Stamped<BmsData>>, protocol::kBatteryCount + 1> bms;  // 0 = pack
  std::array<std::optional<Stamped<BmsAlarm>>, protocol::kBatteryCount + 1> bms_alarm;
  std::array<std::optional<Stamped<UltrasonicFeedback>>, 2> ultrasonic;  // 0x342, 0x343
  std::optional<Stamped<UltrasonicSettingFeedback>> ultrasonic_setting;  // 0x45A
  // The vendor's revisions only (agx_v2, mini_v3): what a manual chassis never sends.
  std::optional<Stamped<LightState>> light_state;                   // 0x231
  std::optional<Stamped<RemoteControlState>> remote_control_state;  // 0x241
  std::optional<Stamped<OdometerFeedback>> odometer;                // 0x311, the front wheels
  std::optional<Stamped<OdometerFeedback>> rear_odometer;           // 0x312 (mini_v3)
  std::string version;         // 0x4A1 answers, concatenated (at most 64 characters kept)
  std::uint64_t messages = 0;  // chassis -> host messages recorded

  // Records a chassis -> host message received at `now` from a frame stamped `stamp`. Host ->
  // chassis messages (another host's commands, our own echo) carry no chassis state: they are
  // not recorded and false is returned.
  bool record(const Message& message, Timestamp stamp, Timestamp now);

  // True once any chassis -> host message was recorded.
  bool heard() const { return messages > 0; }
};

}  // namespace ranger
