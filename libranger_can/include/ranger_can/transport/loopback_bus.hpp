// An in-process CAN bus: a LoopbackNetwork is one simulated interface (default "loopback0") with
// any number of endpoints, each a ranger::Bus. The simulator and the driver run together on it
// where the kernel has no vcan, and unit tests need no kernel support.
//
// It keeps SocketCAN's CAN_RAW semantics (the same behavioural suite runs on both):
//  * a frame sent by one endpoint reaches every other endpoint, never the sender itself
//    (CAN_RAW without CAN_RAW_RECV_OWN_MSGS), subject to each endpoint's receive filter;
//  * frames are stamped with the injected clock when they are delivered (the kernel's receive
//    timestamp);
//  * each endpoint has a bounded receive queue (the socket receive buffer): a frame arriving at
//    a full queue is dropped and counted in that endpoint's rx_dropped; the sender is not told,
//    as on a real bus where a slow reader never slows the writer;
//  * send() never blocks. Normally the wire takes every frame at once. While transmission is
//    stalled (stall_transmission(true), the counterpart of `tc qdisc add dev vcan0 root plug`,
//    or of a bus where nothing acknowledges) frames wait in a bounded transmit queue; when it is
//    full send() drops the frame, counts tx_dropped and returns kWouldBlock, as SocketCAN does
//    with ENOBUFS;
//  * error frames (inject_error_frame, as a controller reports them) reach every endpoint
//    regardless of its filter and update its state when received;
//  * set_link_up(false) is `ip link set <if> down`: every endpoint notices at its next call (or
//    at once if blocked in receive()), reports kDown, loses its queued frames and reopens itself
//    once the link is up: first attempt at once, then at most one per reopen_interval on the
//    injected clock;
//  * fd() is an eventfd that is readable while receive() would not block; -1 while down.
//
// Thread-safe: endpoints may be used from different threads; the network and its endpoints may
// be destroyed in any order.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

struct LoopbackOptions {
  std::string interface = "loopback0";
  // Receive filter of new endpoints; empty = every ID.
  std::vector<std::uint32_t> filter = protocol::all_ids();
  std::size_t rx_queue_capacity = 1024;  // frames per endpoint
  std::size_t tx_queue_capacity = 64;    // frames held while transmission is stalled
  std::chrono::nanoseconds reopen_interval = std::chrono::seconds(1);
  // Stamps frames and rate-limits reopening. nullptr = SystemClock (the epoch of SocketCAN's
  // timestamps). Must outlive the network and its endpoints.
  const Clock* clock = nullptr;
  // false: every frame is stamped with the clock when it goes on the wire. true: a frame that
  // carries a stamp keeps it (a sender with a timeline of its own, the virtual chassis, sends the
  // frames of a late step stamped with their due times); an unstamped one gets the clock's.
  bool sender_stamps = false;
};

namespace loopback_detail {
struct Wire;
struct Endpoint;
}  // namespace loopback_detail

class LoopbackBus;

class LoopbackNetwork {
 public:
  explicit LoopbackNetwork(LoopbackOptions options = {});
  ~LoopbackNetwork();
  LoopbackNetwork(const LoopbackNetwork&) = delete;
  LoopbackNetwork& operator=(const LoopbackNetwork&) = delete;

  // A new endpoint on this network's interface.
  std::unique_ptr<LoopbackBus> connect();
  // Like SocketCanBus::open(): kNoSuchInterface (naming it) unless `interface` is this
  // network's, kInterfaceDown while the link is down.
  Result<std::unique_ptr<LoopbackBus>> open(std::string_view interface);

  const std::string& interface() const;
  std::size_t endpoint_count() const;

  // ---- fault injection (tests, simulator) ----
  // Delivers a controller error frame (see error_frame.hpp, e.g. can_error::make(kBusOff)) to
  // every endpoint, as the kernel delivers a controller's report to every socket.
  void inject_error_frame(const CanFrame& error_frame);
  // `ip link set <if> down` / `up`.
  void set_link_up(bool up);
  // true: frames wait in the transmit queue (kWouldBlock once full). false: the queue drains to
  // the receivers in order.
  void stall_transmission(bool stalled);

 private:
  std::shared_ptr<loopback_detail::Wire> wire_;
};

class LoopbackBus final : public Bus {
 public:
  // Made by LoopbackNetwork only.
  LoopbackBus(std::shared_ptr<loopback_detail::Wire> wire,
              std::shared_ptr<loopback_detail::Endpoint> endpoint);
  ~LoopbackBus() override;

  Status send(const CanFrame& frame) override;
  Result<CanFrame> receive(std::chrono::nanoseconds timeout) override;
  int fd() const override;
  BusStatus status() const override;
  void set_filter(const std::vector<std::uint32_t>& ids) override;
  std::string name() const override;

 private:
  std::shared_ptr<loopback_detail::Wire> wire_;
  std::shared_ptr<loopback_detail::Endpoint> endpoint_;
};

}  // namespace ranger
