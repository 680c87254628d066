// Small text helpers used at the edges (messages, logs, JSON): joining names, hexadecimal numbers,
// JSON string escaping. Header-only, dependency-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace ranger::text {

// The items (anything convertible to std::string_view) separated by `separator`.
template <typename Range>
std::string join(const Range& items, std::string_view separator = ", ") {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) out += separator;
    out += std::string_view(item);
    first = false;
  }
  return out;
}

// The names (to_string, found by argument-dependent lookup) of every enumerator of an enum's
// `all` list, in its order.
template <typename Enum, std::size_t N>
std::vector<std::string> names_of(const Enum (&all)[N]) {
  std::vector<std::string> out;
  out.reserve(N);
  for (const Enum e : all)
    out.emplace_back(to_string(e));
  return out;
}

// "0x" and `value` in upper-case hexadecimal, at least `width` digits: hex(0x211) = "0x211",
// hex(0x5, 2) = "0x05", hex(0x200, 8) = "0x00000200".
inline std::string hex(std::uint32_t value, int width = 3) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", width, static_cast<unsigned>(value));
  return buf;
}

// `value` as the body of a JSON string (without the quotes): quote, backslash, \n, \r and \t
// escaped as such, every other control byte and every byte outside ASCII (which may be bad UTF-8)
// as \u00XX.
inline std::string json_escape(std::string_view value) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(value.size());
  for (const char ch : value) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c >= 0x7F) {
          out += "\\u00";
          out += kHex[c >> 4];
          out += kHex[c & 0x0F];
        } else {
          out += ch;
        }
    }
  }
  return out;
}

}  // namespace ranger::text
