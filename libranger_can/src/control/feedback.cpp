#include "ranger_can/control/feedback.hpp"

#include <type_traits>
#include <variant>

namespace ranger {

bool ChassisFeedback::record(const Message& message, Timestamp stamp, Timestamp now) {
  const bool recorded = std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        const Stamped<T> s{m, now, stamp};
        if constexpr (std::is_same_v<T, SystemStatus>) {
          system_status = s;
        } else if constexpr (std::is_same_v<T, MotionFeedback>) {
          motion = s;
        } else if constexpr (std::is_same_v<T, MotionModeFeedback>) {
          motion_mode = s;
        } else if constexpr (std::is_same_v<T, SteeringAnglesFeedback>) {
          steering_angles = s;
        } else if constexpr (std::is_same_v<T, WheelSpeedsFeedback>) {
          wheel_speeds = s;
        } else if constexpr (std::is_same_v<T, MotorHighSpeedFeedback>) {
          if (m.motor < 1 || m.motor > protocol::kMotorCount) return false;
          motor_high_speed[static_cast<std::size_t>(m.motor - 1)] = s;
        } else if constexpr (std::is_same_v<T, MotorLowSpeedFeedback>) {
          if (m.motor < 1 || m.motor > protocol::kMotorCount) return false;
          motor_low_speed[static_cast<std::size_t>(m.motor - 1)] = s;
        } else if constexpr (std::is_same_v<T, BmsData>) {
          if (m.battery < 0 || m.battery > protocol::kBatteryCount) return false;
          bms[static_cast<std::size_t>(m.battery)] = s;
        } else if constexpr (std::is_same_v<T, BmsAlarm>) {
          if (m.battery < 0 || m.battery > protocol::kBatteryCount) return false;
          bms_alarm[static_cast<std::size_t>(m.battery)] = s;
        } else if constexpr (std::is_same_v<T, UltrasonicFeedback>) {
          ultrasonic[m.first_sensor == 5 ? 1 : 0] = s;
        } else if constexpr (std::is_same_v<T, UltrasonicSettingFeedback>) {
          ultrasonic_setting = s;
        } else if constexpr (std::is_same_v<T, LightState>) {
          light_state = s;
        } else if constexpr (std::is_same_v<T, RemoteControlState>) {
          remote_control_state = s;
        } else if constexpr (std::is_same_v<T, OdometerFeedback>) {
          (m.rear ? rear_odometer : odometer) = s;
        } else if constexpr (std::is_same_v<T, VersionResponse>) {
          constexpr std::size_t kMaxVersion = 64;
          const std::string_view text = m.view();
          version.append(text.substr(0, kMaxVersion - std::min(kMaxVersion, version.size())));
        } else {
          return false;  // host -> chassis
        }
        return true;
      },
      message);
  if (recorded) ++messages;
  return recorded;
}

}  // namespace ranger
