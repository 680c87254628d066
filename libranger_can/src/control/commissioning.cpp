#include "ranger_can/control/commissioning.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "ranger_can/text.hpp"

namespace ranger {

Result<ProtocolProfile> parse_commissioning_text(std::string_view text, std::string_view origin) {
  ProtocolProfile profile = manual_profile();
  std::vector<std::string_view> seen;
  bool any_setting = false;
  for (const text::KeyValueLine& l : text::key_value_lines(text)) {
    auto error = [&](const std::string& what) {
      return Error{Errc::kParseError,
                   std::string(origin) + ": line " + std::to_string(l.line) + ": " + what};
    };
    if (!l.colon || l.key.empty()) {
      return error("'" + std::string(l.text) + "' is not `setting: value`");
    }
    if (std::find(seen.begin(), seen.end(), l.key) != seen.end()) {
      return error("'" + std::string(l.key) + "' is given twice");
    }
    seen.push_back(l.key);
    if (l.key == "protocol") {
      if (any_setting) return error("'protocol' must come before the settings");
      Result<ProtocolProfile> preset = protocol_preset(l.value);
      if (!preset) return error(preset.error().message);
      profile = *preset;
      continue;
    }
    any_setting = true;
    if (Status st = set_setting(profile, l.key, l.value); !st) return error(st.error().message);
  }
  if (Status st = profile.validate(); !st) {
    return Error{Errc::kParseError, std::string(origin) + ": " + st.error().message};
  }
  return profile;
}

Result<ProtocolProfile> load_commissioning_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Error{Errc::kIoError, "cannot read the commissioning file '" + path + "'"};
  std::ostringstream text;
  text << in.rdbuf();
  return parse_commissioning_text(text.str(), path);
}

std::string format_commissioning_file(const ProtocolProfile& profile,
                                      const std::vector<CommissionedSetting>& settings,
                                      const std::vector<std::string>& header) {
  std::string out;
  for (const std::string& h : header)
    out += "# " + h + "\n";
  out += "protocol: " + profile.revision + "\n";
  for (const ProfileSetting& s : profile_settings()) {
    const CommissionedSetting* found = nullptr;
    for (const CommissionedSetting& c : settings) {
      if (c.name == s.name) found = &c;
    }
    const std::string value = found ? found->value : [&] {
      auto v = get_setting(profile, s.name);
      return v ? *v : std::string("?");
    }();
    out += "\n# " + std::string(found && found->decided ? "decided: " : "not decided (kept): ") +
           (found ? found->evidence : std::string("no evidence gathered")) + "\n";
    out += std::string(s.name) + ": " + value + "\n";
  }
  return out;
}

}  // namespace ranger
