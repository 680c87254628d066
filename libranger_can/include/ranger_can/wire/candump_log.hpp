// candump's text formats, the lingua franca of CAN tooling (can-utils): read by `ranger_can
// decode` and `ranger_can odom`, written by the simulator's and the CLI's logging.
//
//   log format (candump -L):      (1700000000.123456) can0 221#0096000000000000
//   default format (candump):     can0  221   [8]  00 96 00 00 00 00 00 00
//   default with -ta timestamps:  (1700000000.123456)  can0  221   [8]  00 96 ...
#pragma once

#include <string>
#include <string_view>

#include "ranger_can/wire/frame.hpp"
#include "ranger_can/result.hpp"

namespace ranger {

struct LogEntry {
  CanFrame frame;     // stamp = the line's timestamp, or 0 when the line has none
  std::string iface;  // "can0"
  bool has_timestamp = false;
};

// Parses one line in either format. Errors (kParseError) say what is wrong ("bad hex digit in
// data", "more than 8 data bytes" ...). Remote (RTR) and CAN FD frames are reported as errors
// too: RANGER uses neither. A well-formed frame with an extended (29-bit) ID is another device's
// on a shared bus: kUnknownId ("extended ID 0x1ABCDEF0 is not a RANGER frame"), so that a reader
// can count it as foreign rather than malformed.
Result<LogEntry> parse_candump_line(std::string_view line);

// Formats a frame as one candump -L line (without a newline).
std::string format_candump_line(const CanFrame& frame, std::string_view iface);

}  // namespace ranger
