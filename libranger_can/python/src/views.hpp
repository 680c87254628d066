// Plain values the binding hands to Python, read out of a DriverSnapshot on demand (a Snapshot
// property builds only what it is asked for). Names and units are the library's; enums become
// their stable snake_case names here, at the edge.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"

namespace ranger::python {

struct OdometryView {
  double x = 0, y = 0, yaw = 0, vx = 0, vy = 0, wz = 0;
  std::int64_t stamp_ns = 0;  // the frames' time (bus clock: wall time), 0 = none yet
  double distance = 0;
  std::array<double, 3> pose_variance{}, twist_variance{};
  std::string source;
  std::uint64_t steps = 0;
  double last_gap = 0;               // s, the latest gap in the feedback (not integrated)
  std::int64_t last_gap_end_ns = 0;  // the frame time the feedback returned, 0 = no gap yet
  std::uint64_t gaps = 0;
};

struct JointsView {
  std::vector<std::string> steering_names, wheel_names;
  std::vector<double> steering_position, steering_velocity, wheel_position, wheel_velocity;
  bool has_steering = false, has_wheels = false;
  std::int64_t stamp_ns = 0;  // the newest 0x271/0x281 frame behind them
};

struct MotorView {
  int motor = 0;
  std::string joint;
  double rpm = 0, current = 0;
  std::int32_t position = 0;
  double driver_voltage = 0, driver_temperature = 0, motor_temperature = 0;
  int driver_status = 0;
  std::vector<std::string> driver_status_names;
  std::int64_t high_speed_stamp_ns = 0, low_speed_stamp_ns = 0;
};

struct BatteryView {
  int battery = 0;  // 0 = the pack, 1..4 the slots
  bool present = false;
  double soc = 0, soh = 0, voltage = 0, current = 0, temperature = 0;
  int alarm1 = 0, alarm2 = 0, warning1 = 0, warning2 = 0;
  std::vector<std::string> alarms, warnings;
  std::int64_t stamp_ns = 0;
};

struct UltrasonicView {
  int sensor = 0;
  int raw = 0;
  std::optional<double> range;  // m, when the library calls the reading ok
  std::string status;
  std::int64_t stamp_ns = 0;
};

struct IdentificationView {
  std::string phase, revision, message;
  std::vector<std::string> evidence, undecided;
  std::vector<std::pair<std::string, std::string>> decided;
  double confidence = 0;
  bool done = false;
  double elapsed = 0;  // s, once done
};

struct RemoteView {
  std::string swa, swb, swc, swd;
  double left_vertical = 0, left_horizontal = 0, right_vertical = 0, right_horizontal = 0, knob = 0;
  std::int64_t stamp_ns = 0;
  std::int64_t received_ns = 0;  // the driver's clock: tells a new report from the last one
};

struct LightsView {
  bool can_control = false;
  std::string front, rear;
  int front_brightness = 0, rear_brightness = 0;
};

struct FrameView {
  std::uint32_t id = 0;
  std::string name;
  std::uint64_t frames = 0, rejected = 0, padded = 0;
};

struct OutcomeView {
  std::uint64_t id = 0;
  std::string kind, what, state, message;
  std::optional<std::uint32_t> error_word;
  RequestOutcome outcome;  // as the driver gave it, for the library's answer texts
  bool done() const { return state == "answered" || state == "failed"; }
};

struct GroundTruthView {
  double x = 0, y = 0, yaw = 0, vx = 0, vy = 0, wz = 0;
  double distance_travelled = 0, yaw_travelled = 0;
  std::string control_mode, motion_mode;
  bool emergency_stop = false, motion_allowed = false;
  std::string motion_refused_reason;
  std::int64_t stamp_ns = 0;
  LightsView lights;
};

struct EventView {
  std::uint64_t sequence = 0;
  std::int64_t time_ns = 0;  // the driver's clock (monotonic)
  std::string kind, severity;
  std::string text;  // describe(): the line the ROS node logs
  std::string json;  // to_json()
};

// The motion estimate in the shape a publisher fills its messages with, in one call: the stamp
// split into s and ns (as ROS splits it), the heading also as a unit quaternion about z.
// (sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw)
using OdometryValues = std::tuple<std::int64_t, std::uint32_t, double, double, double, double,
                                  double, double, double, double, double, double>;
// (sec, nanosec, positions, velocities): the steering joints 1-4, then the wheels 1-4 (the order
// of kSteeringJointNames, kWheelJointNames).
using JointValues =
    std::tuple<std::int64_t, std::uint32_t, std::array<double, 8>, std::array<double, 8>>;
OdometryValues odometry_values(const DriverSnapshot& s);
JointValues joint_values(const DriverSnapshot& s);

OdometryView odometry_view(const DriverSnapshot& s);
EventView event_view(const DriverEvent& e);
JointsView joints_view(const DriverSnapshot& s);
std::vector<MotorView> motors_view(const DriverSnapshot& s);
std::vector<BatteryView> batteries_view(const DriverSnapshot& s);
std::vector<UltrasonicView> ultrasonic_view(const DriverSnapshot& s);
std::optional<IdentificationView> identification_view(const DriverSnapshot& s);
std::optional<RemoteView> remote_view(const DriverSnapshot& s);
std::optional<LightsView> lights_view(const DriverSnapshot& s);
std::vector<FrameView> frames_view(const DriverSnapshot& s);
OutcomeView outcome_view(const RequestOutcome& o);
GroundTruthView ground_truth_view(const sim::ChassisSnapshot& c);

}  // namespace ranger::python
