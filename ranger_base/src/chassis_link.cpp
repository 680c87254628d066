#include "ranger_base/chassis_link.hpp"

#include <poll.h>
#include <pthread.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>

#include <ranger_can/wire/codec.hpp>
#include <ranger_can/transport/socketcan_bus.hpp>

namespace ranger_base {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

// The longest the CAN thread sleeps while the bus is not open (reopen attempts, stop requests).
// With a bus it sleeps until the controller's next_tick_due() (at most one keep-alive period):
// commands wake it at once, and received frames are handled in a batch at each wake-up rather
// than with one wake-up per frame (about 50 wake-ups a second instead of ~800 for the same work).
// The socket (or loopback) queue holds the ~16 frames meanwhile, and the odometry integrates over
// the frames' own timestamps, so batching changes no estimate.
constexpr nanoseconds kMaxWait = milliseconds(20);
constexpr int kMaxFramesPerIteration = 256;

ranger::Status not_connected(const std::string& port, const std::string& why) {
  return ranger::Error{ranger::Errc::kInterfaceDown,
                       "not connected to " + port + (why.empty() ? "" : ": " + why)};
}

}  // namespace

ChassisLink::ChassisLink(ChassisLinkOptions options, const ranger::Clock& clock)
    : options_(std::move(options)),
      clock_(clock),
      odometry_(options_.odometry),
      joints_(options_.odometry.geometry.wheel_radius) {
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (options_.sim) {
    ranger::LoopbackOptions net;
    net.interface = "sim";
    network_ = std::make_unique<ranger::LoopbackNetwork>(net);
    sim_bus_ = network_->connect();
    runner_ = std::make_unique<ranger::sim::VirtualChassisRunner>(*sim_bus_, *options_.sim, clock_);
    if (options_.sim_error_bits != 0) {
      runner_->with_chassis([this](ranger::sim::VirtualChassis& c) {
        c.set_error_bits(options_.sim_error_bits);
        return 0;
      });
    }
  }
}

ChassisLink::~ChassisLink() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void ChassisLink::start(CommandObserver observer) {
  if (thread_.joinable() || stopped_) return;
  observer_ = std::move(observer);
  thread_ = std::thread([this] { loop(); });
}

void ChassisLink::stop() {
  stop_requested_ = true;
  wake();
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  // The thread sends the stop on its way out; this covers a link that never started (or whose
  // thread died). shutdown() is idempotent.
  if (controller_) controller_->shutdown(clock_.now());
  stopped_ = true;
}

void ChassisLink::wake() {
  if (wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  // A full counter (EAGAIN) means a wake-up is pending anyway.
  [[maybe_unused]] const auto n = ::write(wake_fd_, &one, sizeof one);
}

void ChassisLink::wait(nanoseconds timeout) {
  timeout = std::max(timeout, nanoseconds(0));
  const timespec ts{static_cast<time_t>(timeout.count() / 1'000'000'000),
                    static_cast<long>(timeout.count() % 1'000'000'000)};
  if (wake_fd_ < 0) {
    ::nanosleep(&ts, nullptr);
    return;
  }
  pollfd fd{wake_fd_, POLLIN, 0};
  if (::ppoll(&fd, 1, &ts, nullptr) > 0 && (fd.revents & POLLIN)) {
    std::uint64_t value;
    [[maybe_unused]] const auto n = ::read(wake_fd_, &value, sizeof value);
  }
}

void ChassisLink::try_open(ranger::Timestamp now) {
  if (now < next_open_attempt_) return;
  next_open_attempt_ = now + options_.reconnect_interval;
  ranger::Result<std::unique_ptr<ranger::Bus>> bus = ranger::Error{ranger::Errc::kIoError, ""};
  if (network_) {
    bus = std::unique_ptr<ranger::Bus>(network_->connect());
  } else {
    auto opened = ranger::SocketCanBus::open(options_.port_name);
    if (opened) {
      bus = std::unique_ptr<ranger::Bus>(std::move(*opened));
    } else {
      bus = opened.error();
    }
  }
  if (!bus) {
    bus_error_ = bus.error().message;
    return;
  }
  bus_error_.clear();
  bus_ = std::move(*bus);
  controller_ = std::make_unique<ranger::ChassisController>(*bus_, options_.controller);
  if (pending_mode_) controller_->request_motion_mode(*pending_mode_, now);
}

void ChassisLink::handle_frame(const ranger::CanFrame& frame, ranger::Timestamp now) {
  if (frame.is_error) {
    controller_->on_frame(frame, now);  // counts it
    return;
  }
  ++frames_received_;
  ++frames_by_id_[frame.id];
  auto message = ranger::decode(frame);
  if (!message) {
    controller_->on_frame(frame, now);  // counts and records the decode error
    return;
  }
  controller_->on_message(*message, frame.stamp, now);
  odometry_.on_message(*message, frame.stamp);
  joints_.on_message(*message, frame.stamp);
}

void ChassisLink::drain_and_tick(ranger::Timestamp now) {
  for (int i = 0; i < kMaxFramesPerIteration; ++i) {
    auto frame = bus_->receive(nanoseconds(0));
    if (!frame) break;  // kTimeout: nothing more; other errors: the bus reports and reopens
    handle_frame(*frame, now);
  }
  controller_->tick(clock_.now());
  const auto& st = controller_->state();
  if (st.counters.motion_commands_sent != motion_commands_seen_) {
    motion_commands_seen_ = st.counters.motion_commands_sent;
    if (observer_ && st.last_motion_command) {
      pending_events_.push_back(
          {std::chrono::system_clock::now(), *st.last_motion_command, st.last_solution});
    }
  }
}

void ChassisLink::loop() {
  // Named so that top -H and the performance script can tell the CAN thread apart.
  ::pthread_setname_np(::pthread_self(), "ranger_can_link");
  std::vector<MotionCommandEvent> events;
  try {
    while (!stop_requested_.load()) {
      nanoseconds timeout = kMaxWait;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        const auto now = clock_.now();
        if (!bus_) try_open(now);
        if (bus_) {
          timeout = std::min(timeout, controller_->next_tick_due() - now);
          // A command posted but not yet sent goes out once min_command_interval has passed
          // since the previous 0x111 (the controller's rate bound): look again exactly then.
          // (A moment already past means the last tick had other reasons not to send: then the
          // normal schedule applies, so this can never spin.)
          const auto& st = controller_->state();
          const auto sendable =
              st.last_motion_command_time + options_.controller.min_command_interval - now;
          if (st.refusal == ranger::MotionRefusal::kNone && st.has_command &&
              st.last_command_time > st.last_motion_command_time && sendable > nanoseconds(0)) {
            timeout = std::min(timeout, sendable);
          }
        }
      }
      wait(timeout);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++loop_iterations_;
        if (bus_) drain_and_tick(clock_.now());
        events.swap(pending_events_);
      }
      for (const auto& e : events)
        observer_(e);
      events.clear();
    }
  } catch (const std::exception& e) {  // never let an exception escape the thread
    std::lock_guard<std::mutex> lock(mutex_);
    bus_error_ = std::string("CAN thread failed: ") + e.what();
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    bus_error_ = "CAN thread failed";
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (controller_) controller_->shutdown(clock_.now());
}

ranger::Status ChassisLink::set_command(const ranger::MotionRequest& request) {
  ranger::Status st = ranger::ok_status();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!controller_) return not_connected(options_.port_name, bus_error_);
    st = controller_->set_command(request, clock_.now());
  }
  wake();
  return st;
}

void ChassisLink::request_motion_mode(std::optional<ranger::protocol::MotionMode> mode) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_mode_ = mode;  // also applied to a controller created later
    if (controller_) controller_->request_motion_mode(mode, clock_.now());
  }
  wake();
}

ranger::Status ChassisLink::clear_errors(std::uint8_t code) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!controller_) return not_connected(options_.port_name, bus_error_);
  // Sends at once: send() never blocks (a full queue is an error, not a wait).
  return controller_->clear_errors(code, clock_.now());
}

ranger::Status ChassisLink::set_ultrasonic(bool enable) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!controller_) return not_connected(options_.port_name, bus_error_);
  return controller_->set_ultrasonic(enable, clock_.now());
}

LinkSnapshot ChassisLink::snapshot() const {
  LinkSnapshot s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.now = clock_.now();
    s.port_name = options_.port_name;
    s.bus_open = bus_ != nullptr;
    s.bus_error = bus_error_;
    if (bus_) s.bus = bus_->status();
    s.has_controller = controller_ != nullptr;
    if (controller_) s.controller = controller_->state();
    s.odometry = odometry_.state();
    s.joints = joints_.joints();
    s.frames_by_id = frames_by_id_;
    s.frames_received = frames_received_;
    s.loop_iterations = loop_iterations_;
  }
  if (runner_) {
    s.sim = runner_->with_chassis([](ranger::sim::VirtualChassis& c) { return c.snapshot(); });
    s.sim_failure = runner_->failure();
  }
  return s;
}

bool ChassisLink::with_sim(const std::function<void(ranger::sim::VirtualChassis&)>& f) {
  if (!runner_) return false;
  runner_->with_chassis([&f](ranger::sim::VirtualChassis& c) {
    f(c);
    return 0;
  });
  return true;
}

}  // namespace ranger_base
