// Vehicle models: the RANGER and the RANGER MINI V1/V2/V3, each a preset of geometry, limits and
// protocol profile.
//
// Each model is one flat YAML file, libranger_can/models/<model>.yaml, embedded into the library
// at build time (CMake writes the files into a generated source), so model_preset() needs no file
// at run time; ranger_description's generate_urdf.py builds the model's URDF from the same file.
// The subset of YAML a model file may use ("flat"): one `key: value` per line, `#` comments,
// blank lines; a value is a number, a word, or a `[...]` list (kept as text). Keys:
//   model, display_name                         the model's name (= the file name) and its label
//   wheelbase, track, wheel_radius              VehicleGeometry (m)
//   max_linear_speed, max_speed_at_large_steering, max_ackermann_steering,
//   max_oblique_steering, max_spin_wheel_speed  KinematicsLimits (m/s, rad)
//   protocol                                    a revision preset (protocol_revision_names())
//   <setting>                                   any profile_settings() name: the model's own
//                                               reading, applied after the preset, in file order
//   description/...                             the URDF's (body, masses, sensors): ignored here
// Every key but `display_name`, the settings and description/* is required; an unknown key, a
// duplicate, a bad number or value is an error naming the line and the key.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

struct ModelPreset {
  std::string name;          // "ranger_mini_v2" (the file's name without .yaml)
  std::string display_name;  // "RANGER MINI V2"
  VehicleGeometry geometry;
  KinematicsLimits limits;
  std::string protocol = "manual";  // the revision preset the profile starts from
  // The model's own settings on top of the preset (NAME, VALUE), in file order.
  std::vector<std::pair<std::string, std::string>> settings;
  ProtocolProfile profile;  // protocol_preset(protocol) + settings
};

// The names of the embedded models, sorted: ranger, ranger_mini_v1, ranger_mini_v2, ranger_mini_v3.
const std::vector<std::string>& model_names();
// The embedded preset of `name`; kInvalidArgument listing the valid names for an unknown one.
Result<ModelPreset> model_preset(std::string_view name);
// The embedded file of `name`, as it was at build time (for tests and tools).
Result<std::string_view> model_file_text(std::string_view name);

// Parses one model file. `origin` names it in errors ("ranger_mini_v2.yaml: line 12: ...").
// The preset is validated (geometry, limits, profile).
Result<ModelPreset> parse_model(std::string_view text, std::string_view origin);

// The model's profile on another revision: protocol_preset(revision) + the model's own settings
// (the `--protocol` of a command that also has `--model`). kInvalidArgument for an unknown
// revision (listing the valid ones).
Result<ProtocolProfile> model_profile(const ModelPreset& model, std::string_view revision);

}  // namespace ranger
