// `ranger_can decode [FILE] [--json] [--protocol REV] [--set NAME=VALUE]...`: candump logs in, one
// decoded line per frame out, under a protocol profile (cli_profile). Reading (bounded lines,
// numbered errors, read errors reported) is cli_input's.
#include <iterator>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>

#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "cli_input.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger::cli {

namespace {

int decode_stream(std::istream& in, bool json, const ProtocolProfile& profile, Io io) {
  std::string out;
  const CandumpReadSummary summary = read_candump(in, "decode", io.err, [&](const LogEntry& e) {
    out.clear();
    if (json) {
      append_frame_json(out, e.frame, e.iface, profile);
    } else {
      append_frame_text(out, e.frame, e.iface, profile);
    }
    out += '\n';
    io.out << out;
  });
  io.out.flush();
  if (!report_candump_end(summary, "decode", io.err)) return 1;
  if (summary.frames == 0) {
    io.err << "ranger_can decode: nothing to decode: " << describe_no_frames(summary) << "\n";
    return 1;
  }
  return 0;
}

int decode_main(const ParsedArgs& args, Io io) {
  const bool json = args.has("--json");
  if (protocol_is_auto(args)) {
    // Two passes: the whole log identifies the settings, then every frame is decoded under them.
    return with_input(args.get("FILE"), "decode", io, [&](std::istream& in) {
      std::string text;
      if (!slurp(in, text)) {
        io.err << "ranger_can decode: read error\n";
        return 1;
      }
      const Result<ProtocolProfile> profile = profile_for_frames(args, frames_of_text(text));
      if (!profile) return usage_error(decode_command(), io, profile.error().message);
      std::istringstream again(text);
      return decode_stream(again, json, *profile, io);
    });
  }
  const Result<ProtocolProfile> profile = profile_from_args(args);
  if (!profile) return usage_error(decode_command(), io, profile.error().message);
  return with_input(args.get("FILE"), "decode", io,
                    [&](std::istream& in) { return decode_stream(in, json, *profile, io); });
}

}  // namespace

const CommandSpec& decode_command() {
  static const CommandSpec spec{
      "decode",
      "decode a candump log (file or stdin), text or --json",
      "Decodes a candump log of RANGER CAN traffic. Accepts candump's log format (candump -L:\n"
      "'(1700000000.123456) can0 221#0096000000000000') and its default format, with or without\n"
      "timestamps ('can0  221   [8]  00 96 00 ...').\n"
      "\n"
      "Prints one line per frame: human-readable text, or with --json one JSON object per line:\n"
      "  t (s, 0 if the line had none), iface, id (integer), name, dlc, data (hex), extra_bytes\n"
      "  (only for a frame longer than its layout: those bytes were ignored), then the message's\n"
      "  fields in SI units with the manual's signs (steering: rad, positive = right; speeds:\n"
      "  m/s; voltage V; current A; temperature degC; soc/soh %), or `error` for a frame shorter\n"
      "  than its layout, an unknown ID (name \"unknown\"), content impossible under the protocol\n"
      "  profile (a steering angle beyond 100 deg) or an error frame.\n"
      "\n"
      "Frames are read under a protocol profile: --protocol picks the revision (units, signs,\n"
      "the error-word layout, mode numbering), --set changes one interpretation of it. With\n"
      "--protocol auto (the default) the whole log is read first and identifies it: the IDs only\n"
      "the vendor's revision sends, frame lengths, the 0x211 byte-7 counter, the BMS voltage\n"
      "scale, and whether the rolling wheels form one rigid-body motion under a 0x271 reading\n"
      "(`ranger_can identify replay:FILE` prints that decision with its evidence).\n"
      "\n"
      "Malformed lines are reported on stderr as 'line N: reason' (the first 20, then a count)\n"
      "and skipped; blank lines are ignored; frames with extended (29-bit) IDs belong to other\n"
      "devices on the bus: they are counted, not decoded.",
      {optional_arg("FILE", "the candump log; standard input when absent or '-'", any_text())},
      {flag("--json", "one JSON object per line"), protocol_option(), set_option()},
      "Exit status: 0 when the input held at least one frame to decode; 1 when it held none\n"
      "(empty, only malformed lines or only other devices' frames: the reason is on stderr) or\n"
      "could not be opened or read; 2 on a usage error.",
      decode_main,
  };
  return spec;
}

int run_decode(const Args& args, Io io) {
  return run_command(decode_command(), args, io);
}

}  // namespace ranger::cli
