#include "ranger_can/transport/loopback_bus.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <utility>

#include "bus_internal.hpp"

namespace ranger {

using bus_internal::IdFilter;
using bus_internal::ReopenSchedule;
using bus_internal::StatusTracker;
using bus_internal::UniqueFd;

namespace loopback_detail {

// One endpoint's "socket". Every field is guarded by the wire's mutex.
struct Endpoint {
  Endpoint(std::uint64_t n, const std::string& name, const Clock& clock,
           std::chrono::nanoseconds reopen_interval)
      : number(n),
        tracker(name),
        schedule(clock, reopen_interval),
        event_fd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

  const std::uint64_t number;
  StatusTracker tracker;
  ReopenSchedule schedule;
  IdFilter filter;
  std::deque<CanFrame> queue;
  bool attached = true;       // has its "socket": receives frames
  bool loss_pending = false;  // the link went down; not yet noticed by a call on this endpoint
  std::condition_variable wake;
  UniqueFd event_fd;
  bool event_signalled = false;

  // Keeps the eventfd readable exactly while receive() would not block.
  void update_event() {
    if (!event_fd.valid()) return;
    const bool ready = !queue.empty() || loss_pending;
    std::uint64_t value = 1;
    if (ready && !event_signalled) {
      event_signalled = ::write(event_fd.get(), &value, sizeof value) == sizeof value;
    } else if (!ready && event_signalled) {
      event_signalled = ::read(event_fd.get(), &value, sizeof value) != sizeof value;
    }
  }
};

struct Wire {
  explicit Wire(LoopbackOptions o) : options(std::move(o)) {
    static const SystemClock system_clock;
    clock = options.clock ? options.clock : &system_clock;
  }

  std::mutex mutex;
  LoopbackOptions options;
  const Clock* clock = nullptr;
  bool link_up = true;
  bool stalled = false;
  std::deque<std::pair<std::uint64_t, CanFrame>> tx_queue;  // (sender number, frame)
  std::vector<std::shared_ptr<Endpoint>> endpoints;
  std::uint64_t next_number = 1;

  // Puts `frame` on the wire now: every other attached endpoint whose filter accepts it.
  void deliver(std::uint64_t sender, CanFrame frame) {
    if (!options.sender_stamps || frame.stamp == Timestamp{0}) frame.stamp = clock->now();
    for (const auto& ep : endpoints) {
      if (ep->number == sender || !ep->attached || ep->loss_pending) continue;
      if (!frame.is_error && !ep->filter.accepts(frame.id)) continue;
      if (ep->queue.size() >= options.rx_queue_capacity) {
        ++ep->tracker.stats().rx_dropped;
        continue;
      }
      ep->queue.push_back(frame);
      ep->update_event();
      ep->wake.notify_all();
    }
  }

  Error down_error(const Endpoint& ep) const {
    return Error{Errc::kInterfaceDown, ep.tracker.status().detail};
  }

  // What every call does first: notice a lost link, and reopen when it is back and due.
  // Returns true when this call noticed the loss.
  bool refresh(Endpoint& ep) {
    const bool noticed_loss = ep.loss_pending;
    if (ep.loss_pending) {
      ep.loss_pending = false;
      ep.attached = false;
      ep.queue.clear();
      ep.update_event();
      ep.tracker.on_lost("interface went down");
      ep.schedule.on_lost();
    }
    if (!ep.attached && ep.schedule.due()) {
      if (link_up) {
        ep.attached = true;
        ep.tracker.on_reopened();
      } else {
        ep.schedule.on_failed();
        ep.tracker.on_reopen_failed("link is still down");
      }
    }
    return noticed_loss;
  }
};

}  // namespace loopback_detail

using loopback_detail::Endpoint;
using loopback_detail::Wire;

// ---- LoopbackNetwork ----------------------------------------------------------------------------

LoopbackNetwork::LoopbackNetwork(LoopbackOptions options)
    : wire_(std::make_shared<Wire>(std::move(options))) {}

LoopbackNetwork::~LoopbackNetwork() = default;

std::unique_ptr<LoopbackBus> LoopbackNetwork::connect() {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  const std::uint64_t n = wire_->next_number++;
  auto ep = std::make_shared<Endpoint>(n, wire_->options.interface + ":" + std::to_string(n),
                                       *wire_->clock, wire_->options.reopen_interval);
  ep->filter.set(wire_->options.filter);
  if (!wire_->link_up) {  // born without a link: reports kDown, reopens when the link is up
    ep->attached = false;
    ep->tracker.on_lost("interface is down");
    ep->schedule.on_lost();
  }
  if (!ep->event_fd.valid()) ep->tracker.status().detail = ep->tracker.name() + ": no eventfd";
  wire_->endpoints.push_back(ep);
  return std::make_unique<LoopbackBus>(wire_, std::move(ep));
}

Result<std::unique_ptr<LoopbackBus>> LoopbackNetwork::open(std::string_view interface) {
  {
    std::lock_guard<std::mutex> lock(wire_->mutex);
    if (interface != wire_->options.interface) {
      return Error{Errc::kNoSuchInterface, "loopback interface '" + std::string(interface) +
                                               "' does not exist (this network provides '" +
                                               wire_->options.interface + "')"};
    }
    if (!wire_->link_up) {
      return Error{Errc::kInterfaceDown,
                   "loopback interface '" + wire_->options.interface + "' is down"};
    }
  }
  return connect();
}

const std::string& LoopbackNetwork::interface() const {
  return wire_->options.interface;
}

std::size_t LoopbackNetwork::endpoint_count() const {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  return wire_->endpoints.size();
}

void LoopbackNetwork::inject_error_frame(const CanFrame& error_frame) {
  CanFrame f = error_frame;
  f.is_error = true;
  std::lock_guard<std::mutex> lock(wire_->mutex);
  if (wire_->link_up) wire_->deliver(0, f);  // sender 0 = the controller, not an endpoint
}

void LoopbackNetwork::set_link_up(bool up) {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  if (wire_->link_up == up) return;
  wire_->link_up = up;
  if (up) return;           // endpoints reopen themselves on their next calls
  wire_->tx_queue.clear();  // the kernel flushes the qdisc of a device going down
  for (const auto& ep : wire_->endpoints) {
    if (!ep->attached) continue;
    ep->loss_pending = true;
    ep->queue.clear();
    ep->update_event();
    ep->wake.notify_all();
  }
}

void LoopbackNetwork::stall_transmission(bool stalled) {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  wire_->stalled = stalled;
  if (stalled) return;
  while (!wire_->tx_queue.empty()) {
    auto [sender, frame] = std::move(wire_->tx_queue.front());
    wire_->tx_queue.pop_front();
    wire_->deliver(sender, frame);
  }
}

// ---- LoopbackBus --------------------------------------------------------------------------------

LoopbackBus::LoopbackBus(std::shared_ptr<Wire> wire, std::shared_ptr<Endpoint> endpoint)
    : wire_(std::move(wire)), endpoint_(std::move(endpoint)) {}

LoopbackBus::~LoopbackBus() {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  auto& eps = wire_->endpoints;
  eps.erase(std::remove(eps.begin(), eps.end(), endpoint_), eps.end());
}

Status LoopbackBus::send(const CanFrame& frame) {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  Endpoint& ep = *endpoint_;
  if (auto st = bus_internal::validate_outgoing(frame, ep.tracker.name()); !st) return st;
  wire_->refresh(ep);
  if (!ep.attached) return wire_->down_error(ep);
  if (wire_->stalled) {
    if (wire_->tx_queue.size() >= wire_->options.tx_queue_capacity) {
      ++ep.tracker.stats().tx_dropped;
      return Error{Errc::kWouldBlock, ep.tracker.name() + ": transmit queue full, frame " +
                                          bus_internal::hex_id(frame.id) + " dropped"};
    }
    wire_->tx_queue.emplace_back(ep.number, frame);
  } else {
    wire_->deliver(ep.number, frame);
  }
  ++ep.tracker.stats().tx_frames;
  return ok_status();
}

Result<CanFrame> LoopbackBus::receive(std::chrono::nanoseconds timeout) {
  // A poll (timeout <= 0) never touches the condition variable: even an already expired timed
  // wait costs a futex round trip, which dominates lock-step simulations that poll every tick.
  const bool poll = timeout <= std::chrono::nanoseconds::zero();
  const auto deadline =
      poll ? std::chrono::steady_clock::time_point{} : std::chrono::steady_clock::now() + timeout;
  std::unique_lock<std::mutex> lock(wire_->mutex);
  Endpoint& ep = *endpoint_;
  const bool noticed_loss = wire_->refresh(ep);
  if (!ep.attached) {
    if (noticed_loss || poll) return wire_->down_error(ep);
    // Nothing to wait on: wait out the timeout like an idle bus, so callers do not spin.
    while (ep.wake.wait_until(lock, deadline) != std::cv_status::timeout) {
    }
    return wire_->down_error(ep);
  }
  for (;;) {
    if (!poll) {
      ep.wake.wait_until(lock, deadline, [&] { return !ep.queue.empty() || ep.loss_pending; });
    }
    if (ep.loss_pending) {
      wire_->refresh(ep);
      return wire_->down_error(ep);
    }
    if (ep.queue.empty()) {
      return Error{Errc::kTimeout, ep.tracker.name() + ": no frame within the timeout"};
    }
    CanFrame frame = ep.queue.front();
    ep.queue.pop_front();
    ep.update_event();
    if (frame.is_error) {
      ep.tracker.on_error_frame(frame);
      return frame;
    }
    if (!ep.filter.accepts(frame.id)) continue;  // queued before a filter change
    ++ep.tracker.stats().rx_frames;
    return frame;
  }
}

int LoopbackBus::fd() const {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  return endpoint_->attached ? endpoint_->event_fd.get() : -1;
}

BusStatus LoopbackBus::status() const {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  return endpoint_->tracker.status();
}

void LoopbackBus::set_filter(const std::vector<std::uint32_t>& ids) {
  std::lock_guard<std::mutex> lock(wire_->mutex);
  endpoint_->filter.set(ids);
}

std::string LoopbackBus::name() const {
  return endpoint_->tracker.name();
}

}  // namespace ranger
