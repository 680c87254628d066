#include "cli_profile.hpp"

#include <algorithm>
#include <sstream>
#include <string>

#include "ranger_can/wire/candump_log.hpp"

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

std::vector<std::string> protocol_choices() {
  std::vector<std::string> choices = {"auto"};
  for (const std::string& n : protocol_revision_names())
    choices.push_back(n);
  return choices;
}

OptionSpec protocol_option(bool with_auto) {
  const std::vector<std::string> choices =
      with_auto ? protocol_choices() : protocol_revision_names();
  std::string names;
  for (const std::string& n : choices)
    names += (names.empty() ? "" : "|") + n;
  return option("--protocol", names,
                with_auto
                    ? "the protocol revision the chassis speaks: auto (the default) identifies "
                      "it from the chassis's own frames (a log's frames when reading one); "
                      "manual (the user manual), agx_v2 (the vendor's current software) or "
                      "mini_v3 (the RANGER MINI 3.0's manual) force a preset; "
                      "docs/PROTOCOL_INTERPRETATIONS.md lists what each one sets and how auto "
                      "decides"
                    : "the protocol revision: manual (the user manual), agx_v2 (the vendor's "
                      "current software) or mini_v3 (the RANGER MINI 3.0's manual); default: "
                      "the model's, else manual; docs/PROTOCOL_INTERPRETATIONS.md lists what "
                      "each one sets",
                one_of(choices));
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

std::vector<OptionSpec> vehicle_options(bool with_auto) {
  return {model_option(), protocol_option(with_auto), set_option()};
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
  std::string revision = args.get_or("--protocol", "auto");
  if (revision == "auto") revision = v.model ? v.model->protocol : "manual";
  Result<ProtocolProfile> profile =
      v.model ? model_profile(*v.model, revision) : protocol_preset(revision);
  if (!profile) return Error{profile.error().code, "--protocol: " + profile.error().message};
  if (Status st = apply_set_options(*profile, args); !st) return st.error();
  v.profile = *profile;
  return v;
}

void apply_vehicle(const Vehicle& vehicle, DriverConfig& config) {
  if (vehicle.model) {
    config.controller.geometry = vehicle.geometry;
    config.controller.limits = vehicle.limits;
    config.odometry.geometry = vehicle.geometry;
  }
  config.controller.profile = vehicle.profile;
}

bool protocol_is_auto(const ParsedArgs& args) {
  return args.get_or("--protocol", "auto") == "auto";
}

std::optional<std::string> protocol_revision(const ParsedArgs& args) {
  if (protocol_is_auto(args)) return std::nullopt;
  return args.get_or("--protocol", "manual");
}

Status apply_set_options(ProtocolProfile& profile, const ParsedArgs& args) {
  for (const std::string& assignment : args.all("--set")) {
    if (Status st = apply_setting(profile, assignment); !st) {
      return Error{st.error().code, "--set: " + st.error().message};
    }
  }
  return ok_status();
}

bool slurp(std::istream& in, std::string& text) {
  try {
    std::string line;
    while (std::getline(in, line)) {
      text += line;
      text += '\n';
    }
    return !in.bad();
  } catch (...) {  // a filebuf may throw on a read error (e.g. EISDIR)
    return false;
  }
}

std::vector<CanFrame> frames_of_text(const std::string& text) {
  std::vector<CanFrame> frames;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (auto e = parse_candump_line(line)) frames.push_back(e->frame);
  }
  return frames;
}

Result<ProtocolProfile> profile_for_frames(const ParsedArgs& args,
                                           const std::vector<CanFrame>& frames,
                                           const VehicleGeometry& geometry,
                                           IdentificationStatus* status) {
  if (!protocol_is_auto(args)) return profile_from_args(args);
  IdentificationStatus id = identify_log(frames, geometry);
  ProtocolProfile profile = id.profile;  // the preset it reached, even when nothing was decided
  if (Status st = apply_set_options(profile, args); !st) return st.error();
  if (status) *status = std::move(id);
  return profile;
}

Result<ProtocolProfile> profile_from_args(const ParsedArgs& args) {
  auto v = vehicle_from_args(args);
  if (!v) return v.error();
  return v->profile;
}

}  // namespace ranger::cli
