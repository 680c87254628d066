// `ranger_can decode [FILE] [--json]`: candump logs in, one decoded line per frame out. Reading
// (bounded lines, numbered errors, read errors reported) is cli_input's.
#include <optional>
#include <ostream>
#include <string>

#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "cli_input.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger::cli {

namespace {

constexpr const char* kUsage =
    "usage: ranger_can decode [FILE|-] [--json]\n"
    "\n"
    "Decodes a candump log of RANGER CAN traffic: FILE, or standard input when FILE is absent or\n"
    "'-'. Accepts candump's log format (candump -L: '(1700000000.123456) can0 "
    "221#0096000000000000')\n"
    "and its default format, with or without timestamps ('can0  221   [8]  00 96 00 ...').\n"
    "\n"
    "Prints one line per frame: human-readable text, or with --json one JSON object per line:\n"
    "  t (s, 0 if the line had none), iface, id (integer), name, dlc, data (hex), then the\n"
    "  message's fields in SI units with the manual's signs (steering: rad, positive = right;\n"
    "  speeds: m/s; voltage V; current A; temperature degC; soc/soh %), or `error` for a frame\n"
    "  with a bad DLC, an unknown ID (name \"unknown\") or an error frame.\n"
    "\n"
    "Malformed lines are reported on stderr as 'line N: reason' and skipped; blank lines are\n"
    "ignored. Exit status: 0 when the input was read to its end, 1 if it could not be opened or\n"
    "read, 2 on a usage error.\n"
    "\n"
    "options:\n"
    "  --json      one JSON object per line\n"
    "  -h, --help  this text\n";

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
  return report_candump_end(summary, "decode", io.err) ? 0 : 1;
}

}  // namespace

int run_decode(const Args& args, Io io) {
  bool json = false;
  std::optional<std::string> path;
  for (const std::string& a : args) {
    if (a == "-h" || a == "--help") {
      io.out << kUsage;
      return 0;
    }
    if (a == "--json") {
      json = true;
    } else if (a.size() > 1 && a[0] == '-') {
      io.err << "ranger_can decode: unknown option '" << a << "'\n\n" << kUsage;
      return 2;
    } else if (path) {
      io.err << "ranger_can decode: more than one input file ('" << *path << "', '" << a << "')\n\n"
             << kUsage;
      return 2;
    } else {
      path = a;
    }
  }
  return with_input(path, "decode", io,
                    [&](std::istream& in) { return decode_stream(in, json, io); });
}

}  // namespace ranger::cli
