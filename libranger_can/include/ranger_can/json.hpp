// Minimal JSON output: the ranger_can sub-commands' JSON lines (decode, odom, monitor, sim's pose)
// and the scenario runner's samples.
//
// Appends to a std::string so that a line is built without per-value stream overhead and written
// in one go. Output is always valid JSON whatever the input: control and non-ASCII bytes in
// strings are escaped as \u00XX (so even binary garbage from a log file stays valid), and a NaN or
// infinite double is written as null, never as `nan`/`inf`. Commas are placed automatically:
//   w.begin_object().key("id").integer(0x221).key("speeds").begin_array().number(0.1)...
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/types.hpp"

namespace ranger {

class JsonWriter {
 public:
  explicit JsonWriter(std::string& out) : out_(out) {}

  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(std::string_view name);

  // Shortest text that reads back as v, always with a fraction or exponent ("0.0", "0.15",
  // "1e+20"); null if v is not finite.
  JsonWriter& number(double v);
  // `v` with exactly `decimals` digits after the point ("%.*f"); a value that prints as zero
  // prints without a sign ("0.000", never "-0.000"); null if v is not finite.
  JsonWriter& fixed(double v, int decimals);
  JsonWriter& integer(std::int64_t v);
  JsonWriter& unsigned_integer(std::uint64_t v);
  JsonWriter& boolean(bool v);
  JsonWriter& string(std::string_view v);
  JsonWriter& null();
  JsonWriter& string_or_null(const std::optional<std::string>& v);
  JsonWriter& strings(const std::vector<std::string>& v);  // an array of strings
  JsonWriter& raw(std::string_view json);                  // a value already written as JSON
  JsonWriter& seconds(Timestamp t);  // a timestamp as seconds with exactly 6 decimals

 private:
  void before_value();
  std::string& out_;
  bool need_comma_ = false;
};

// Free helpers, usable without a writer.
void append_json_number(std::string& out, double v);
void append_json_fixed(std::string& out, double v, int decimals);
void append_json_string(std::string& out, std::string_view v);
// Seconds with 6 decimals from a nanosecond timestamp, computed in integers so that a 10-digit
// epoch keeps its microseconds exactly ("1700000000.123456"); negative stamps keep their sign.
void append_seconds(std::string& out, Timestamp t);

}  // namespace ranger
