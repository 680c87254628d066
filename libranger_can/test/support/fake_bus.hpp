// A recording Bus for deterministic tests: send() appends to `sent` (never blocks, optionally
// fails), receive() pops frames a test injected. No threads, no clock: tests drive the time.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "ranger_can/transport/bus.hpp"

namespace ranger::test {

class FakeBus final : public Bus {
 public:
  Status send(const CanFrame& frame) override;
  Result<CanFrame> receive(std::chrono::nanoseconds timeout) override;
  int fd() const override { return -1; }
  BusStatus status() const override { return status_; }
  void set_filter(const std::vector<std::uint32_t>& ids) override { filter_ = ids; }
  std::string name() const override { return "fake"; }

  // Queues a frame for receive().
  void inject(const CanFrame& frame) { rx_.push_back(frame); }

  // Every frame passed to send() that was accepted, in order (stamp = the sender's time).
  std::vector<CanFrame> sent;
  // Frames sent with `id`, in order.
  std::vector<CanFrame> sent_with_id(std::uint32_t id) const;
  std::size_t count(std::uint32_t id) const { return sent_with_id(id).size(); }
  void clear_sent() { sent.clear(); }

  // While true, send() refuses with kWouldBlock (and counts a drop).
  bool fail_sends = false;

 private:
  std::deque<CanFrame> rx_;
  std::vector<std::uint32_t> filter_;
  BusStatus status_;
};

}  // namespace ranger::test
