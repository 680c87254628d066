#include "ranger_can/json.hpp"

#include "ranger_can/text.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace ranger {

void append_json_number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  out.append(buf, res.ptr);
  // Keep doubles recognisable as such ("0.0", not "0"): JSON readers that type numbers (Python,
  // jq's tonumber round trips) then see a float for every physical quantity.
  bool has_fraction_or_exponent = false;
  for (const char* p = buf; p != res.ptr; ++p) {
    if (*p == '.' || *p == 'e') has_fraction_or_exponent = true;
  }
  if (!has_fraction_or_exponent) out += ".0";
}

void append_json_fixed(std::string& out, double v, int decimals) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  std::string s = text::fixed(v, decimals);
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // -0.000
  out += s;
}

void append_json_string(std::string& out, std::string_view v) {
  out += '"';
  out += text::json_escape(v);
  out += '"';
}

void append_seconds(std::string& out, Timestamp t) {
  const long long ns = t.count();
  const unsigned long long mag =
      ns < 0 ? 0ULL - static_cast<unsigned long long>(ns) : static_cast<unsigned long long>(ns);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%s%llu.%06llu", ns < 0 ? "-" : "", mag / 1000000000ULL,
                mag % 1000000000ULL / 1000ULL);
  out += buf;
}

void JsonWriter::before_value() {
  if (need_comma_) out_ += ',';
  need_comma_ = true;
}

JsonWriter& JsonWriter::begin_object() {
  before_value();
  out_ += '{';
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::end_object() {
  out_ += '}';
  need_comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::begin_array() {
  before_value();
  out_ += '[';
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::end_array() {
  out_ += ']';
  need_comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::key(std::string_view name) {
  before_value();
  append_json_string(out_, name);
  out_ += ':';
  need_comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::number(double v) {
  before_value();
  append_json_number(out_, v);
  return *this;
}

JsonWriter& JsonWriter::fixed(double v, int decimals) {
  before_value();
  append_json_fixed(out_, v, decimals);
  return *this;
}

JsonWriter& JsonWriter::integer(std::int64_t v) {
  before_value();
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::unsigned_integer(std::uint64_t v) {
  before_value();
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::boolean(bool v) {
  before_value();
  out_ += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::string(std::string_view v) {
  before_value();
  append_json_string(out_, v);
  return *this;
}

JsonWriter& JsonWriter::null() {
  before_value();
  out_ += "null";
  return *this;
}

JsonWriter& JsonWriter::string_or_null(const std::optional<std::string>& v) {
  return v ? string(*v) : null();
}

JsonWriter& JsonWriter::strings(const std::vector<std::string>& v) {
  begin_array();
  for (const std::string& s : v)
    string(s);
  return end_array();
}

JsonWriter& JsonWriter::raw(std::string_view json) {
  before_value();
  out_ += json;
  return *this;
}

JsonWriter& JsonWriter::seconds(Timestamp t) {
  before_value();
  append_seconds(out_, t);
  return *this;
}

}  // namespace ranger
