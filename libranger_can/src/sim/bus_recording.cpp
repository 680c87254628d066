#include "ranger_can/sim/bus_recording.hpp"

#include <utility>

#include "ranger_can/wire/candump_log.hpp"

namespace ranger::sim {

CandumpRecording::CandumpRecording(std::unique_ptr<Bus> tap, std::ostream& out, Timestamp origin,
                                   std::string iface)
    : tap_(std::move(tap)), out_(out), origin_(origin), iface_(std::move(iface)) {}

void CandumpRecording::drain() {
  for (;;) {
    auto frame = tap_->receive(std::chrono::nanoseconds(0));
    if (!frame) return;
    if (frame->is_error) continue;  // candump -L has no line for a controller's error report
    CanFrame f = *frame;
    f.stamp = f.stamp - origin_;
    out_ << format_candump_line(f, iface_) << '\n';
    ++frames_;
  }
}

}  // namespace ranger::sim
