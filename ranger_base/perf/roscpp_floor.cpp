// roscpp_floor: what roscpp alone costs for the node's real-use traffic, so the driver's share of
// the node's CPU can be told from the transport's (measure_performance.py runs it beside the node).
// It publishes what ranger_base_node publishes at 50 Hz (odom, /tf, joint_states: the same
// conversions, so the same message sizes) and subscribes to cmd_vel, and does nothing else: no
// driver, no bus, no other topics, no diagnostics. A benchmark aid, not a driver.
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_broadcaster.h>

#include "ranger_base/conversions.hpp"
#include "ranger_base/parameters.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "roscpp_floor");
  ros::NodeHandle nh;
  ros::Publisher odom_pub = nh.advertise<nav_msgs::Odometry>("odom", 10);
  ros::Publisher joint_pub = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  ros::Subscriber cmd_vel = nh.subscribe(
      "cmd_vel", 1, +[](const geometry_msgs::Twist::ConstPtr&) {});
  tf2_ros::TransformBroadcaster tf;
  ros::AsyncSpinner spinner(1);  // cmd_vel's callbacks, as the node's spinner
  spinner.start();

  const ranger_base::NodeParameters params;
  ranger::OdometryState odometry;
  const ranger::WheelJoints joints;
  ros::Rate rate(50.0);
  while (ros::ok()) {
    odometry.stamp = ranger::Timestamp(ros::Time::now().toNSec());
    const nav_msgs::Odometry odom = ranger_base::to_odometry(odometry, params);
    odom_pub.publish(odom);
    tf.sendTransform(ranger_base::to_transform(odom));
    joint_pub.publish(ranger_base::to_joint_state(joints, odom.header.stamp));
    rate.sleep();
  }
}
