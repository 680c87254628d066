// ranger_base/PerfSubscriber: a nodelet subscribing to odom, /tf and joint_states, for
// measure_performance.py's nodelet phase (the driver and its consumers in one manager: the
// messages pass as shared pointers, without serialisation). It counts what arrives and, when
// unloaded, writes each topic's rate (messages/s between its first and its last message) as one
// JSON object to the file named by its private parameter `report` (nothing if unset).
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>

namespace ranger_base {

class PerfSubscriber : public nodelet::Nodelet {
 public:
  ~PerfSubscriber() override {
    for (auto& s : subs_)
      s.shutdown();
    if (report_.empty()) return;
    std::FILE* f = std::fopen(report_.c_str(), "w");
    if (!f) return;
    std::lock_guard<std::mutex> lock(mutex_);
    std::fprintf(f, "{");
    const char* sep = "";
    for (const auto& [topic, seen] : seen_) {
      const double span = std::chrono::duration<double>(seen.last - seen.first).count();
      std::fprintf(f, "%s\"%s\": %.1f", sep, topic.c_str(),
                   span > 0.0 ? static_cast<double>(seen.count - 1) / span : 0.0);
      sep = ", ";
    }
    std::fprintf(f, "}\n");
    std::fclose(f);
  }

 private:
  struct Seen {
    std::size_t count = 0;
    std::chrono::steady_clock::time_point first, last;
  };

  void onInit() override {
    getPrivateNodeHandle().param<std::string>("report", report_, "");
    ros::NodeHandle& nh = getNodeHandle();
    subs_[0] = nh.subscribe<nav_msgs::Odometry>(
        "odom", 10, [this](const nav_msgs::Odometry::ConstPtr&) { count("odom"); });
    subs_[1] = nh.subscribe<sensor_msgs::JointState>(
        "joint_states", 10,
        [this](const sensor_msgs::JointState::ConstPtr&) { count("joint_states"); });
    subs_[2] = nh.subscribe<tf2_msgs::TFMessage>(
        "/tf", 10, [this](const tf2_msgs::TFMessage::ConstPtr&) { count("/tf"); });
  }

  void count(const char* topic) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    Seen& s = seen_[topic];
    if (s.count++ == 0) s.first = now;
    s.last = now;
  }

  std::string report_;
  ros::Subscriber subs_[3];
  std::mutex mutex_;
  std::map<std::string, Seen> seen_;
};

}  // namespace ranger_base

PLUGINLIB_EXPORT_CLASS(ranger_base::PerfSubscriber, nodelet::Nodelet)
