#include "ranger_can/text.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "ranger_can/types.hpp"

namespace ranger::text {

namespace {
constexpr std::string_view kBlanks = " \t\r\n\v\f";

bool is_blank(char c) {
  return kBlanks.find(c) != std::string_view::npos;
}
}  // namespace

std::string alternatives(const std::vector<std::string_view>& items,
                         std::string_view last_separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? last_separator : std::string_view(", ");
    out += items[i];
  }
  return out;
}

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(kBlanks);
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(kBlanks) - first + 1);
}

std::vector<std::string> split_words(std::string_view text) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_blank(text[i]))
      ++i;
    std::size_t j = i;
    while (j < text.size() && !is_blank(text[j]))
      ++j;
    if (j > i) words.emplace_back(text.substr(i, j - i));
    i = j;
  }
  return words;
}

std::vector<std::string> split(std::string_view text, char separator) {
  std::vector<std::string> pieces;
  std::size_t start = 0;
  while (start < text.size()) {
    const auto end = std::min(text.find(separator, start), text.size());
    pieces.emplace_back(text.substr(start, end - start));
    start = end + 1;
  }
  return pieces;
}

std::vector<KeyValueLine> key_value_lines(std::string_view text) {
  std::vector<KeyValueLine> lines;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t nl = std::min(text.find('\n', pos), text.size());
    std::string_view raw = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    raw = raw.substr(0, raw.find('#'));
    KeyValueLine l;
    l.line = line_no;
    l.text = trim(raw);
    if (l.text.empty()) continue;
    l.indented = is_blank(raw.front()) || raw.front() == '-';
    const auto colon = l.text.find(':');
    l.colon = colon != std::string_view::npos;
    if (l.colon) {
      l.key = trim(l.text.substr(0, colon));
      l.value = trim(l.text.substr(colon + 1));
    }
    lines.push_back(l);
  }
  return lines;
}

std::string format(const char* format, ...) {
  char buf[256];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  if (n < 0) return {};
  if (static_cast<std::size_t>(n) < sizeof buf)
    return std::string(buf, static_cast<std::size_t>(n));
  std::string out(static_cast<std::size_t>(n) + 1, '\0');
  va_start(args, format);
  std::vsnprintf(out.data(), out.size(), format, args);
  va_end(args);
  out.resize(static_cast<std::size_t>(n));
  return out;
}

std::string number_text(double v) {
  return format("%g", v);
}

std::string fixed(double v, int decimals) {
  return format("%.*f", decimals, v);
}

std::string degrees(double rad) {
  return fixed(rad_to_deg(rad), 2) + " deg";
}

std::string duration_text(std::chrono::nanoseconds d) {
  return fixed(seconds(d), 2) + " s";
}

std::string hex(std::uint32_t value, int width) {
  return format("0x%0*X", width, static_cast<unsigned>(value));
}

std::string json_escape(std::string_view value) {
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
