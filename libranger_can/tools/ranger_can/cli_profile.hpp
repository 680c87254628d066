// The protocol profile on the command line: one place for the options every sub-command that
// speaks the RANGER protocol takes, and for turning them into a ranger::ProtocolProfile.
//
//   --model NAME               a vehicle model (control/model.hpp): its geometry, limits and
//                              protocol profile (a revision preset and the model's own settings)
//   --protocol manual|agx_v2   the revision's preset (default: the model's, else manual); with
//                              --model, the model's own settings still apply on top of it
//   --set NAME=VALUE           one interpretation changed after the preset (repeatable, applied in
//                              order; NAME and VALUE as in docs/PROTOCOL_INTERPRETATIONS.md)
//
// An unknown revision, setting or value is a usage error (exit 2) whose message lists the valid
// values. A sub-command adds both options with one entry in its table and reads the profile with
// one call:
//   spec.options: {..., protocol_option(), set_option()}     (or append profile_options())
//   run:          const Result<ProtocolProfile> profile = profile_from_args(args);
//                 if (!profile) return usage_error(spec, io, profile.error().message);
#pragma once

#include <optional>
#include <vector>

#include "cli_options.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::cli {

OptionSpec protocol_option();               // --protocol REVISION
OptionSpec set_option();                    // --set NAME=VALUE, repeatable
std::vector<OptionSpec> profile_options();  // both, in that order

OptionSpec model_option();                  // --model NAME
std::vector<OptionSpec> vehicle_options();  // --model, --protocol, --set

// The preset --protocol names (manual when absent), then every --set in order. The parser has
// already checked each value against the same rules, so an error here is unexpected; it names the
// option and lists the valid values all the same. When the command also declares --model, the
// model's profile is the start (vehicle_from_args).
Result<ProtocolProfile> profile_from_args(const ParsedArgs& args);

// What --model, --protocol and --set make of a vehicle: the model's geometry and limits (the
// library's defaults, a RANGER, without --model) and the profile: the model's (or manual), its
// revision replaced by --protocol (the model's own settings kept), then every --set.
struct Vehicle {
  std::optional<ModelPreset> model;
  VehicleGeometry geometry;
  KinematicsLimits limits;
  ProtocolProfile profile;
};
Result<Vehicle> vehicle_from_args(const ParsedArgs& args);

}  // namespace ranger::cli
