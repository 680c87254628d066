#include "ranger_can/transport/error_frame.hpp"
#include "ranger_can/text.hpp"

#include <cstdio>
#include <vector>

namespace ranger {

namespace can_error {

CanFrame make(std::uint32_t classes, std::uint8_t controller_status) {
  CanFrame f;
  f.is_error = true;
  f.id = classes & kClassMask;
  f.dlc = kErrorFrameDlc;
  f.data[1] = controller_status;
  return f;
}

}  // namespace can_error

namespace {

using text::join;

}  // namespace

ErrorFrameReport interpret_error_frame(const CanFrame& frame) {
  using namespace can_error;
  ErrorFrameReport r;
  if (!frame.is_error) return r;
  const std::uint32_t c = frame.id;
  const std::uint8_t ctrl = frame.data[1];
  std::vector<std::string> parts;

  if (c & kBusOff) parts.emplace_back("bus-off");
  if (c & kRestarted) parts.emplace_back("controller restarted");
  if (c & kController) {
    std::vector<std::string> details;
    if (ctrl & kCtrlRxOverflow) details.emplace_back("rx buffer overflow");
    if (ctrl & kCtrlTxOverflow) details.emplace_back("tx buffer overflow");
    if (ctrl & kCtrlRxWarning) details.emplace_back("rx error-warning");
    if (ctrl & kCtrlTxWarning) details.emplace_back("tx error-warning");
    if (ctrl & kCtrlRxPassive) details.emplace_back("rx error-passive");
    if (ctrl & kCtrlTxPassive) details.emplace_back("tx error-passive");
    if (ctrl & kCtrlActive) details.emplace_back("back to error-active");
    if (details.empty()) details.emplace_back("unspecified");
    parts.push_back("controller: " + join(details, ", "));
    r.controller_problem = true;
  }
  if (c & kNoAck) parts.emplace_back("no ACK on transmission (chassis off or bitrate wrong?)");
  if (c & kTxTimeout) parts.emplace_back("transmit timeout");
  if (c & kLostArbitration) parts.emplace_back("lost arbitration");
  if (c & kProtocol) parts.emplace_back("protocol violation");
  if (c & kTransceiver) parts.emplace_back("transceiver status");
  if (c & kBusError) parts.emplace_back("bus error");
  if (c & kCounters) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "error counters tx=%u rx=%u", unsigned{frame.data[6]},
                  unsigned{frame.data[7]});
    parts.emplace_back(buf);
  }
  if (parts.empty()) parts.emplace_back("error frame without class bits");
  r.description = join(parts, "; ");

  if (c & kBusOff) {
    r.new_state = BusState::kBusOff;
  } else if (c & kRestarted) {
    r.new_state = BusState::kActive;
    r.restarted = true;
  } else if ((c & kController) && (ctrl & (kCtrlRxPassive | kCtrlTxPassive))) {
    r.new_state = BusState::kErrorPassive;
  } else if ((c & kController) && (ctrl & (kCtrlRxWarning | kCtrlTxWarning))) {
    r.new_state = BusState::kErrorWarning;
  } else if ((c & kController) && (ctrl & kCtrlActive)) {
    r.new_state = BusState::kActive;
  }
  if ((c & kRestarted) && (c & kBusOff)) r.restarted = true;  // counted, but bus-off wins
  return r;
}

}  // namespace ranger
