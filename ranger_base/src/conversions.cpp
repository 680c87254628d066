#include "ranger_base/conversions.hpp"

#include <tf2/LinearMath/Quaternion.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include <ranger_can/control/geometry.hpp>
#include <ranger_can/wire/protocol.hpp>

namespace ranger_base {
namespace {

using ranger::Timestamp;
namespace protocol = ranger::protocol;

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using RowMajorMatrix6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

Matrix6 diagonal(const std::array<double, 6>& d) {
  return Eigen::Map<const Eigen::Matrix<double, 6, 1>>(d.data()).asDiagonal();
}

// ROS covariance arrays are row-major 6x6.
void store(const Matrix6& m, boost::array<double, 36>& out) {
  Eigen::Map<RowMajorMatrix6>(out.data()) = m;
}

geometry_msgs::Quaternion yaw_quaternion(double yaw) {
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  return tf2::toMsg(q);
}

template <typename T>
bool fresh(const std::optional<ranger::Stamped<T>>& v, Timestamp now, int period_ms) {
  return v && now - v->received <= std::chrono::milliseconds(kStalePeriods * period_ms);
}

std::string joint_of_motor(int motor) {
  if (motor >= 1 && motor <= ranger::kWheelCount) {
    return std::string(ranger::kWheelJointNames[static_cast<std::size_t>(motor - 1)]);
  }
  if (motor > ranger::kWheelCount && motor <= 2 * ranger::kWheelCount) {
    return std::string(
        ranger::kSteeringJointNames[static_cast<std::size_t>(motor - 1 - ranger::kWheelCount)]);
  }
  return "";
}

}  // namespace

ros::Time TimeMapper::to_ros(Timestamp t) const {
  if (t.count() == 0) return ros::Time();
  const double offset = std::chrono::duration<double>(link_now_ - t).count();
  const double seconds = ros_now_.toSec() - offset;
  return seconds > 0.0 ? ros::Time(seconds) : ros::Time();
}

// ---- cmd_vel ----------------------------------------------------------------------------------

ranger::BodyTwist to_body_twist(const geometry_msgs::Twist& twist) {
  return {twist.linear.x, twist.linear.y, twist.angular.z};
}

bool has_non_planar_components(const geometry_msgs::Twist& twist) {
  return twist.linear.z != 0.0 || twist.angular.x != 0.0 || twist.angular.y != 0.0;
}

geometry_msgs::TwistStamped to_twist_stamped(const ranger::BodyTwist& twist, const ros::Time& stamp,
                                             const std::string& frame_id) {
  geometry_msgs::TwistStamped out;
  out.header.stamp = stamp;
  out.header.frame_id = frame_id;
  out.twist.linear.x = twist.vx;
  out.twist.linear.y = twist.vy;
  out.twist.angular.z = twist.wz;
  return out;
}

// ---- odometry, TF, joints ---------------------------------------------------------------------

nav_msgs::Odometry to_odometry(const ranger::OdometryState& odometry, const NodeParameters& params,
                               const ros::Time& stamp) {
  nav_msgs::Odometry out;
  out.header.stamp = stamp;
  out.header.frame_id = params.odom_frame;
  out.child_frame_id = params.base_frame;
  out.pose.pose.position.x = odometry.pose.x;
  out.pose.pose.position.y = odometry.pose.y;
  out.pose.pose.orientation = yaw_quaternion(odometry.pose.yaw);
  out.twist.twist.linear.x = odometry.twist.vx;
  out.twist.twist.linear.y = odometry.twist.vy;
  out.twist.twist.angular.z = odometry.twist.wz;

  Matrix6 pose = diagonal(params.pose_covariance_diagonal);
  pose(0, 0) += odometry.pose_variance[0];
  pose(1, 1) += odometry.pose_variance[1];
  pose(5, 5) += odometry.pose_variance[2];
  store(pose, out.pose.covariance);
  store(diagonal(params.twist_covariance_diagonal), out.twist.covariance);
  return out;
}

geometry_msgs::TransformStamped to_transform(const nav_msgs::Odometry& odometry) {
  geometry_msgs::TransformStamped out;
  out.header = odometry.header;
  out.child_frame_id = odometry.child_frame_id;
  out.transform.translation.x = odometry.pose.pose.position.x;
  out.transform.translation.y = odometry.pose.pose.position.y;
  out.transform.translation.z = odometry.pose.pose.position.z;
  out.transform.rotation = odometry.pose.pose.orientation;
  return out;
}

sensor_msgs::JointState to_joint_state(const WheelJoints& joints, const ros::Time& stamp) {
  sensor_msgs::JointState out;
  out.header.stamp = stamp;
  for (int i = 0; i < ranger::kWheelCount; ++i) {
    const auto w = static_cast<std::size_t>(i);
    out.name.emplace_back(ranger::kSteeringJointNames[w]);
    out.position.push_back(joints.steering_position[w]);
    out.velocity.push_back(joints.steering_velocity[w]);
  }
  for (int i = 0; i < ranger::kWheelCount; ++i) {
    const auto w = static_cast<std::size_t>(i);
    out.name.emplace_back(ranger::kWheelJointNames[w]);
    out.position.push_back(joints.wheel_position[w]);
    out.velocity.push_back(joints.wheel_velocity[w]);
  }
  return out;
}

nav_msgs::Odometry to_ground_truth(const ranger::sim::ChassisSnapshot& sim,
                                   const NodeParameters& params, const ros::Time& stamp) {
  nav_msgs::Odometry out;
  out.header.stamp = stamp;
  out.header.frame_id = params.odom_frame;
  out.child_frame_id = params.base_frame;
  out.pose.pose.position.x = sim.pose.x;
  out.pose.pose.position.y = sim.pose.y;
  out.pose.pose.orientation = yaw_quaternion(sim.pose.yaw);
  out.twist.twist.linear.x = sim.twist.vx;
  out.twist.twist.linear.y = sim.twist.vy;
  out.twist.twist.angular.z = sim.twist.wz;
  return out;
}

// ---- named bits ---------------------------------------------------------------------------------

#define RANGER_FIELD(msg, name) \
  { #name, &ranger_msgs::msg::name }

const std::map<std::string_view, SystemErrorField>& system_error_fields() {
  static const std::map<std::string_view, SystemErrorField> fields = {
      RANGER_FIELD(SystemErrors, steering_servo_warning_front_right),
      RANGER_FIELD(SystemErrors, steering_servo_warning_rear_right),
      RANGER_FIELD(SystemErrors, steering_servo_warning_rear_left),
      RANGER_FIELD(SystemErrors, steering_servo_warning_front_left),
      RANGER_FIELD(SystemErrors, steering_calibration_fault_front_right),
      RANGER_FIELD(SystemErrors, steering_calibration_fault_rear_right),
      RANGER_FIELD(SystemErrors, steering_calibration_fault_rear_left),
      RANGER_FIELD(SystemErrors, steering_calibration_fault_front_left),
      RANGER_FIELD(SystemErrors, steering_calibration_timeout),
      RANGER_FIELD(SystemErrors, safety_edge_collision),
      RANGER_FIELD(SystemErrors, driver_status_error),
      RANGER_FIELD(SystemErrors, host_communication_lost),
      RANGER_FIELD(SystemErrors, motor_driver_5_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_6_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_7_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_8_communication_fault),
      RANGER_FIELD(SystemErrors, over_temperature),
      RANGER_FIELD(SystemErrors, over_current),
      RANGER_FIELD(SystemErrors, battery_under_voltage),
      RANGER_FIELD(SystemErrors, ultrasonic_obstacle_triggered),
      RANGER_FIELD(SystemErrors, remote_control_lost),
      RANGER_FIELD(SystemErrors, motor_driver_1_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_2_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_3_communication_fault),
      RANGER_FIELD(SystemErrors, motor_driver_4_communication_fault),
  };
  return fields;
}

const std::map<std::string_view, DriverStatusField>& driver_status_fields() {
  static const std::map<std::string_view, DriverStatusField> fields = {
      RANGER_FIELD(DriverStatus, supply_voltage_low),
      RANGER_FIELD(DriverStatus, motor_over_temperature),
      RANGER_FIELD(DriverStatus, driver_over_current),
      RANGER_FIELD(DriverStatus, driver_over_temperature),
      RANGER_FIELD(DriverStatus, sensor_abnormal),
      RANGER_FIELD(DriverStatus, driver_error),
      RANGER_FIELD(DriverStatus, driver_disabled),
  };
  return fields;
}

const std::map<std::string_view, BmsFlagField>& bms_flag_fields() {
  static const std::map<std::string_view, BmsFlagField> fields = {
      RANGER_FIELD(BmsFlags, over_voltage),           RANGER_FIELD(BmsFlags, under_voltage),
      RANGER_FIELD(BmsFlags, high_temperature),       RANGER_FIELD(BmsFlags, low_temperature),
      RANGER_FIELD(BmsFlags, discharge_over_current), RANGER_FIELD(BmsFlags, charge_over_current),
  };
  return fields;
}

#undef RANGER_FIELD

namespace {
template <typename Msg, typename Field>
void fill_bits(std::uint32_t word, const std::vector<protocol::NamedBit>& bits,
               const std::map<std::string_view, Field>& fields, Msg& out) {
  for (const auto& bit : bits) {
    const auto it = fields.find(bit.name);
    if (it != fields.end()) out.*(it->second) = ((word >> bit.index) & 1u) != 0;
  }
}
}  // namespace

void fill_system_errors(std::uint32_t error_word, ranger_msgs::SystemErrors& out) {
  fill_bits(error_word, protocol::system_error_bits(), system_error_fields(), out);
}

ranger_msgs::DriverStatus to_driver_status(std::uint8_t status) {
  ranger_msgs::DriverStatus out;
  fill_bits(status, protocol::driver_status_bits(), driver_status_fields(), out);
  return out;
}

ranger_msgs::BmsFlags to_bms_flags(std::uint8_t status1, std::uint8_t status2) {
  ranger_msgs::BmsFlags out;
  fill_bits(status1, protocol::bms_status1_bits(), bms_flag_fields(), out);
  fill_bits(status2, protocol::bms_status2_bits(), bms_flag_fields(), out);
  return out;
}

// ---- chassis state ----------------------------------------------------------------------------

ranger_msgs::SystemState to_system_state(const ranger::ControllerState& state,
                                         const ros::Time& stamp) {
  ranger_msgs::SystemState out;
  out.header.stamp = stamp;
  out.link_up = state.link == ranger::LinkState::kConnected;
  if (const auto& s = state.feedback.system_status) {
    out.vehicle_status = s->value.vehicle_status_raw;
    out.vehicle_status_name = std::string(protocol::to_string(s->value.vehicle_status));
    out.control_mode = s->value.control_mode_raw;
    out.control_mode_name = std::string(protocol::to_string(s->value.control_mode));
    out.battery_voltage = static_cast<float>(s->value.battery_voltage);
  } else {
    out.vehicle_status_name = "unknown";
    out.control_mode_name = "unknown";
  }
  if (const auto& m = state.feedback.motion_mode) {
    out.motion_mode = m->value.mode_raw;
    out.motion_mode_name = std::string(protocol::to_string(m->value.mode));
    out.motion_mode_switching = m->value.switching;
  } else {
    out.motion_mode_name = "unknown";
  }
  out.error_word = state.error_bits;
  fill_system_errors(state.error_bits, out.errors);
  out.active_errors = protocol::error_bit_names(state.error_bits);
  if (state.refusal != ranger::MotionRefusal::kNone) {
    out.motion_inhibited_reason = std::string(ranger::to_string(state.refusal));
  }
  return out;
}

ranger_msgs::ActuatorStateArray to_actuator_state(const ranger::ChassisFeedback& feedback,
                                                  const TimeMapper& time, const ros::Time& stamp) {
  ranger_msgs::ActuatorStateArray out;
  out.header.stamp = stamp;
  for (int motor = 1; motor <= protocol::kMotorCount; ++motor) {
    const auto i = static_cast<std::size_t>(motor - 1);
    ranger_msgs::ActuatorState a;
    a.motor = static_cast<std::uint8_t>(motor);
    a.joint_name = joint_of_motor(motor);
    if (const auto& h = feedback.motor_high_speed[i]) {
      a.rpm = h->value.rpm;
      a.current = h->value.current;
      a.position = h->value.position;
      a.high_speed_stamp = time.to_ros(h->received);
    }
    if (const auto& l = feedback.motor_low_speed[i]) {
      a.driver_voltage = l->value.driver_voltage;
      a.driver_temperature = l->value.driver_temperature;
      a.motor_temperature = l->value.motor_temperature;
      a.driver_status = l->value.driver_status;
      a.driver_status_bits = to_driver_status(l->value.driver_status);
      a.low_speed_stamp = time.to_ros(l->received);
    }
    out.actuators.push_back(a);
  }
  return out;
}

ranger_msgs::BmsStateArray to_bms_state(const ranger::ChassisFeedback& feedback,
                                        const TimeMapper& time, Timestamp link_now,
                                        const ros::Time& stamp) {
  ranger_msgs::BmsStateArray out;
  out.header.stamp = stamp;
  for (int b = 0; b <= protocol::kBatteryCount; ++b) {
    const auto i = static_cast<std::size_t>(b);
    ranger_msgs::BmsState s;
    s.battery = static_cast<std::uint8_t>(b);
    const auto& data = feedback.bms[i];
    s.present = fresh(data, link_now, protocol::kBmsPeriodMs);
    if (data) {
      s.header.stamp = time.to_ros(data->received);
      s.soc = static_cast<float>(data->value.soc);
      s.soh = static_cast<float>(data->value.soh);
      s.voltage = static_cast<float>(data->value.voltage);
      s.current = static_cast<float>(data->value.current);
      s.temperature = static_cast<float>(data->value.temperature);
    }
    if (const auto& alarm = feedback.bms_alarm[i]) {
      s.alarm_status1 = alarm->value.alarm1;
      s.alarm_status2 = alarm->value.alarm2;
      s.warning_status1 = alarm->value.warning1;
      s.warning_status2 = alarm->value.warning2;
      s.alarms = to_bms_flags(alarm->value.alarm1, alarm->value.alarm2);
      s.warnings = to_bms_flags(alarm->value.warning1, alarm->value.warning2);
    }
    out.batteries.push_back(s);
  }
  return out;
}

sensor_msgs::BatteryState to_battery_state(const ranger::ControllerState& state, Timestamp link_now,
                                           const ros::Time& stamp) {
  using sensor_msgs::BatteryState;
  BatteryState out;
  out.header.stamp = stamp;
  out.voltage = out.current = out.temperature = out.charge = out.capacity = out.percentage =
      std::numeric_limits<float>::quiet_NaN();
  out.design_capacity = std::numeric_limits<float>::quiet_NaN();
  out.power_supply_status = BatteryState::POWER_SUPPLY_STATUS_UNKNOWN;
  out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_UNKNOWN;
  out.power_supply_technology = BatteryState::POWER_SUPPLY_TECHNOLOGY_LION;
  out.location = "pack";

  const auto& fb = state.feedback;
  const auto& pack = fb.bms[0];
  if (fresh(pack, link_now, protocol::kBmsPeriodMs)) {
    out.present = true;
    out.voltage = static_cast<float>(pack->value.voltage);
    out.current = static_cast<float>(pack->value.current);
    out.temperature = static_cast<float>(pack->value.temperature);
    out.percentage = static_cast<float>(std::clamp(pack->value.soc / 100.0, 0.0, 1.0));
    // sensor_msgs/BatteryState: current negative while discharging, as the BMS reports it.
    if (pack->value.current > 0.0) {
      out.power_supply_status = BatteryState::POWER_SUPPLY_STATUS_CHARGING;
    } else if (pack->value.current < 0.0) {
      out.power_supply_status = BatteryState::POWER_SUPPLY_STATUS_DISCHARGING;
    } else {
      out.power_supply_status = BatteryState::POWER_SUPPLY_STATUS_NOT_CHARGING;
    }
    out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_GOOD;
    if (const auto& alarm = fb.bms_alarm[0]) {
      const auto flags = to_bms_flags(alarm->value.alarm1, alarm->value.alarm2);
      if (flags.over_voltage) {
        out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_OVERVOLTAGE;
      } else if (flags.high_temperature) {
        out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_OVERHEAT;
      } else if (flags.low_temperature) {
        out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_COLD;
      } else if (flags.under_voltage || flags.discharge_over_current || flags.charge_over_current) {
        out.power_supply_health = BatteryState::POWER_SUPPLY_HEALTH_UNSPEC_FAILURE;
      }
    }
  } else if (const auto& status = fb.system_status) {
    out.present = true;  // the chassis runs, so it has a battery; the BMS is not reporting
    out.voltage = static_cast<float>(status->value.battery_voltage);
  }
  for (int b = 1; b <= protocol::kBatteryCount; ++b) {
    const auto& slot = fb.bms[static_cast<std::size_t>(b)];
    const bool present = fresh(slot, link_now, protocol::kBmsPeriodMs);
    out.cell_voltage.push_back(present ? static_cast<float>(slot->value.voltage)
                                       : std::numeric_limits<float>::quiet_NaN());
    out.cell_temperature.push_back(present ? static_cast<float>(slot->value.temperature)
                                           : std::numeric_limits<float>::quiet_NaN());
  }
  return out;
}

std::string ultrasonic_frame_id(int sensor) {
  return "ultrasonic_" + std::to_string(sensor) + "_link";
}

sensor_msgs::Range to_range(int sensor, std::int16_t raw, const UltrasonicRangeParameters& params,
                            const ros::Time& stamp) {
  sensor_msgs::Range out;
  out.header.stamp = stamp;
  out.header.frame_id = ultrasonic_frame_id(sensor);
  out.radiation_type = sensor_msgs::Range::ULTRASOUND;
  out.field_of_view = static_cast<float>(params.field_of_view);
  out.min_range = static_cast<float>(params.min_range);
  out.max_range = static_cast<float>(params.max_range);
  if (raw < 0) {
    out.range = std::numeric_limits<float>::quiet_NaN();
  } else {
    const double m = raw / 1000.0;
    out.range =
        m > params.max_range ? std::numeric_limits<float>::infinity() : static_cast<float>(m);
  }
  return out;
}

ranger_msgs::UltrasonicState to_ultrasonic_state(const ranger::ControllerState& state,
                                                 const ros::Time& stamp) {
  ranger_msgs::UltrasonicState out;
  out.header.stamp = stamp;
  out.avoidance_known = state.ultrasonic_enabled.has_value();
  out.avoidance_enabled = state.ultrasonic_enabled.value_or(false);
  for (const auto& group : state.feedback.ultrasonic) {
    if (!group) continue;
    for (int k = 0; k < 4; ++k) {
      ranger_msgs::UltrasonicReading r;
      r.sensor = static_cast<std::uint8_t>(group->value.first_sensor + k);
      r.raw = group->value.raw[static_cast<std::size_t>(k)];
      r.range =
          r.raw < 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(r.raw / 1000.0);
      r.status = std::string(protocol::ultrasonic_status_name(r.raw));
      out.sensors.push_back(r);
    }
  }
  std::sort(out.sensors.begin(), out.sensors.end(),
            [](const auto& a, const auto& b) { return a.sensor < b.sensor; });
  return out;
}

}  // namespace ranger_base
