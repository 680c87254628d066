// The Bus over Linux SocketCAN (CAN_RAW), for a real adapter (can0 from gs_usb) or vcan.
//
//  * Receive filters in the kernel: only the configured IDs (default: every RANGER ID) wake us.
//  * Error frames are enabled and turned into BusState (see error_frame.hpp).
//  * Every frame carries the kernel's receive timestamp (SO_TIMESTAMPNS, CLOCK_REALTIME):
//    odometry integrates over when the frame arrived, not over when a thread got round to it.
//  * send() never blocks: a full transmit queue (ENOBUFS from the qdisc, EAGAIN from the socket
//    buffer) drops the frame, counts it in tx_dropped and returns kWouldBlock.
//  * Frames are read in batches: one recvmmsg() takes everything queued (up to kReceiveBatch
//    frames), and receive() hands them out one by one without another system call;
//    receive_queued() hands out the whole queue, and receive(0) reads no clock.
//  * Frames the kernel dropped because we read too slowly are counted in rx_dropped
//    (SO_RXQ_OVFL on every frame queued after a drop; SO_MEMINFO when the status is read after
//    a quiet spell or a backlog).
//  * Losing the interface (link down: ENETDOWN; adapter unplugged: ENODEV) closes the socket,
//    reports kDown with the reason, and later send()/receive() calls reopen it by name once it is
//    back (first attempt at once, then at most one per `reopen_interval` on the injected clock).
//
// Thread-safety: send() and receive() may be called from different threads (concurrent
// receive() calls take turns); status(), fd(),
// set_filter() from any thread. fd() changes when the socket is reopened: re-read it after
// status() reported kDown.
#pragma once

#include <linux/can.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

struct SocketCanOptions {
  // IDs delivered by receive(); empty = every standard-ID data frame.
  std::vector<std::uint32_t> filter = protocol::all_ids();
  // Minimum time between two reopen attempts while the interface is gone.
  std::chrono::nanoseconds reopen_interval = std::chrono::seconds(1);
  // Clock for the reopen rate limit (not for frame timestamps: those come from the kernel).
  // nullptr = a steady clock. Must outlive the bus.
  const Clock* clock = nullptr;
  // SO_RCVBUF in bytes; 0 keeps the kernel default.
  int receive_buffer_bytes = 0;
};

class SocketCanBus final : public Bus {
 public:
  // At most this many frames per recvmmsg() (about 20 ms of the RANGER's feedback).
  static constexpr std::size_t kReceiveBatch = 32;

  // Opens `interface` (e.g. "can0", "vcan0"). Errors name the interface and say what to do:
  // kNoSuchInterface, kNotCanInterface, kInterfaceDown, kPermissionDenied, or kIoError (e.g. a
  // kernel without CAN support: "modprobe can-raw").
  static Result<std::unique_ptr<SocketCanBus>> open(const std::string& interface,
                                                    SocketCanOptions options = {});

  // Only open() can make the key: every bus starts with a working socket.
  class Key {
    explicit Key() = default;
    friend class SocketCanBus;
  };
  struct Socket;
  SocketCanBus(Key, std::string interface, SocketCanOptions options,
               std::shared_ptr<Socket> socket);
  ~SocketCanBus() override;

  Status send(const CanFrame& frame) override;
  Result<CanFrame> receive(std::chrono::nanoseconds timeout) override;
  std::size_t receive_queued(std::vector<Result<CanFrame>>& out, std::size_t max) override;
  int fd() const override;
  BusStatus status() const override;
  void set_filter(const std::vector<std::uint32_t>& ids) override;
  std::string name() const override { return interface_; }

 private:
  // Current socket, reopening it first if it is gone and an attempt is due. Null while down.
  std::shared_ptr<Socket> acquire_socket();
  std::shared_ptr<Socket> reopen_if_due_locked();
  // `failed` reported that the interface went down or away (errno `err`): closes it, reports
  // kDown and makes the immediate first reopen attempt. Returns the socket to carry on with, or
  // null while the interface is down.
  std::shared_ptr<Socket> on_interface_lost(const std::shared_ptr<Socket>& failed, int err);
  Error down_error() const;
  // Reads what `socket` has queued (one recvmmsg, not waiting) into rx_: the number of frames
  // read, 0 for none (EAGAIN), -1 for an error (`err` set).
  int read_batch(const std::shared_ptr<Socket>& socket, int& err);
  // read_batch() on `socket`, retried after EINTR and, after a lost interface, on the reopened
  // socket (`socket` follows it; null while down): the frames read (0: nothing queued), or the
  // error to report (the interface down, or why it cannot be read).
  Result<int> read_queued(std::shared_ptr<Socket>& socket);
  // Drops the frames read before the last set_filter() that the new filter refuses.
  void refilter_ready();

  struct State;
  struct ReceiveBatch;
  const std::string interface_;
  const SocketCanOptions options_;
  mutable std::mutex mutex_;
  std::unique_ptr<State> state_;      // guarded by mutex_
  std::mutex receive_mutex_;          // one receive() at a time
  std::unique_ptr<ReceiveBatch> rx_;  // guarded by receive_mutex_: read, not yet returned
  std::atomic<std::uint64_t> filter_generation_{0};  // set_filter() calls so far
};

// ---- kernel frame conversion (exposed for unit tests; no socket needed) -----------------------
namespace socketcan {

// Converts what recvmmsg() returned (`nbytes` bytes into `kf`) into a CanFrame. Rejects, with a
// message naming `interface` and the ID: a size other than a classic CAN frame, DLC > 8,
// extended (29-bit) and remote frames. Error frames come back with is_error set.
Result<CanFrame> from_kernel(const struct can_frame& kf, std::size_t nbytes,
                             std::string_view interface);
struct can_frame to_kernel(const CanFrame& frame);

}  // namespace socketcan

}  // namespace ranger
