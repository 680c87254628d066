// Strict parsing of numbers typed by people (command-line options, simulator control lines,
// scenario scripts): the whole text must be the number, it must be finite, and the error names
// what was being read and the offending text ("--soc: 'abc' is not a number").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

Result<double> parse_double(std::string_view what, const std::string& text);
// Like parse_double, and inside [min, max].
Result<double> parse_double_in(std::string_view what, const std::string& text, double min,
                               double max);
// Decimal or 0x-prefixed hexadecimal integer inside [min, max].
Result<std::int64_t> parse_integer(std::string_view what, const std::string& text, std::int64_t min,
                                   std::int64_t max);

// A number as help texts show defaults and ranges (text.hpp).
using text::number_text;

}  // namespace ranger
