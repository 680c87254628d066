// The protocol profile on the command line: one place for the options every sub-command that
// speaks the RANGER protocol takes, and for turning them into a ranger::ProtocolProfile.
//
//   --model NAME               a vehicle model (control/model.hpp): its geometry, limits and
//                              protocol profile (a revision preset and the model's own settings)
//   --protocol auto|manual|agx_v2   auto (the default): identified from the chassis's frames
//                              (control/identification.hpp: a log's frames for decode and odom,
//                              the live chassis for identify and commission); or a revision's
//                              preset (with --model, the model's own settings still apply on top)
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

#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::cli {

// --protocol; `with_auto` = false for the commands that set the chassis's own protocol (sim) or
// send without listening (send): there is nothing to identify from.
OptionSpec protocol_option(bool with_auto = true);               // --protocol REVISION
OptionSpec set_option();                                         // --set NAME=VALUE, repeatable
std::vector<OptionSpec> profile_options();                       // both, in that order
OptionSpec model_option();                                       // --model NAME
std::vector<OptionSpec> vehicle_options(bool with_auto = true);  // --model, --protocol, --set

// What --model, --protocol and --set make of a vehicle: the model's geometry and limits (the
// library's defaults, a RANGER, without --model) and the profile: the model's (or manual), its
// revision replaced by a forced --protocol (the model's own settings kept), then every --set.
// With --protocol auto this profile is the fallback an identification starts from.
struct Vehicle {
  std::optional<ModelPreset> model;
  VehicleGeometry geometry;
  KinematicsLimits limits;
  ProtocolProfile profile;
};
Result<Vehicle> vehicle_from_args(const ParsedArgs& args);
// The driver's vehicle: the model's geometry and limits (with --model; the config's own without)
// and the profile (with auto, the fallback the identification starts from).
void apply_vehicle(const Vehicle& vehicle, DriverConfig& config);

// vehicle_from_args(...).profile: the preset --protocol names (the model's, or manual, for auto
// or when absent: the fallback), then every --set in order. The parser has already checked each
// value against the same rules, so an error here is unexpected; it names the option and lists the
// valid values all the same.
Result<ProtocolProfile> profile_from_args(const ParsedArgs& args);

// Whether --protocol is auto (given or by default).
bool protocol_is_auto(const ParsedArgs& args);
// The preset --protocol names; nullopt for auto.
std::optional<std::string> protocol_revision(const ParsedArgs& args);
// Every --set, in order, on `profile` (after an identification).
Status apply_set_options(ProtocolProfile& profile, const ParsedArgs& args);
// For a log: with auto, the identification of `frames` (identify_log) and then the --set values;
// otherwise profile_from_args. `status` (if not null) receives the identification.
Result<ProtocolProfile> profile_for_frames(const ParsedArgs& args,
                                           const std::vector<CanFrame>& frames,
                                           const VehicleGeometry& geometry = {},
                                           IdentificationStatus* status = nullptr);
// Reads the whole stream into `text`; false on a read error (an exception of the stream's buffer
// included).
bool slurp(std::istream& in, std::string& text);
// The frames of a candump text (malformed lines skipped: the command's own reader reports them).
std::vector<CanFrame> frames_of_text(const std::string& text);

}  // namespace ranger::cli
