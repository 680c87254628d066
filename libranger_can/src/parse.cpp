#include "ranger_can/parse.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace ranger {

namespace {
Error bad(std::string_view what, const std::string& text, const std::string& why) {
  return Error{Errc::kParseError, std::string(what) + ": '" + text + "' " + why};
}
}  // namespace

Result<double> parse_double(std::string_view what, const std::string& text) {
  if (text.empty()) return bad(what, text, "is not a number");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return bad(what, text, "is not a number");
  if (!std::isfinite(v) || errno == ERANGE) return bad(what, text, "is not a finite number");
  return v;
}

Result<double> parse_double_in(std::string_view what, const std::string& text, double min,
                               double max) {
  auto v = parse_double(what, text);
  if (!v) return v;
  if (*v < min || *v > max) {
    return bad(what, text, "is outside [" + number_text(min) + ", " + number_text(max) + "]");
  }
  return v;
}

Result<std::int64_t> parse_integer(std::string_view what, const std::string& text, std::int64_t min,
                                   std::int64_t max) {
  if (text.empty()) return bad(what, text, "is not an integer");
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 0);  // base 0: decimal or 0x...
  if (end != text.c_str() + text.size() || errno == ERANGE) {
    return bad(what, text, "is not an integer");
  }
  if (v < min || v > max) {
    return bad(what, text, "is outside [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return static_cast<std::int64_t>(v);
}

}  // namespace ranger
