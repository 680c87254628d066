// A recording sink for a run on the virtual chassis: an endpoint of its own on the in-process bus
// that, as a candump on a real interface would, hears every frame both ways (the loopback bus
// keeps CAN_RAW's rule: a frame reaches every endpoint but its sender), and writes each as one
// candump -L line (wire/candump_log.hpp) stamped in simulated time, seconds since `origin`. The
// log reads as a real recording would: `ranger_can decode`, `ranger_can odom`, cantools and the
// DBC files (`ranger_can scenario --candump FILE`).
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/types.hpp"

namespace ranger::sim {

class CandumpRecording {
 public:
  // `tap`: the recording's own endpoint on the bus; `out` must outlive the recording.
  CandumpRecording(std::unique_ptr<Bus> tap, std::ostream& out, Timestamp origin,
                   std::string iface = "vcan0");
  // Writes every frame the tap has heard since the last call, in the order the bus delivered them.
  void drain();
  std::uint64_t frames() const { return frames_; }

 private:
  std::unique_ptr<Bus> tap_;
  std::ostream& out_;
  Timestamp origin_;
  std::string iface_;
  std::uint64_t frames_ = 0;
};

}  // namespace ranger::sim
