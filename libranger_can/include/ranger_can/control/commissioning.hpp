// Commissioning files: the protocol settings `ranger_can commission IFACE --wheels-lifted` decided
// for one chassis, as a flat YAML file the node loads with one parameter (`commissioning_file`).
//
// Format (a subset of YAML: one `key: value` per line, `#` starts a comment, blank lines ignored):
//   protocol: agx_v2             the preset the settings start from (optional; default manual)
//   steering_unit_111: millirad  any setting of profile_settings(), in any order, at most once
// `protocol`, if present, comes before every setting. An unknown key, a duplicate, a bad value or
// a line that is not `key: value` is an error naming the file and the line ("FILE: line 7:
// protocol setting steering_unit_111 = 'mrad' is invalid (valid: centideg|millirad)").
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/result.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

// Parses the text of a commissioning file; `origin` names it in errors.
Result<ProtocolProfile> parse_commissioning_text(std::string_view text, std::string_view origin);
// Reads and parses `path` (kIoError naming the path when it cannot be read).
Result<ProtocolProfile> load_commissioning_file(const std::string& path);

// One setting as commissioning decided it.
struct CommissionedSetting {
  std::string name;      // "steering_unit_111"
  std::string value;     // "millirad"
  bool decided = false;  // false: kept at the preset's value (the comment says why)
  std::string evidence;  // one line
};
// The file's text: `header` lines as comments, `protocol: REVISION`, then every setting of
// profile_settings() in its order, each preceded by its evidence as a comment. `profile` gives
// the values of settings missing from `settings`.
std::string format_commissioning_file(const ProtocolProfile& profile,
                                      const std::vector<CommissionedSetting>& settings,
                                      const std::vector<std::string>& header);

}  // namespace ranger
