// A classic CAN 2.0 frame as it travels between the library and a bus.
//
// The library never hands out the kernel's `struct can_frame`: keeping our own value type lets
// the codec, the simulator and the tests run on machines without <linux/can.h> semantics, and
// lets every frame carry the receive timestamp that odometry integrates over.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "ranger_can/types.hpp"

namespace ranger {

using ranger::Timestamp;  // types.hpp

struct CanFrame {
  static constexpr std::size_t kMaxDlc = 8;

  std::uint32_t id = 0;  // 11-bit standard identifier (RANGER uses standard IDs only)
  std::uint8_t dlc = 0;  // number of valid bytes in `data`, 0..8
  std::array<std::uint8_t, kMaxDlc> data{};  // bytes past `dlc` are zero
  Timestamp stamp{0};  // receive time (or send time for frames we create); 0 = unknown

  // Marks a frame that reports a controller/bus error (SocketCAN CAN_ERR_FLAG); `id` then holds
  // the CAN_ERR_* class bits. Error frames never reach the codec.
  bool is_error = false;
};

inline bool operator==(const CanFrame& a, const CanFrame& b) {
  return a.id == b.id && a.dlc == b.dlc && a.data == b.data && a.is_error == b.is_error;
}
inline bool operator!=(const CanFrame& a, const CanFrame& b) {
  return !(a == b);
}

}  // namespace ranger
