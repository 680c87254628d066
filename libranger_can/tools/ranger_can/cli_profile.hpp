// The protocol profile on the command line: one place for the options every sub-command that
// speaks the RANGER protocol takes, and for turning them into a ranger::ProtocolProfile.
//
//   --protocol manual|agx_v2   the revision's preset (default manual)
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

#include <vector>

#include "cli_options.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger::cli {

OptionSpec protocol_option();               // --protocol REVISION
OptionSpec set_option();                    // --set NAME=VALUE, repeatable
std::vector<OptionSpec> profile_options();  // both, in that order

// The preset --protocol names (manual when absent), then every --set in order. The parser has
// already checked each value against the same rules, so an error here is unexpected; it names the
// option and lists the valid values all the same.
Result<ProtocolProfile> profile_from_args(const ParsedArgs& args);

}  // namespace ranger::cli
