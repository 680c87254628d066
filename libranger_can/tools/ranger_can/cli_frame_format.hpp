// How the ranger_can tool shows a RANGER frame: one JSON object or one human-readable line.
// `decode` prints these for every log line; `monitor` and others may reuse them.
//
// JSON line contract: every line has `t` (s; 0 when the log line had no timestamp),
// `iface`, `id` (integer), `name` (protocol::frame_name), `dlc`, `data` (hex), `extra_bytes` when
// the frame is longer than its layout (those bytes are ignored); then the decoded
// message's fields in SI units and the manual's signs (rad, m/s, V, A, degC, %), or `error` for a
// frame that did not decode (short DLC, unknown ID, impossible content, error frame). Frames are
// decoded under a protocol profile (cli_profile.hpp: --protocol, --set), which also names the
// error bits (the profile's error-word layout).
#pragma once

#include <string>
#include <string_view>

#include "ranger_can/json.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger::cli {

// Appends one complete line (no newline) for `frame` seen on `iface`, decoded under `profile`.
void append_frame_json(std::string& out, const CanFrame& frame, std::string_view iface,
                       const ProtocolProfile& profile = manual_profile());
void append_frame_text(std::string& out, const CanFrame& frame, std::string_view iface,
                       const ProtocolProfile& profile = manual_profile());

// The decoded message alone: its fields as keys of an already open JSON object, or as text.
// `profile` names what depends on it (error bits, mode wire values).
void write_message_json(JsonWriter& w, const Message& message,
                        const ProtocolProfile& profile = manual_profile());
void append_message_text(std::string& out, const Message& message,
                         const ProtocolProfile& profile = manual_profile());

}  // namespace ranger::cli
