// `ranger_can decode [FILE] [--json]`: candump logs in, one decoded line per frame out. Reading
// (bounded lines, numbered errors, read errors reported) is cli_input's.
#include <optional>
#include <ostream>
#include <string>

#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "cli_input.hpp"
#include "cli_options.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger::cli {

namespace {

int decode_stream(std::istream& in, bool json, Io io) {
  std::string out;
  const CandumpReadSummary summary = read_candump(in, "decode", io.err, [&](const LogEntry& e) {
    out.clear();
    if (json) {
      append_frame_json(out, e.frame, e.iface);
    } else {
      append_frame_text(out, e.frame, e.iface);
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
  return with_input(args.get("FILE"), "decode", io,
                    [&](std::istream& in) { return decode_stream(in, json, io); });
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
      "  t (s, 0 if the line had none), iface, id (integer), name, dlc, data (hex), then the\n"
      "  message's fields in SI units with the manual's signs (steering: rad, positive = right;\n"
      "  speeds: m/s; voltage V; current A; temperature degC; soc/soh %), or `error` for a frame\n"
      "  with a bad DLC, an unknown ID (name \"unknown\") or an error frame.\n"
      "\n"
      "Malformed lines are reported on stderr as 'line N: reason' (the first 20, then a count)\n"
      "and skipped; blank lines are ignored; frames with extended (29-bit) IDs belong to other\n"
      "devices on the bus: they are counted, not decoded.",
      {optional_arg("FILE", "the candump log; standard input when absent or '-'", any_text())},
      {flag("--json", "one JSON object per line")},
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
