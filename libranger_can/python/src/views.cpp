#include "views.hpp"

#include <algorithm>
#include <cmath>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::python {
namespace {

std::int64_t ns(Timestamp t) {
  return static_cast<std::int64_t>(t.count());
}

std::string joint_of_motor(int motor) {
  if (motor >= 1 && motor <= kWheelCount) {
    return std::string(kWheelJointNames[static_cast<std::size_t>(motor - 1)]);
  }
  if (motor > kWheelCount && motor <= 2 * kWheelCount) {
    return std::string(kSteeringJointNames[static_cast<std::size_t>(motor - 1 - kWheelCount)]);
  }
  return "";
}

template <std::size_t N>
std::vector<std::string> names(const std::array<std::string_view, N>& a) {
  return std::vector<std::string>(a.begin(), a.end());
}

std::vector<double> values(const std::array<double, kWheelCount>& a) {
  return std::vector<double>(a.begin(), a.end());
}

LightsView lights_of(const LightState& l) {
  return LightsView{l.enable, std::string(protocol::to_string(l.front_mode)),
                    std::string(protocol::to_string(l.rear_mode)), l.front_custom, l.rear_custom};
}

}  // namespace

OdometryView odometry_view(const DriverSnapshot& s) {
  const OdometryState& o = s.odometry;
  OdometryView v;
  v.x = o.pose.x;
  v.y = o.pose.y;
  v.yaw = o.pose.yaw;
  v.vx = o.twist.vx;
  v.vy = o.twist.vy;
  v.wz = o.twist.wz;
  v.stamp_ns = ns(o.stamp);
  v.distance = o.distance;
  v.pose_variance = o.pose_variance;
  v.twist_variance = o.twist_variance;
  v.source = std::string(to_string(o.active_source));
  v.steps = o.steps;
  v.last_gap = seconds(o.last_gap);
  v.last_gap_end_ns = ns(o.last_gap_end);
  v.gaps = o.gaps;
  return v;
}

namespace {
std::pair<std::int64_t, std::uint32_t> split(Timestamp t) {
  const std::int64_t n = ns(t);
  const std::int64_t sec = n >= 0 ? n / 1'000'000'000 : (n - 999'999'999) / 1'000'000'000;
  return {sec, static_cast<std::uint32_t>(n - sec * 1'000'000'000)};
}
}  // namespace

OdometryValues odometry_values(const DriverSnapshot& s) {
  const OdometryState& o = s.odometry;
  const auto [sec, nanosec] = split(o.stamp);
  return {sec,
          nanosec,
          o.pose.x,
          o.pose.y,
          std::sin(o.pose.yaw / 2.0),
          std::cos(o.pose.yaw / 2.0),
          o.twist.vx,
          o.twist.vy,
          o.twist.wz,
          o.pose_variance[0],
          o.pose_variance[1],
          o.pose_variance[2]};
}

JointValues joint_values(const DriverSnapshot& s) {
  const WheelJoints& j = s.joints;
  const auto [sec, nanosec] = split(joints_stamp(s.feedback));
  JointValues out{sec, nanosec, {}, {}};
  for (std::size_t w = 0; w < static_cast<std::size_t>(kWheelCount); ++w) {
    std::get<2>(out)[w] = j.steering_position[w];
    std::get<3>(out)[w] = j.steering_velocity[w];
    std::get<2>(out)[w + kWheelCount] = j.wheel_position[w];
    std::get<3>(out)[w + kWheelCount] = j.wheel_velocity[w];
  }
  return out;
}

JointsView joints_view(const DriverSnapshot& s) {
  const WheelJoints& j = s.joints;
  JointsView v;
  v.steering_names = names(kSteeringJointNames);
  v.wheel_names = names(kWheelJointNames);
  v.steering_position = values(j.steering_position);
  v.steering_velocity = values(j.steering_velocity);
  v.wheel_position = values(j.wheel_position);
  v.wheel_velocity = values(j.wheel_velocity);
  v.has_steering = j.has_steering;
  v.has_wheels = j.has_wheels;
  v.stamp_ns = ns(joints_stamp(s.feedback));
  return v;
}

std::vector<MotorView> motors_view(const DriverSnapshot& s) {
  std::vector<MotorView> out;
  for (int motor = 1; motor <= kMotorCount; ++motor) {
    const auto i = static_cast<std::size_t>(motor - 1);
    MotorView m;
    m.motor = motor;
    m.joint = joint_of_motor(motor);
    if (const auto& h = s.feedback.motor_high_speed[i]) {
      m.rpm = h->value.rpm;
      m.current = h->value.current;
      m.position = h->value.position;
      m.high_speed_stamp_ns = ns(h->stamp);
    }
    if (const auto& l = s.feedback.motor_low_speed[i]) {
      m.driver_voltage = l->value.driver_voltage;
      m.driver_temperature = l->value.driver_temperature;
      m.motor_temperature = l->value.motor_temperature;
      m.driver_status = l->value.driver_status;
      m.driver_status_names = protocol::driver_status_names(l->value.driver_status);
      m.low_speed_stamp_ns = ns(l->stamp);
    }
    out.push_back(std::move(m));
  }
  return out;
}

std::vector<BatteryView> batteries_view(const DriverSnapshot& s) {
  std::vector<BatteryView> out;
  for (int b = 0; b <= kBatteryCount; ++b) {
    const auto i = static_cast<std::size_t>(b);
    BatteryView v;
    v.battery = b;
    const auto& data = s.feedback.bms[i];
    v.present = bms_present(s.feedback, b, s.now);  // the library's freshness, as ROS 1 reads it
    if (data) {
      v.soc = data->value.soc;
      v.soh = data->value.soh;
      v.voltage = data->value.voltage;
      v.current = data->value.current;
      v.temperature = data->value.temperature;
      v.stamp_ns = ns(data->stamp);
    }
    if (const auto& a = s.feedback.bms_alarm[i]) {
      v.alarm1 = a->value.alarm1;
      v.alarm2 = a->value.alarm2;
      v.warning1 = a->value.warning1;
      v.warning2 = a->value.warning2;
      v.alarms = protocol::bms_status_names(a->value.alarm1, a->value.alarm2);
      v.warnings = protocol::bms_status_names(a->value.warning1, a->value.warning2);
    }
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<UltrasonicView> ultrasonic_view(const DriverSnapshot& s) {
  std::vector<UltrasonicView> out;
  for (const auto& group : s.feedback.ultrasonic) {
    if (!group) continue;
    for (int k = 0; k < 4; ++k) {
      UltrasonicView u;
      u.sensor = group->value.first_sensor + k;
      u.raw = group->value.raw[static_cast<std::size_t>(k)];
      u.status = std::string(ultrasonic_status(group->value.raw[k]));  // the library's words
      if (u.status == "ok") u.range = ultrasonic_range(group->value.raw[k]);
      u.stamp_ns = ns(group->stamp);
      out.push_back(std::move(u));
    }
  }
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.sensor < b.sensor; });
  return out;
}

std::optional<IdentificationView> identification_view(const DriverSnapshot& s) {
  if (!s.identification) return std::nullopt;
  const IdentificationStatus& id = *s.identification;
  IdentificationView v;
  v.phase = std::string(to_string(id.phase));
  v.revision = id.revision;
  v.message = id.message;
  v.evidence = id.evidence;
  v.undecided = id.undecided;
  for (const auto& d : id.decided)
    v.decided.emplace_back(d.name, d.value);
  v.confidence = id.confidence;
  v.done = id.done();
  if (v.done) v.elapsed = seconds(id.elapsed());
  return v;
}

std::optional<RemoteView> remote_view(const DriverSnapshot& s) {
  if (!s.remote) return std::nullopt;
  const RemoteState& r = *s.remote;
  RemoteView v;
  v.swa = std::string(protocol::to_string(r.swa));
  v.swb = std::string(protocol::to_string(r.swb));
  v.swc = std::string(protocol::to_string(r.swc));
  v.swd = std::string(protocol::to_string(r.swd));
  v.left_vertical = r.left_vertical;
  v.left_horizontal = r.left_horizontal;
  v.right_vertical = r.right_vertical;
  v.right_horizontal = r.right_horizontal;
  v.knob = r.knob;
  if (s.feedback.remote_control_state) v.stamp_ns = ns(s.feedback.remote_control_state->stamp);
  v.received_ns = ns(r.received);
  return v;
}

std::optional<LightsView> lights_view(const DriverSnapshot& s) {
  if (!s.lights) return std::nullopt;
  const LightsState& l = *s.lights;
  return LightsView{l.can_control, std::string(protocol::to_string(l.front)),
                    std::string(protocol::to_string(l.rear)), l.front_brightness,
                    l.rear_brightness};
}

std::vector<FrameView> frames_view(const DriverSnapshot& s) {
  std::vector<FrameView> out;
  for (const FrameIdCounts& c : s.frames.counts()) {
    out.push_back(
        FrameView{c.id, std::string(protocol::frame_name(c.id)), c.frames, c.rejected, c.padded});
  }
  return out;
}

EventView event_view(const DriverEvent& e) {
  return EventView{
      e.sequence,  ns(e.time), std::string(to_string(e.kind)), std::string(to_string(e.severity)),
      describe(e), to_json(e)};
}

OutcomeView outcome_view(const RequestOutcome& o) {
  return OutcomeView{o.id,      std::string(to_string(o.kind)),
                     o.what,    std::string(to_string(o.state)),
                     o.message, o.error_word,
                     o};
}

GroundTruthView ground_truth_view(const sim::ChassisSnapshot& c) {
  GroundTruthView v;
  v.x = c.pose.x;
  v.y = c.pose.y;
  v.yaw = c.pose.yaw;
  v.vx = c.twist.vx;
  v.vy = c.twist.vy;
  v.wz = c.twist.wz;
  v.distance_travelled = c.distance_travelled;
  v.yaw_travelled = c.yaw_travelled;
  v.control_mode = std::string(protocol::to_string(c.control_mode));
  v.motion_mode = std::string(protocol::to_string(c.motion_mode));
  v.emergency_stop = c.emergency_stop;
  v.motion_allowed = c.motion_allowed;
  v.motion_refused_reason = c.motion_refused_reason;
  v.stamp_ns = ns(c.time);
  v.lights = lights_of(c.lights);
  return v;
}

}  // namespace ranger::python
