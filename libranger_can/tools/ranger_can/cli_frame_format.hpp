// How the ranger_can tool shows a RANGER frame: one JSON object or one human-readable line.
// `decode` prints these for every log line; `monitor` and others may reuse them.
//
// JSON line contract (issue 2): every line has `t` (s; 0 when the log line had no timestamp),
// `iface`, `id` (integer), `name` (protocol::frame_name), `dlc`, `data` (hex); then the decoded
// message's fields in SI units and the manual's signs (rad, m/s, V, A, degC, %), or `error` for a
// frame that did not decode (bad DLC, unknown ID, error frame).
#pragma once

#include <string>
#include <string_view>

#include "cli_json.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger::cli {

// Appends one complete line (no newline) for `frame` seen on `iface`.
void append_frame_json(std::string& out, const CanFrame& frame, std::string_view iface);
void append_frame_text(std::string& out, const CanFrame& frame, std::string_view iface);

// The decoded message alone: its fields as keys of an already open JSON object, or as text.
void write_message_json(JsonWriter& w, const Message& message);
void append_message_text(std::string& out, const Message& message);

}  // namespace ranger::cli
