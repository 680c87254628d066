#include "support/fake_bus.hpp"

namespace ranger::test {

Status FakeBus::send(const CanFrame& frame) {
  if (fail_sends) {
    ++status_.stats.tx_dropped;
    return Error{Errc::kWouldBlock, "fake bus: send refused by the test"};
  }
  sent.push_back(frame);
  ++status_.stats.tx_frames;
  return ok_status();
}

Result<CanFrame> FakeBus::receive(std::chrono::nanoseconds) {
  if (rx_.empty()) return Error{Errc::kTimeout, "fake bus: nothing injected"};
  CanFrame f = rx_.front();
  rx_.pop_front();
  ++status_.stats.rx_frames;
  return f;
}

std::vector<CanFrame> FakeBus::sent_with_id(std::uint32_t id) const {
  std::vector<CanFrame> out;
  for (const CanFrame& f : sent) {
    if (f.id == id) out.push_back(f);
  }
  return out;
}

}  // namespace ranger::test
