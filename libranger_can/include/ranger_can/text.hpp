// Names and text, once, for every layer and front end (the library, the tool, the node):
//  * enum names: one {value, name} table per enum gives its to_string, its parser and the list of
//    all its values (EnumNames below);
//  * words and lines: split, trim, the `key: value` lines of the flat YAML files (model presets,
//    commissioning files);
//  * numbers: "%g", fixed decimals, degrees, printf-style formatting;
//  * joining names, hexadecimal numbers, JSON string escaping (ranger_can/json.hpp writes JSON).
// Dependency-free; the templates are here, the rest in src/text.cpp.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ranger::text {

// ---- Enum names ---------------------------------------------------------------------------------

template <typename Enum>
struct EnumName {
  Enum value{};
  std::string_view name;  // snake_case, stable: logs, messages, JSON, CLI words, parameters
};

// An enum's names: every enumerator once, in the order lists and help texts show them.
//   inline constexpr auto kLinkStateNames = text::enum_names<LinkState>({
//       {LinkState::kNeverConnected, "never_connected"}, {LinkState::kConnected, "connected"}});
//   kLinkStateNames.name(s)          "connected" ("unknown" for a value the table lacks)
//   kLinkStateNames.parse("stale")   std::optional<LinkState>
//   kLinkStateNames.values()         every enumerator, in the table's order
//   kLinkStateNames.names()          every name, in the table's order
// A test checks that each table holds every enumerator of its enum (test_text.cpp).
template <typename Enum, std::size_t N>
class EnumNames {
 public:
  using Row = EnumName<Enum>;

  constexpr explicit EnumNames(const Row (&rows)[N]) {
    for (std::size_t i = 0; i < N; ++i)
      rows_[i] = rows[i];
  }

  constexpr std::string_view name(Enum value) const {
    for (const Row& r : rows_) {
      if (r.value == value) return r.name;
    }
    return "unknown";
  }
  constexpr std::optional<Enum> parse(std::string_view name) const {
    for (const Row& r : rows_) {
      if (r.name == name) return r.value;
    }
    return std::nullopt;
  }
  constexpr bool contains(Enum value) const {
    for (const Row& r : rows_) {
      if (r.value == value) return true;
    }
    return false;
  }
  constexpr std::array<Enum, N> values() const {
    std::array<Enum, N> out{};
    for (std::size_t i = 0; i < N; ++i)
      out[i] = rows_[i].value;
    return out;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    out.reserve(N);
    for (const Row& r : rows_)
      out.emplace_back(r.name);
    return out;
  }
  static constexpr std::size_t size() { return N; }
  constexpr const Row* begin() const { return rows_.data(); }
  constexpr const Row* end() const { return rows_.data() + N; }

 private:
  std::array<Row, N> rows_{};
};

// Builds an enum's table; the enum is named, the row count is counted:
//   text::enum_names<Direction>({{Direction::kToChassis, "to_chassis"}, ...})
template <typename Enum, std::size_t N>
constexpr EnumNames<Enum, N> enum_names(const EnumName<Enum> (&rows)[N]) {
  return EnumNames<Enum, N>(rows);
}

// ---- Lists of names -----------------------------------------------------------------------------

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

// The items, the last two joined by `last_separator`: "a, b or c".
std::string alternatives(const std::vector<std::string_view>& items,
                         std::string_view last_separator = " or ");

// ---- Words and lines ----------------------------------------------------------------------------

// `text` without the blanks (space, tab, CR, LF, VT, FF) at either end.
std::string_view trim(std::string_view text);
// The words of `text`: the runs of characters between blanks.
std::vector<std::string> split_words(std::string_view text);
// The pieces of `text` between the separators: split("a,b", ',') = {"a", "b"}; an empty text has
// none, and a separator at the end adds no empty piece.
std::vector<std::string> split(std::string_view text, char separator);

// One line of a flat YAML file (a model preset, a commissioning file): `key: value`, '#' starting
// a comment. key_value_lines() gives every line that is not blank once its comment is removed;
// each caller decides what it accepts (nesting, quotes, duplicates) and words its own errors.
struct KeyValueLine {
  std::size_t line = 0;    // 1-based
  std::string_view text;   // the line without its comment, trimmed
  bool colon = false;      // the line has a ':'
  std::string_view key;    // the trimmed text before the first ':' (empty without one)
  std::string_view value;  // the trimmed text after it
  bool indented = false;   // the line begins with a blank or '-' (a nested YAML item)
};
std::vector<KeyValueLine> key_value_lines(std::string_view text);

// ---- Numbers ------------------------------------------------------------------------------------

// printf-style formatting into a string: format("%6.2f deg", x).
std::string format(const char* format, ...) __attribute__((format(printf, 1, 2)));
// A number as help texts show defaults and ranges: "%g" ("0.89", "90", "1e-05").
std::string number_text(double v);
// `v` with `decimals` digits after the point ("%.*f"): fixed(0.125, 2) = "0.13" (or "0.12": the
// nearest double decides).
std::string fixed(double v, int decimals);
// An angle in radians as degrees with two decimals: degrees(M_PI / 4) = "45.00 deg".
std::string degrees(double rad);
// A duration in seconds with two decimals: duration_text(1250ms) = "1.25 s".
std::string duration_text(std::chrono::nanoseconds d);

// "0x" and `value` in upper-case hexadecimal, at least `width` digits: hex(0x211) = "0x211",
// hex(0x5, 2) = "0x05", hex(0x200, 8) = "0x00000200".
std::string hex(std::uint32_t value, int width = 3);

// `value` as the body of a JSON string (without the quotes): quote, backslash, \n, \r and \t
// escaped as such, every other control byte and every byte outside ASCII (which may be bad UTF-8)
// as \u00XX.
std::string json_escape(std::string_view value);

}  // namespace ranger::text
