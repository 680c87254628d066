#include "ranger_can/transport/bus.hpp"

namespace ranger {

std::size_t Bus::receive_queued(std::vector<Result<CanFrame>>& out, std::size_t max) {
  std::size_t n = 0;
  while (n < max) {
    Result<CanFrame> r = receive(std::chrono::nanoseconds(0));
    if (!r && r.error().code == Errc::kTimeout) break;
    const bool failed = !r;
    out.push_back(std::move(r));
    ++n;
    if (failed) break;
  }
  return n;
}

}  // namespace ranger
