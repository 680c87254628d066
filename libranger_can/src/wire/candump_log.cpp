// Reading and writing can-utils' candump text formats (see candump_log.hpp for examples).
//
// The parser is a small hand-written scanner over a string_view: it must survive any byte
// sequence (the CLI feeds it whatever a file holds), so every access is bounds-checked and every
// rejection says what was wrong.
#include "ranger_can/wire/candump_log.hpp"

#include <cstdint>
#include <cstdio>
#include <string>

#include "ranger_can/text.hpp"

namespace ranger {

namespace {

constexpr std::uint32_t kCanErrFlag = 0x20000000U;  // SocketCAN CAN_ERR_FLAG
constexpr std::uint32_t kCanEffMask = 0x1FFFFFFFU;
constexpr std::uint32_t kCanSffMax = 0x7FF;
constexpr std::size_t kMaxIfaceLength = 15;  // IFNAMSIZ - 1

Error parse_error(std::string what) {
  return Error{Errc::kParseError, std::move(what)};
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v';
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Printable rendering of a token for error messages (bounded, no control bytes).
std::string quoted(std::string_view s) {
  constexpr std::size_t kMax = 24;
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7F) ? static_cast<char>(c) : '?';
  }
  if (s.size() > kMax) out += "...";
  return out + "'";
}

class Scanner {
 public:
  explicit Scanner(std::string_view s) : s_(s) {}
  void skip_space() {
    while (pos_ < s_.size() && is_space(s_[pos_]))
      ++pos_;
  }
  bool at_end() {
    skip_space();
    return pos_ >= s_.size();
  }
  char peek() {
    skip_space();
    return pos_ < s_.size() ? s_[pos_] : '\0';
  }
  // The next whitespace-delimited token (empty at the end).
  std::string_view token() {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !is_space(s_[pos_]))
      ++pos_;
    return s_.substr(start, pos_ - start);
  }
  // Everything up to (excluding) `delim`, consuming the delimiter; false when it is missing.
  bool until(char delim, std::string_view* out) {
    const std::size_t end = s_.find(delim, pos_);
    if (end == std::string_view::npos) return false;
    *out = s_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return true;
  }
  std::string_view rest() {
    skip_space();
    return s_.substr(pos_);
  }

 private:
  std::string_view s_;
  std::size_t pos_ = 0;
};

// "1700000000.123456" (candump -L / -ta) or a relative "000.000123" (-td / -tz) -> nanoseconds.
Result<Timestamp> parse_timestamp(std::string_view t) {
  if (t.find(':') != std::string_view::npos || t.find(' ') != std::string_view::npos) {
    return parse_error("date-formatted timestamp " + quoted(t) +
                       " is not supported (use candump -L or -ta)");
  }
  bool negative = false;
  if (!t.empty() && t[0] == '-') {
    negative = true;
    t.remove_prefix(1);
  }
  const std::size_t dot = t.find('.');
  const std::string_view whole = t.substr(0, dot);
  const std::string_view frac =
      dot == std::string_view::npos ? std::string_view{} : t.substr(dot + 1);
  if (whole.empty() || whole.size() > 12 || frac.size() > 9 ||
      (dot != std::string_view::npos && frac.empty())) {
    return parse_error("bad timestamp " + quoted(t));
  }
  std::int64_t seconds = 0;
  for (char c : whole) {
    if (c < '0' || c > '9') return parse_error("bad timestamp " + quoted(t));
    seconds = seconds * 10 + (c - '0');
  }
  // Timestamps stay within +-2^62 ns (146 years) so that the difference of any two, which
  // odometry and rate statistics take, cannot overflow int64.
  if (seconds >= (std::int64_t{1} << 62) / 1000000000LL) {
    return parse_error("timestamp " + quoted(t) + " out of range");
  }
  std::int64_t nanos = 0;
  for (std::size_t i = 0; i < 9; ++i) {
    int digit = 0;
    if (i < frac.size()) {
      if (frac[i] < '0' || frac[i] > '9') return parse_error("bad timestamp " + quoted(t));
      digit = frac[i] - '0';
    }
    nanos = nanos * 10 + digit;
  }
  const std::int64_t total = seconds * 1000000000LL + nanos;
  return Timestamp{negative ? -total : total};
}

// A CAN identifier as candump prints it: 3 hex digits for a standard frame, 8 for an extended
// or error frame. Fills the frame's id / is_error; `*extended` tells an extended (29-bit) ID,
// which the caller rejects once the rest of the line proved well-formed.
Status parse_id(std::string_view s, CanFrame* frame, bool* extended) {
  if (s.empty()) return parse_error("missing CAN ID");
  if (s.size() != 3 && s.size() != 8) {
    return parse_error("bad CAN ID " + quoted(s) + " (expected 3 or 8 hex digits)");
  }
  std::uint32_t id = 0;
  for (char c : s) {
    const int v = hex_value(c);
    if (v < 0) return parse_error("bad hex digit in CAN ID " + quoted(s));
    id = id << 4 | static_cast<std::uint32_t>(v);
  }
  if (s.size() == 3) {
    if (id > kCanSffMax) return parse_error("standard CAN ID " + quoted(s) + " exceeds 0x7FF");
    frame->id = id;
    return ok_status();
  }
  if (id & kCanErrFlag) {
    frame->id = id & kCanEffMask;
    frame->is_error = true;
    return ok_status();
  }
  frame->id = id & kCanEffMask;
  *extended = true;
  return ok_status();
}

// A well-formed frame of another device on the bus: kUnknownId, not a parse error.
Error extended_id_error(std::uint32_t id) {
  return Error{Errc::kUnknownId,
               "extended ID " + text::hex(id & kCanEffMask, 8) + " is not a RANGER frame"};
}

// "0096000000000000" (optionally dot-separated, as cansend accepts) -> data/dlc.
Status parse_log_data(std::string_view s, CanFrame* frame) {
  if (!s.empty() && (s[0] == 'R' || s[0] == 'r')) {
    return parse_error("remote (RTR) frame: RANGER uses none");
  }
  if (!s.empty() && s[0] == '#') return parse_error("CAN FD frame: RANGER uses classic CAN only");
  if (s.find('_') != std::string_view::npos) {
    return parse_error("DLC above 8 (len8_dlc suffix) is not supported");
  }
  std::size_t n = 0;
  std::size_t i = 0;
  while (i < s.size()) {
    if (s[i] == '.') {
      ++i;
      continue;
    }
    const int hi = hex_value(s[i]);
    if (hi < 0) return parse_error("bad hex digit in data " + quoted(s));
    if (i + 1 >= s.size() || s[i + 1] == '.') {
      return parse_error("odd number of hex digits in data " + quoted(s));
    }
    const int lo = hex_value(s[i + 1]);
    if (lo < 0) return parse_error("bad hex digit in data " + quoted(s));
    if (n == CanFrame::kMaxDlc) return parse_error("more than 8 data bytes in " + quoted(s));
    frame->data[n++] = static_cast<std::uint8_t>(hi << 4 | lo);
    i += 2;
  }
  frame->dlc = static_cast<std::uint8_t>(n);
  return ok_status();
}

// "[8]  00 96 00 00 00 00 00 00" (default format) -> data/dlc; `rest` is what follows the ID.
Status parse_default_data(Scanner& sc, CanFrame* frame) {
  const std::string_view len = sc.token();
  if (len.size() < 3 || len.front() != '[' || len.back() != ']') {
    return parse_error("expected data length like '[8]' after the ID, found " + quoted(len));
  }
  const std::string_view digits = len.substr(1, len.size() - 2);
  if (digits.size() == 2) return parse_error("CAN FD frame " + quoted(len) + ": not supported");
  if (digits.size() != 1 || digits[0] < '0' || digits[0] > '8') {
    return parse_error("bad data length " + quoted(len) + " (expected [0]..[8])");
  }
  const int dlc = digits[0] - '0';
  if (sc.peek() == 'r') {
    const std::string_view rest = sc.rest();
    if (rest.rfind("remote request", 0) == 0) {
      return parse_error("remote (RTR) frame: RANGER uses none");
    }
  }
  for (int i = 0; i < dlc; ++i) {
    const std::string_view byte = sc.token();
    if (byte.empty()) {
      return parse_error("data length says " + std::to_string(dlc) + " bytes, found " +
                         std::to_string(i));
    }
    if (byte.size() != 2 || hex_value(byte[0]) < 0 || hex_value(byte[1]) < 0) {
      return parse_error("bad hex byte " + quoted(byte) + " in data");
    }
    frame->data[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(hex_value(byte[0]) << 4 | hex_value(byte[1]));
  }
  frame->dlc = static_cast<std::uint8_t>(dlc);
  // candump may append the ASCII rendering ('...', option -a) or ERRORFRAME details.
  const std::string_view rest = sc.rest();
  if (!rest.empty() && rest[0] != '\'' && rest.rfind("ERRORFRAME", 0) != 0) {
    return parse_error("unexpected text after the data: " + quoted(rest));
  }
  return ok_status();
}

}  // namespace

Result<LogEntry> parse_candump_line(std::string_view line) {
  Scanner sc(line);
  if (sc.at_end()) return parse_error("empty line");
  LogEntry entry;

  if (sc.peek() == '(') {
    // Read up to ')' rather than a token: candump -tA's date timestamps contain a space.
    std::string_view inside;
    sc.until('(', &inside);
    if (!sc.until(')', &inside)) return parse_error("timestamp '(' without ')'");
    auto stamp = parse_timestamp(inside);
    if (!stamp) return stamp.error();
    entry.frame.stamp = *stamp;
    entry.has_timestamp = true;
  }

  const std::string_view iface = sc.token();
  if (iface.empty()) return parse_error("missing interface name");
  if (iface.size() > kMaxIfaceLength || iface.find('#') != std::string_view::npos) {
    return parse_error("bad interface name " + quoted(iface));
  }
  entry.iface.assign(iface.data(), iface.size());

  std::string_view frame_text = sc.token();
  if (frame_text == "TX" || frame_text == "RX") {  // candump -x: direction and two flag columns
    sc.token();
    sc.token();
    frame_text = sc.token();
  }
  if (frame_text.empty()) return parse_error("missing CAN frame after interface " + quoted(iface));

  bool extended = false;
  const std::size_t hash = frame_text.find('#');
  if (hash != std::string_view::npos) {  // log format: ID#DATA
    Status id = parse_id(frame_text.substr(0, hash), &entry.frame, &extended);
    if (!id) return id.error();
    Status data = parse_log_data(frame_text.substr(hash + 1), &entry.frame);
    if (!data) return data.error();
    const std::string_view flag = sc.token();  // newer candump -L may add a direction flag
    if (!flag.empty() && flag != "T" && flag != "R") {
      return parse_error("unexpected text after the frame: " + quoted(flag));
    }
    if (!sc.at_end()) return parse_error("unexpected text after the frame: " + quoted(sc.rest()));
  } else {  // default format: ID [n] bytes...
    Status id = parse_id(frame_text, &entry.frame, &extended);
    if (!id) return id.error();
    Status data = parse_default_data(sc, &entry.frame);
    if (!data) return data.error();
  }
  if (extended) return extended_id_error(entry.frame.id);
  return entry;
}

std::string format_candump_line(const CanFrame& frame, std::string_view iface) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::int64_t ns = frame.stamp.count();
  const std::int64_t mag = ns < 0 ? -ns : ns;
  char head[64];
  // Microseconds truncate towards zero; a stamp in (-1 us, 0) prints as 0.000000, not -0.000000.
  std::snprintf(head, sizeof head, "(%s%lld.%06lld) ", ns <= -1000 ? "-" : "",
                static_cast<long long>(mag / 1000000000),
                static_cast<long long>(mag % 1000000000 / 1000));
  std::string out = head;
  out.append(iface.data(), iface.size());
  char id[16];
  if (frame.is_error) {
    std::snprintf(id, sizeof id, " %08X#", (frame.id & kCanEffMask) | kCanErrFlag);
  } else if (frame.id > kCanSffMax) {
    std::snprintf(id, sizeof id, " %08X#", frame.id & kCanEffMask);
  } else {
    std::snprintf(id, sizeof id, " %03X#", frame.id);
  }
  out += id;
  const std::size_t n = frame.dlc < CanFrame::kMaxDlc ? frame.dlc : CanFrame::kMaxDlc;
  for (std::size_t i = 0; i < n; ++i) {
    out += kHex[frame.data[i] >> 4];
    out += kHex[frame.data[i] & 0x0F];
  }
  return out;
}

}  // namespace ranger
