#include "cli_profile.hpp"

#include <algorithm>
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

OptionSpec model_option() {
  std::string names;
  for (const std::string& n : model_names())
    names += (names.empty() ? "" : ", ") + n;
  return option("--model", "MODEL",
                "the vehicle, one of " + names +
                    ": its geometry, limits and protocol profile (libranger_can/models/; "
                    "--protocol and --set change the profile after it)",
                one_of(model_names()));
}

std::vector<OptionSpec> vehicle_options() {
  return {model_option(), protocol_option(), set_option()};
}

Result<Vehicle> vehicle_from_args(const ParsedArgs& args) {
  const auto& options = args.spec().options;
  const bool has_model_option = std::any_of(
      options.begin(), options.end(), [](const OptionSpec& o) { return o.name == "--model"; });
  Vehicle v;
  if (has_model_option && args.has("--model")) {
    auto model = model_preset(*args.get("--model"));
    if (!model) return Error{model.error().code, "--model: " + model.error().message};
    v.model = *model;
    v.geometry = model->geometry;
    v.limits = model->limits;
  }
  Result<ProtocolProfile> profile =
      v.model ? model_profile(*v.model, args.get_or("--protocol", v.model->protocol))
              : protocol_preset(args.get_or("--protocol", "manual"));
  if (!profile) return Error{profile.error().code, "--protocol: " + profile.error().message};
  for (const std::string& assignment : args.all("--set")) {
    if (Status st = apply_setting(*profile, assignment); !st) {
      return Error{st.error().code, "--set: " + st.error().message};
    }
  }
  v.profile = *profile;
  return v;
}

Result<ProtocolProfile> profile_from_args(const ParsedArgs& args) {
  auto v = vehicle_from_args(args);
  if (!v) return v.error();
  return v->profile;
}

}  // namespace ranger::cli
