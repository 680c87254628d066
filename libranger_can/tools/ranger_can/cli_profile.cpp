#include "cli_profile.hpp"

#include <string>

namespace ranger::cli {

namespace {

// "  steering_unit_111 = centideg|millirad" lines for the help of --set.
std::string settings_help() {
  std::string out =
      "change one interpretation of the protocol after the preset (repeatable, applied in "
      "order); NAME=VALUE, one of:";
  for (const ProfileSetting& s : profile_settings()) {
    out += "\n" + std::string(s.name) + "=";
    for (std::size_t i = 0; i < s.values.size(); ++i)
      out += (i ? "|" : "") + std::string(s.values[i]);
  }
  return out;
}

Status check_assignment(const std::string& text) {
  ProtocolProfile scratch;  // which values are valid does not depend on the preset
  return apply_setting(scratch, text);
}

}  // namespace

OptionSpec protocol_option() {
  std::string names;
  for (const std::string& n : protocol_revision_names())
    names += (names.empty() ? "" : "|") + n;
  return option("--protocol", names,
                "the protocol revision the chassis speaks: manual (the user manual, the default) "
                "or agx_v2 (the vendor's current software); docs/PROTOCOL_INTERPRETATIONS.md lists "
                "what each one sets",
                one_of(protocol_revision_names()));
}

OptionSpec set_option() {
  return option("--set", "NAME=VALUE", settings_help(), checked_by(check_assignment)).repeated();
}

std::vector<OptionSpec> profile_options() {
  return {protocol_option(), set_option()};
}

Result<ProtocolProfile> profile_from_args(const ParsedArgs& args) {
  Result<ProtocolProfile> profile = protocol_preset(args.get_or("--protocol", "manual"));
  if (!profile) return Error{profile.error().code, "--protocol: " + profile.error().message};
  for (const std::string& assignment : args.all("--set")) {
    if (Status st = apply_setting(*profile, assignment); !st) {
      return Error{st.error().code, "--set: " + st.error().message};
    }
  }
  return profile;
}

}  // namespace ranger::cli
