// The bus abstraction: everything above it (controller, simulator, CLI, ROS node) talks to a
// `Bus` and does not know whether frames cross a kernel SocketCAN socket or an in-process queue.
// Modelled on ros_canopen's socketcan_interface split: an abstract interface, a SocketCAN
// implementation (socketcan_bus.hpp) and an in-process loopback for tests (loopback_bus.hpp).
//
// Contract shared by every implementation (one behavioural test suite runs against each):
//  * send() never blocks. A full transmit queue drops the frame and returns kWouldBlock; the
//    drop is counted in BusStatistics::tx_dropped.
//  * receive() waits at most `timeout` and returns kTimeout when nothing came. Frames carry a
//    receive timestamp from the bus's clock. Error frames come back with is_error = true after
//    updating state(); callers may ignore them.
//  * receive_queued() returns what has already arrived, without waiting, as receive(0) would one
//    call at a time, with as few system calls as the implementation can manage.
//  * Only frames whose ID passes the receive filter are delivered (default: RANGER IDs only).
//  * A lost interface (unplugged, link down) is reported through state() == kDown and recovered
//    by the implementation itself (reopen on the next call after it reappears); nothing throws.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger {

// CAN controller / link state, worst first in severity order for display.
enum class BusState {
  kActive,        // error-active: all well
  kErrorWarning,  // error counters above the warning level
  kErrorPassive,  // error counters above 127: the controller no longer sends error flags
  kBusOff,        // controller disconnected from the bus (too many errors)
  kDown,          // interface gone or administratively down; reopening is being attempted
};
inline constexpr auto kBusStateNames = text::enum_names<BusState>({
    {BusState::kActive, "active"},
    {BusState::kErrorWarning, "error-warning"},
    {BusState::kErrorPassive, "error-passive"},
    {BusState::kBusOff, "bus-off"},
    {BusState::kDown, "down"},
});
inline std::string_view to_string(BusState s) {
  return kBusStateNames.name(s);
}

struct BusStatistics {
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_frames = 0;            // delivered data frames (after filtering)
  std::uint64_t tx_dropped = 0;           // send() found the queue full (kWouldBlock)
  std::uint64_t rx_dropped = 0;           // frames the kernel or queue dropped before we read them
  std::uint64_t error_frames = 0;         // error frames seen
  std::uint64_t controller_problems = 0;  // CAN_ERR_CRTL reports (overflow, warning, passive)
  std::uint64_t restarts = 0;             // controller restarted after bus-off (CAN_ERR_RESTARTED)
  std::uint64_t reopens = 0;              // times the interface was reopened after going down
};

struct BusStatus {
  BusState state = BusState::kActive;
  std::string detail;  // last transition's reason, e.g. "bus-off reported by controller"
  BusStatistics stats;
};

class Bus {
 public:
  virtual ~Bus() = default;
  Bus() = default;
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  virtual Status send(const CanFrame& frame) = 0;
  virtual Result<CanFrame> receive(std::chrono::nanoseconds timeout) = 0;

  // What has already arrived, without waiting: appends to `out` at most `max` results, in order,
  // exactly as successive receive(0ns) calls would return them, and returns how many it appended.
  // It stops after the first error (a frame the bus could not read, the interface gone; never
  // kTimeout, which just ends the list), leaving what follows for the next call. Frames that
  // arrive while it runs may be left for the next call. The default calls receive(0ns);
  // SocketCanBus reads the whole queue with one recvmmsg() per kReceiveBatch frames.
  virtual std::size_t receive_queued(std::vector<Result<CanFrame>>& out, std::size_t max);

  // A file descriptor that becomes readable when receive() would not block (for poll/epoll), or
  // -1 while none is available (e.g. interface down).
  virtual int fd() const = 0;

  virtual BusStatus status() const = 0;

  // Replaces the receive filter: only these IDs are delivered. Empty = deliver every ID.
  virtual void set_filter(const std::vector<std::uint32_t>& ids) = 0;

  // Human-readable name ("can0", "loopback:1").
  virtual std::string name() const = 0;
};

}  // namespace ranger
