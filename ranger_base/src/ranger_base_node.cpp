// ranger_base_node: the RANGER driver as an executable (ranger_nodelet.cpp: the same as a
// nodelet; both run ranger_base::RangerNode). Reads and checks its parameters (exit status 2 naming
// every bad one; `ranger_base_node --check-parameters` checks them alone, parameter_check.hpp),
// runs until SIGINT/SIGTERM or `rosnode kill`, and stops the chassis (a zero motion command,
// logged and published on cmd_vel_out) before ROS goes down.
//
// Shutdown is prompt: SIGINT, SIGTERM and the master's shutdown request (`rosnode kill`) only
// write to a pipe the main thread waits on; the main thread then stops the chassis while ROS is
// still up (so the stop reaches the log and cmd_vel_out), and shuts ROS down afterwards. roscpp's
// own handlers would shut ROS down first, from the signal or its XML-RPC thread. ros::shutdown()
// itself is hurried along (ros_shutdown_promptly below), so that the process exits well within
// 0.3 s.
#include <fcntl.h>
#include <poll.h>
#include <ros/callback_queue.h>
#include <ros/poll_manager.h>
#include <ros/ros.h>
#include <ros/xmlrpc_manager.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include "ranger_base/parameter_check.hpp"
#include "ranger_base/ranger_node.hpp"

namespace ros {
// Exported by libroscpp (init.cpp) but not declared in its installed headers.
CallbackQueuePtr getInternalCallbackQueue();
}  // namespace ros

namespace {

// ros::shutdown() with fewer idle waits: roscpp's internal callback thread and its poll thread
// notice the shutdown only when their 100 ms waits end. The internal queue is disabled first (its
// thread stops waiting), and while ros::shutdown() runs, a helper signals the poll set every 2 ms.
// (The XML-RPC thread's 100 ms wait cannot be cut short through roscpp's API: it remains.)
void ros_shutdown_promptly() {
  std::mutex mutex;
  std::condition_variable done_cv;
  bool done = false;
  std::thread waker([&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (!done) {
      ros::PollManager::instance()->getPollSet().signal();
      done_cv.wait_for(lock, std::chrono::milliseconds(2));
    }
  });
  ros::getInternalCallbackQueue()->disable();
  ros::shutdown();
  {
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
  }
  done_cv.notify_all();
  waker.join();
}

int g_wake[2] = {-1, -1};  // self-pipe: [0] read by the main thread, [1] written on a request
// Set by a signal handler (any thread) and by the XML-RPC thread, read by the main thread:
// atomics, lock-free (so async-signal-safe). A volatile flag raced with the XML-RPC thread
// (ThreadSanitizer on the node, scripts/test_sanitizers.sh ros_thread).
std::atomic<int> g_signal{0};
std::atomic<bool> g_kill_requested{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

void wake_main() {
  const char byte = 1;
  [[maybe_unused]] const auto n = ::write(g_wake[1], &byte, 1);  // full pipe: already awake
}

void on_signal(int sig) {  // async-signal-safe: two stores and a write
  g_signal = sig;
  wake_main();
}

// The master's (or `rosnode kill`'s) shutdown request, on roscpp's XML-RPC thread.
void on_shutdown_request(XmlRpc::XmlRpcValue& params, XmlRpc::XmlRpcValue& result) {
  if (params.getType() == XmlRpc::XmlRpcValue::TypeArray && params.size() > 1) {
    ROS_INFO("shutdown requested (%s): stopping the chassis",
             static_cast<std::string>(params[1]).c_str());
  }
  g_kill_requested = true;
  wake_main();
  result = ros::xmlrpc::responseInt(1, "", 0);
}

// Waits until a signal or shutdown request arrives, or ROS stops by itself.
void wait_for_stop_request() {
  pollfd fd{g_wake[0], POLLIN, 0};
  while (g_signal == 0 && !g_kill_requested && ros::ok()) {
    // The timeout only notices ros::ok() turning false some other way.
    if (::poll(&fd, 1, 500) > 0) {
      char buf[16];
      while (::read(g_wake[0], buf, sizeof buf) > 0) {
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  // ranger_bringup's launch files check the parameters before anything starts
  // (parameter_check.hpp).
  if (argc == 2 && std::strcmp(argv[1], "--check-parameters") == 0) {
    return ranger_base::check_parameters(std::cin, std::cerr);
  }
  ros::init(argc, argv, "ranger_base_node", ros::init_options::NoSigintHandler);
  if (::pipe2(g_wake, O_CLOEXEC | O_NONBLOCK) != 0) {
    ROS_FATAL("ranger_base_node: cannot create its wake-up pipe: %s", std::strerror(errno));
    return 1;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  ros::XMLRPCManager::instance()->unbind("shutdown");
  ros::XMLRPCManager::instance()->bind("shutdown", on_shutdown_request);

  auto node = ranger_base::RangerNode::from_parameters(nh, private_nh);
  if (!node) {
    std::istringstream lines(node.error().message);
    for (std::string line; std::getline(lines, line);)
      ROS_FATAL("%s", line.c_str());
    ROS_FATAL("ranger_base_node not started: fix the above");
    ros::shutdown();
    return 2;
  }

  (*node)->start();
  wait_for_stop_request();
  if (const int sig = g_signal; sig != 0) {
    ROS_INFO("signal %d (%s): stopping the chassis", sig, sig == SIGINT ? "SIGINT" : "SIGTERM");
  }
  (*node)->shutdown();  // the stop goes out (and is logged) before anything else goes away
  node->reset();
  ros_shutdown_promptly();
  return 0;
}
