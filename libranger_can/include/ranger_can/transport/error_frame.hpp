// What a CAN error frame says and what it does to the bus state.
//
// Controllers report trouble as SocketCAN error frames (CAN_ERR_FLAG set in the ID, the error
// classes in the remaining ID bits, details in the payload; layout of <linux/can/error.h>).
// Every Bus implementation interprets them here, so an error frame means the same thing on a real
// adapter, on vcan and on the in-process loopback.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger::can_error {

// Error classes: bits of CanFrame::id when is_error is set (values of <linux/can/error.h>,
// checked against the kernel header by socketcan_bus.cpp).
inline constexpr std::uint32_t kTxTimeout = 0x001;
inline constexpr std::uint32_t kLostArbitration = 0x002;
inline constexpr std::uint32_t kController = 0x004;  // details in data[1]
inline constexpr std::uint32_t kProtocol = 0x008;
inline constexpr std::uint32_t kTransceiver = 0x010;
inline constexpr std::uint32_t kNoAck = 0x020;
inline constexpr std::uint32_t kBusOff = 0x040;
inline constexpr std::uint32_t kBusError = 0x080;
inline constexpr std::uint32_t kRestarted = 0x100;
inline constexpr std::uint32_t kCounters = 0x200;  // data[6] = tx error count, data[7] = rx
inline constexpr std::uint32_t kClassMask = 0x1FFFFFFF;

// data[1] of a kController frame.
inline constexpr std::uint8_t kCtrlRxOverflow = 0x01;
inline constexpr std::uint8_t kCtrlTxOverflow = 0x02;
inline constexpr std::uint8_t kCtrlRxWarning = 0x04;
inline constexpr std::uint8_t kCtrlTxWarning = 0x08;
inline constexpr std::uint8_t kCtrlRxPassive = 0x10;
inline constexpr std::uint8_t kCtrlTxPassive = 0x20;
inline constexpr std::uint8_t kCtrlActive = 0x40;  // back to error-active

inline constexpr std::uint8_t kErrorFrameDlc = 8;

// Builds an error frame as a controller would send it (for tests, fault injection, simulators).
CanFrame make(std::uint32_t classes, std::uint8_t controller_status = 0);

}  // namespace ranger::can_error

namespace ranger {

struct ErrorFrameReport {
  std::optional<BusState> new_state;  // the controller state this frame reports, if any
  bool controller_problem = false;    // a kController report (warning, passive, overflow, ...)
  bool restarted = false;             // the controller restarted after bus-off
  std::string description;            // e.g. "bus-off", "controller: tx error-passive"
};

// Interprets an error frame (frame.is_error must be set; otherwise the report is empty).
// Severity wins within one frame: bus-off > restarted > passive > warning > active.
ErrorFrameReport interpret_error_frame(const CanFrame& frame);

}  // namespace ranger
