// The motion estimate as ROS 2 messages on the wire: nav_msgs/Odometry, tf2_msgs/TFMessage (the
// odometry's one transform) and sensor_msgs/JointState in their serialised form, the bytes rclpy's
// Publisher.publish takes instead of a message. The ROS 2 node publishes those 50 times a second;
// building them here skips rclpy's per-message conversion from Python objects and the rmw's
// serialisation, the bulk of its publication cost.
//
// The encoding is OMG CDR (XCDR1, plain) as rmw_fastrtps writes it (checked against it here): a
// 4-byte encapsulation header (CDR little endian, no options), then the fields in message order,
// each primitive aligned to its size (8 at most) from the end of the header, a string as its
// length with the terminating NUL (uint32) and its bytes, a sequence as its length (uint32) and
// its elements; padding is written as zeros. Nothing here is trusted blindly: at start-up the node
// reads sample bytes back with the rmw's own deserialisation and publishes messages unless they
// read as exactly the messages it would have published (ros2/ranger_base conversions.py,
// motion_encoder).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "views.hpp"

namespace ranger::python {

// What the three messages carry beside the estimate, fixed for a node's life: the frames (odom's
// header and child frame, the transform's), the joint names in JointValues' order and the
// covariances' diagonals (pose: the floor the odometry's variance adds to; twist: as given).
struct MotionWireSetup {
  std::string odom_frame;
  std::string base_frame;
  std::vector<std::string> joint_names;
  std::array<double, 6> pose_covariance_diagonal{};
  std::array<double, 6> twist_covariance_diagonal{};
};

// The encoder of one node: each call returns one message's serialised bytes. Pose covariance =
// diag(pose_covariance_diagonal) + the odometry's x/y/yaw variance at (0,0), (1,1), (5,5); twist
// covariance = diag(twist_covariance_diagonal); JointState: names, positions, velocities, no
// efforts (as the ROS 1 node publishes).
class MotionWireEncoder {
 public:
  explicit MotionWireEncoder(MotionWireSetup setup);

  std::string odometry(const OdometryValues& v) const;
  std::string transform(const OdometryValues& v) const;
  std::string joint_state(const JointValues& v) const;

 private:
  MotionWireSetup setup_;
};

// geometry_msgs/Twist read from its serialised form, the bytes rclpy's raw subscription hands
// over (the node's cmd_vel: no Python message is built for a command): linear x, y, z, then
// angular x, y, z, as on the wire. Read: plain CDR and plain XCDR2 (encapsulation ids 0x0000,
// 0x0001, 0x0006, 0x0007), either byte order, the six doubles right after the header; bytes
// beyond the message (alignment slack, a longer serialisation) ignored. Anything else (shorter,
// another encapsulation) gives nullopt: the caller hands the bytes to the rmw's own reader. The
// values are not judged here (NaN and infinity stay what they are: the driver refuses them).
std::optional<std::array<double, 6>> read_twist(std::string_view bytes);

}  // namespace ranger::python
