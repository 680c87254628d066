#include "ranger_base/conversions.hpp"

#include <tf2/LinearMath/Quaternion.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <ranger_can/control/geometry.hpp>
#include <ranger_can/frontend/answers.hpp>
#include <ranger_can/text.hpp>

namespace ranger_base {
namespace {

using ranger::Timestamp;

void store(const ranger::Covariance& c, boost::array<double, 36>& out) {
  std::copy(c.begin(), c.end(), out.begin());
}

geometry_msgs::Quaternion yaw_quaternion(double yaw) {
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  return tf2::toMsg(q);
}

const float kNaN = std::numeric_limits<float>::quiet_NaN();

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

ros::Time to_ros_time(Timestamp bus_stamp) {
  if (bus_stamp.count() <= 0) return ros::Time();
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(bus_stamp.count()));
  return t;
}

// ---- cmd_vel ----------------------------------------------------------------------------------

ranger::BodyTwist to_body_twist(const geometry_msgs::Twist& twist) {
  return {twist.linear.x, twist.linear.y, twist.angular.z};
}

ranger::MotionRequest to_motion_request(const geometry_msgs::Twist& twist) {
  return ranger::MotionRequest{
      to_body_twist(twist), std::nullopt,
      ranger::OutOfPlaneTwist{twist.linear.z, twist.angular.x, twist.angular.y}};
}

bool has_non_planar_components(const geometry_msgs::Twist& twist) {
  return twist.linear.z != 0.0 || twist.angular.x != 0.0 || twist.angular.y != 0.0;
}

std::optional<ranger::BodyTwist> achieved_twist(const ranger::SentEvent& event) {
  if (!std::holds_alternative<ranger::MotionCommand>(event.sent.message)) return std::nullopt;
  return event.sent.achieved;
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

nav_msgs::Odometry to_odometry(const ranger::OdometryState& odometry,
                               const NodeParameters& params) {
  nav_msgs::Odometry out;
  out.header.stamp = to_ros_time(odometry.stamp);
  out.header.frame_id = params.odom_frame;
  out.child_frame_id = params.base_frame;
  out.pose.pose.position.x = odometry.pose.x;
  out.pose.pose.position.y = odometry.pose.y;
  out.pose.pose.orientation = yaw_quaternion(odometry.pose.yaw);
  out.twist.twist.linear.x = odometry.twist.vx;
  out.twist.twist.linear.y = odometry.twist.vy;
  out.twist.twist.angular.z = odometry.twist.wz;

  store(ranger::pose_covariance(odometry, params.pose_covariance_diagonal), out.pose.covariance);
  store(ranger::diagonal_covariance(params.twist_covariance_diagonal), out.twist.covariance);
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

sensor_msgs::JointState to_joint_state(const ranger::WheelJoints& joints, const ros::Time& stamp) {
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
      RANGER_FIELD(SystemErrors, battery_warning),
      RANGER_FIELD(SystemErrors, steering_encoder_fault),
      RANGER_FIELD(SystemErrors, battery_over_voltage),
      RANGER_FIELD(SystemErrors, emergency_stop),
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
// Each named flag sets the message field of its name.
template <typename Msg, typename Field>
Msg& fill(const std::vector<ranger::NamedFlag>& flags,
          const std::map<std::string_view, Field>& fields, Msg& out) {
  for (const ranger::NamedFlag& flag : flags) {
    const auto it = fields.find(flag.name);
    if (it != fields.end()) out.*(it->second) = flag.set;
  }
  return out;
}
}  // namespace

void fill_system_errors(std::uint32_t error_word, ranger::ErrorWordLayout layout,
                        ranger_msgs::SystemErrors& out) {
  fill(ranger::fault_flags(error_word, layout), system_error_fields(), out);
}

ranger_msgs::DriverStatus to_driver_status(std::uint8_t status) {
  ranger_msgs::DriverStatus out;
  return fill(ranger::driver_status_flags(status), driver_status_fields(), out);
}

ranger_msgs::BmsFlags to_bms_flags(std::uint8_t status1, std::uint8_t status2) {
  ranger_msgs::BmsFlags out;
  return fill(ranger::bms_flags(status1, status2), bms_flag_fields(), out);
}

// ---- chassis state ----------------------------------------------------------------------------

ranger_msgs::SystemState to_system_state(const ranger::DriverSnapshot& snapshot,
                                         const ros::Time& stamp) {
  const ranger::ControllerState& state = snapshot.controller;
  const ranger::ChassisFeedback& feedback = snapshot.feedback;
  ranger_msgs::SystemState out;
  out.header.stamp = stamp;
  out.link_up = state.link == ranger::LinkState::kConnected;
  out.motion_known = snapshot.motion_known;
  out.odometry_gap = ranger::seconds(snapshot.odometry.last_gap);
  out.odometry_gap_end = to_ros_time(snapshot.odometry.last_gap_end);
  out.odometry_gaps = static_cast<std::uint32_t>(snapshot.odometry.gaps);
  if (const auto& s = feedback.system_status) {
    out.vehicle_status = s->value.vehicle_status_raw;
    out.vehicle_status_name = std::string(ranger::to_string(s->value.vehicle_status));
    out.control_mode = s->value.control_mode_raw;
    out.control_mode_name = std::string(ranger::to_string(s->value.control_mode));
    out.battery_voltage = static_cast<float>(s->value.battery_voltage);
  } else {
    out.vehicle_status_name = "unknown";
    out.control_mode_name = "unknown";
  }
  if (const auto& m = feedback.motion_mode) {
    out.motion_mode = m->value.mode_raw;
    out.motion_mode_name = std::string(ranger::to_string(m->value.mode));
    out.motion_mode_switching = m->value.switching;
  } else {
    out.motion_mode_name = "unknown";
  }
  out.error_word = state.error_bits;
  fill_system_errors(state.error_bits, snapshot.profile.error_word, out.errors);
  out.active_errors = ranger::fault_names(state.error_bits, snapshot.profile.error_word);
  out.motion_inhibited_reason = ranger::refusal_name(state);
  out.protocol = std::string(ranger::to_string(snapshot.protocol));
  out.protocol_profile = ranger::describe(snapshot.profile);
  if (snapshot.identification) {
    out.identification = std::string(ranger::to_string(snapshot.identification->phase));
  }
  out.motion_inhibited_detail = ranger::describe_refusal(snapshot);
  out.rearm_required = state.rearm_required();
  out.latched_causes = ranger::cause_names(state.latched_causes);
  out.active_causes = ranger::cause_names(state.active_causes);
  out.reclaim_blocked = state.reclaim_blocked;
  out.steer_first_factor = static_cast<float>(state.steer_first_factor);
  out.park_requested = state.park_requested;
  out.parked = state.parked();
  out.firmware_version = snapshot.firmware.text;
  out.firmware_version_state = std::string(ranger::to_string(snapshot.firmware.state));
  out.drive_mode = ranger_msgs::SystemState::DRIVE_MODE_NONE;
  if (snapshot.drive_mode) {
    out.drive_mode = static_cast<std::uint8_t>(*snapshot.drive_mode);
    out.drive_mode_name = std::string(ranger::to_string(*snapshot.drive_mode));
  }
  const auto [front_left, front_right, rear_left, rear_right] = ranger::wheel_odometers(feedback);
  out.front_left_distance = front_left;
  out.front_right_distance = front_right;
  out.rear_left_distance = rear_left;
  out.rear_right_distance = rear_right;
  auto bms = ranger::pack_bms_alarms(feedback);
  out.bms_alarms = std::move(bms.alarms);
  out.bms_warnings = std::move(bms.warnings);
  return out;
}

ranger_msgs::RemoteState to_remote_state(const ranger::RemoteState& remote,
                                         const ros::Time& stamp) {
  ranger_msgs::RemoteState out;
  out.header.stamp = stamp;
  out.swa = std::string(ranger::to_string(remote.swa));
  out.swb = std::string(ranger::to_string(remote.swb));
  out.swc = std::string(ranger::to_string(remote.swc));
  out.swd = std::string(ranger::to_string(remote.swd));
  out.left_vertical = static_cast<float>(remote.left_vertical);
  out.left_horizontal = static_cast<float>(remote.left_horizontal);
  out.right_vertical = static_cast<float>(remote.right_vertical);
  out.right_horizontal = static_cast<float>(remote.right_horizontal);
  out.knob = static_cast<float>(remote.knob);
  return out;
}

ranger::Result<ranger::LightsRequest> to_lights_request(const ranger_msgs::SetLights::Request& r) {
  return ranger::lights_request(r.front_mode, r.front_brightness, r.rear_mode, r.rear_brightness);
}

void fill_lights_response(const std::optional<ranger::LightsState>& lights,
                          ranger_msgs::SetLights::Response& out) {
  if (!lights) return;
  out.can_control = lights->can_control;
  out.front_mode = static_cast<std::uint8_t>(lights->front);
  out.front_brightness = lights->front_brightness;
  out.rear_mode = static_cast<std::uint8_t>(lights->rear);
  out.rear_brightness = lights->rear_brightness;
}

ranger_msgs::ActuatorStateArray to_actuator_state(const ranger::ChassisFeedback& feedback,
                                                  const ros::Time& stamp) {
  ranger_msgs::ActuatorStateArray out;
  out.header.stamp = stamp;
  for (int motor = 1; motor <= ranger::kMotorCount; ++motor) {
    const auto i = static_cast<std::size_t>(motor - 1);
    ranger_msgs::ActuatorState a;
    a.motor = static_cast<std::uint8_t>(motor);
    a.joint_name = joint_of_motor(motor);
    if (const auto& h = feedback.motor_high_speed[i]) {
      a.rpm = h->value.rpm;
      a.current = h->value.current;
      a.position = h->value.position;
      a.high_speed_stamp = to_ros_time(h->stamp);
    }
    if (const auto& l = feedback.motor_low_speed[i]) {
      a.driver_voltage = l->value.driver_voltage;
      a.driver_temperature = l->value.driver_temperature;
      a.motor_temperature = l->value.motor_temperature;
      a.driver_status = l->value.driver_status;
      a.driver_status_bits = to_driver_status(l->value.driver_status);
      a.low_speed_stamp = to_ros_time(l->stamp);
    }
    out.actuators.push_back(a);
  }
  return out;
}

ranger_msgs::BmsStateArray to_bms_state(const ranger::ChassisFeedback& feedback, Timestamp now,
                                        const ros::Time& stamp) {
  ranger_msgs::BmsStateArray out;
  out.header.stamp = stamp;
  for (int b = 0; b <= ranger::kBatteryCount; ++b) {
    const auto i = static_cast<std::size_t>(b);
    ranger_msgs::BmsState s;
    s.battery = static_cast<std::uint8_t>(b);
    const auto& data = feedback.bms[i];
    s.present = ranger::bms_present(feedback, b, now);
    if (data) {
      s.header.stamp = to_ros_time(data->stamp);
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

sensor_msgs::BatteryState to_battery_state(const ranger::ChassisFeedback& fb, Timestamp now,
                                           const ros::Time& stamp) {
  // What the library says of the pack (ranger::battery_report), field for field.
  using sensor_msgs::BatteryState;
  static_assert(BatteryState::POWER_SUPPLY_STATUS_DISCHARGING ==
                static_cast<int>(ranger::PowerSupplyStatus::kDischarging));
  static_assert(BatteryState::POWER_SUPPLY_HEALTH_COLD ==
                static_cast<int>(ranger::PowerSupplyHealth::kCold));
  const ranger::BatteryReport r = ranger::battery_report(fb, now);
  BatteryState out;
  out.header.stamp = r.stamp.count() > 0 ? to_ros_time(r.stamp) : stamp;
  out.present = r.present;
  out.voltage = static_cast<float>(r.voltage);
  out.current = static_cast<float>(r.current);
  out.temperature = static_cast<float>(r.temperature);
  out.percentage = static_cast<float>(r.percentage);
  out.charge = out.capacity = kNaN;
  out.design_capacity = kNaN;  // 24 Ah per battery, but how many are fitted is not reported
  out.power_supply_status = static_cast<std::uint8_t>(r.status);
  out.power_supply_health = static_cast<std::uint8_t>(r.health);
  static_assert(ranger::vehicle_spec::kBatteryChemistry == "LiFePO4");
  out.power_supply_technology = BatteryState::POWER_SUPPLY_TECHNOLOGY_LIFE;
  out.location = "pack";
  for (std::size_t b = 0; b < r.cell_voltage.size(); ++b) {
    out.cell_voltage.push_back(static_cast<float>(r.cell_voltage[b]));
    out.cell_temperature.push_back(static_cast<float>(r.cell_temperature[b]));
  }
  return out;
}

std::string ultrasonic_frame_id(const std::string& frame_prefix, int sensor) {
  return frame_prefix + "ultrasonic_" + std::to_string(sensor) + "_link";
}

float ultrasonic_range_m(std::int16_t raw) {
  return static_cast<float>(ranger::ultrasonic_range(raw));
}

sensor_msgs::Range to_range(int sensor, std::int16_t raw, const NodeParameters& params,
                            const ros::Time& stamp) {
  const auto& u = params.ultrasonic;
  sensor_msgs::Range out;
  out.header.stamp = stamp;
  out.header.frame_id = ultrasonic_frame_id(params.frame_prefix, sensor);
  out.radiation_type = sensor_msgs::Range::ULTRASOUND;
  out.field_of_view = static_cast<float>(u.field_of_view);
  out.min_range = static_cast<float>(u.min_range);
  out.max_range = static_cast<float>(u.max_range);
  out.range = static_cast<float>(ranger::range_reading(raw, u.max_range));
  return out;
}

ranger_msgs::UltrasonicState to_ultrasonic_state(const ranger::DriverSnapshot& snapshot,
                                                 const ros::Time& stamp) {
  const auto& state = snapshot.controller;
  ranger_msgs::UltrasonicState out;
  out.header.stamp = stamp;
  out.avoidance_known = state.ultrasonic_enabled.has_value();
  out.avoidance_enabled = state.ultrasonic_enabled.value_or(false);
  for (const auto& group : snapshot.feedback.ultrasonic) {
    if (!group) continue;
    for (int k = 0; k < 4; ++k) {
      ranger_msgs::UltrasonicReading r;
      r.sensor = static_cast<std::uint8_t>(group->value.first_sensor + k);
      r.raw = group->value.raw[static_cast<std::size_t>(k)];
      r.range = ultrasonic_range_m(r.raw);
      r.status = std::string(ranger::ultrasonic_status(r.raw));
      out.sensors.push_back(r);
    }
  }
  std::sort(out.sensors.begin(), out.sensors.end(),
            [](const auto& a, const auto& b) { return a.sensor < b.sensor; });
  return out;
}

}  // namespace ranger_base
