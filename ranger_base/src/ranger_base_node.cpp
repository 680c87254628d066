// ranger_base_node: the RANGER driver. Reads and checks its parameters (exit status 2 naming
// every bad one), runs until SIGINT/SIGTERM or `rosnode kill`, and stops the chassis (a zero
// 0x111) before it exits.
#include <ros/ros.h>

#include <csignal>
#include <cstdlib>
#include <sstream>
#include <string>

#include "ranger_base/parameters.hpp"
#include "ranger_base/ranger_node.hpp"

namespace {

volatile std::sig_atomic_t g_signal = 0;

// roscpp's own handler would call ros::shutdown() from the signal; ours only records the
// request, so the main thread stops the chassis first and shuts ROS down afterwards.
void on_signal(int sig) {
  g_signal = sig;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "ranger_base_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  const ranger_base::NodeHandleParameterSource source(private_nh);
  for (const auto& name : ranger_base::unknown_parameter_names(source)) {
    ROS_WARN("unknown parameter %s ignored (see ranger_base/README.md for the names)",
             source.display_name(name).c_str());
  }
  auto params = ranger_base::load_parameters(source);
  if (!params) {
    std::istringstream lines(params.error().message);
    for (std::string line; std::getline(lines, line);)
      ROS_FATAL("%s", line.c_str());
    ROS_FATAL("ranger_base_node not started: fix the parameters above");
    ros::shutdown();
    return 2;
  }

  {
    ranger_base::RangerNode node(nh, private_nh, std::move(*params));
    node.start();
    ros::WallRate idle(20.0);  // how often a signal or ros::ok() is looked at
    while (ros::ok() && g_signal == 0)
      idle.sleep();
    if (g_signal != 0) ROS_INFO("signal %d: stopping the chassis", static_cast<int>(g_signal));
    node.shutdown();  // zero 0x111 before anything else goes away
  }
  ros::shutdown();
  return 0;
}
