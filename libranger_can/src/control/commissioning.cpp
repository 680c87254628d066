#include "ranger_can/control/commissioning.hpp"

#include <fstream>
#include <sstream>

namespace ranger {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

}  // namespace

Result<ProtocolProfile> parse_commissioning_text(std::string_view text, std::string_view origin) {
  ProtocolProfile profile = manual_profile();
  std::vector<std::string> seen;
  bool any_setting = false;
  std::size_t line_no = 0;
  auto error = [&](const std::string& what) {
    return Error{Errc::kParseError,
                 std::string(origin) + ": line " + std::to_string(line_no) + ": " + what};
  };
  while (!text.empty()) {
    ++line_no;
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    line = trim(line);
    if (line.empty()) continue;
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || colon == 0) {
      return error("'" + std::string(line) + "' is not `setting: value`");
    }
    const std::string key(trim(line.substr(0, colon)));
    const std::string value(trim(line.substr(colon + 1)));
    for (const std::string& k : seen) {
      if (k == key) return error("'" + key + "' is given twice");
    }
    seen.push_back(key);
    if (key == "protocol") {
      if (any_setting) return error("'protocol' must come before the settings");
      Result<ProtocolProfile> preset = protocol_preset(value);
      if (!preset) return error(preset.error().message);
      profile = *preset;
      continue;
    }
    any_setting = true;
    if (Status st = set_setting(profile, key, value); !st) return error(st.error().message);
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
