// A roscpp callback queue that runs each callback at once, on the thread that queues it: roscpp's
// network thread for a publisher in another process, the publisher's own thread for one in the
// same process (a nodelet). For subscriptions whose callback only hands a value over and never
// blocks (cmd_vel -> the driver's mailbox): no spinner thread is woken per message, which saves
// a thread switch per command in CPU and in latency.
#pragma once

#include <ros/callback_queue_interface.h>
#include <ros/console.h>

#include <cstdint>
#include <exception>
#include <mutex>

namespace ranger_base {

class ImmediateCallbackQueue final : public ros::CallbackQueueInterface {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t /*owner_id*/) override {
    // One at a time (a subscription's callbacks never run concurrently), and removeByID waits
    // for a call in progress.
    std::lock_guard<std::mutex> lock(mutex_);
    if (disabled_ || !callback->ready()) return;
    // A subscription queue answers TryAgain only to a concurrent call, which the lock rules out.
    // Nothing may escape into roscpp's network thread.
    try {
      callback->call();
    } catch (const std::exception& e) {
      ROS_ERROR_THROTTLE(5.0, "callback failed: %s", e.what());
    } catch (...) {
      ROS_ERROR_THROTTLE(5.0, "callback failed");
    }
  }
  // The owner's subscription is already gone from roscpp's lists when this is called: once the
  // call in progress (if any) ends, none of its callbacks runs again.
  void removeByID(uint64_t /*owner_id*/) override { std::lock_guard<std::mutex> lock(mutex_); }
  // From now on callbacks are dropped (shutdown).
  void disable() {
    std::lock_guard<std::mutex> lock(mutex_);
    disabled_ = true;
  }

 private:
  std::mutex mutex_;
  bool disabled_ = false;
};

}  // namespace ranger_base
