#include "ranger_can/transport/error_frame.hpp"
#include "ranger_can/text.hpp"

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
using namespace can_error;

// A bit and what it says, in the order the description lists them.
struct BitText {
  std::uint32_t bit;
  const char* text;
};
constexpr BitText kLeadingClasses[] = {{kBusOff, "bus-off"}, {kRestarted, "controller restarted"}};
constexpr BitText kControllerBits[] = {
    {kCtrlRxOverflow, "rx buffer overflow"}, {kCtrlTxOverflow, "tx buffer overflow"},
    {kCtrlRxWarning, "rx error-warning"},    {kCtrlTxWarning, "tx error-warning"},
    {kCtrlRxPassive, "rx error-passive"},    {kCtrlTxPassive, "tx error-passive"},
    {kCtrlActive, "back to error-active"},
};
constexpr BitText kTrailingClasses[] = {
    {kNoAck, "no ACK on transmission (chassis off or bitrate wrong?)"},
    {kTxTimeout, "transmit timeout"},
    {kLostArbitration, "lost arbitration"},
    {kProtocol, "protocol violation"},
    {kTransceiver, "transceiver status"},
    {kBusError, "bus error"},
};

template <std::size_t N>
void add_texts(std::uint32_t bits, const BitText (&table)[N], std::vector<std::string>& out) {
  for (const BitText& b : table) {
    if (bits & b.bit) out.emplace_back(b.text);
  }
}

// The bus state the frame reports, if any (bus-off wins over a restart).
void set_state(std::uint32_t c, std::uint8_t ctrl, ErrorFrameReport& r) {
  const bool controller = (c & kController) != 0;
  if (c & kBusOff) {
    r.new_state = BusState::kBusOff;
  } else if (c & kRestarted) {
    r.new_state = BusState::kActive;
  } else if (controller && (ctrl & (kCtrlRxPassive | kCtrlTxPassive))) {
    r.new_state = BusState::kErrorPassive;
  } else if (controller && (ctrl & (kCtrlRxWarning | kCtrlTxWarning))) {
    r.new_state = BusState::kErrorWarning;
  } else if (controller && (ctrl & kCtrlActive)) {
    r.new_state = BusState::kActive;
  }
  if (c & kRestarted) r.restarted = true;  // counted, but bus-off wins
}

}  // namespace

ErrorFrameReport interpret_error_frame(const CanFrame& frame) {
  ErrorFrameReport r;
  if (!frame.is_error) return r;
  const std::uint32_t c = frame.id;
  const std::uint8_t ctrl = frame.data[1];
  std::vector<std::string> parts;
  add_texts(c, kLeadingClasses, parts);
  if (c & kController) {
    std::vector<std::string> details;
    add_texts(ctrl, kControllerBits, details);
    if (details.empty()) details.emplace_back("unspecified");
    parts.push_back("controller: " + join(details, ", "));
    r.controller_problem = true;
  }
  add_texts(c, kTrailingClasses, parts);
  if (c & kCounters) {
    parts.push_back(text::format("error counters tx=%u rx=%u", unsigned{frame.data[6]},
                                 unsigned{frame.data[7]}));
  }
  if (parts.empty()) parts.emplace_back("error frame without class bits");
  r.description = join(parts, "; ");
  set_state(c, ctrl, r);
  return r;
}

}  // namespace ranger
