// `ranger_can decode [FILE] [--json]`: candump logs in, one decoded line per frame out.
//
// Robust by construction: lines are read with a length bound (a file without newlines cannot
// exhaust memory), every line goes through the bounds-checked candump parser, and a bad line is
// reported on stderr with its number while decoding goes on.
#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <istream>
#include <ostream>
#include <string>
#include <system_error>

#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "ranger_can/candump_log.hpp"

namespace ranger::cli {

namespace {

// Longer than any line candump writes (about 100 characters with -x and -a).
constexpr std::size_t kMaxLineLength = 4096;

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

enum class LineRead { kLine, kTooLong, kEnd };

// Reads one line into `line` (without its newline), bounded by kMaxLineLength; an over-long line
// is consumed to its end and reported as kTooLong.
LineRead read_line(std::istream& in, std::string& line) {
  line.clear();
  std::streambuf* buf = in.rdbuf();
  if (buf == nullptr) return LineRead::kEnd;
  bool any = false;
  bool too_long = false;
  for (;;) {
    int c;
    try {  // a filebuf throws on a read error (e.g. EISDIR); report it like istream would
      c = buf->sbumpc();
    } catch (const std::exception&) {
      in.setstate(std::ios::badbit);
      return LineRead::kEnd;
    }
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      if (!any) return LineRead::kEnd;
      break;
    }
    any = true;
    if (c == '\n') break;
    if (line.size() < kMaxLineLength) {
      line += static_cast<char>(c);
    } else {
      too_long = true;
    }
  }
  return too_long ? LineRead::kTooLong : LineRead::kLine;
}

bool is_blank(const std::string& s) {
  for (char c : s) {
    if (c != ' ' && c != '\t' && c != '\r') return false;
  }
  return true;
}

int decode_stream(std::istream& in, bool json, Io io) {
  std::string line;
  std::string out;
  std::size_t line_no = 0;
  std::size_t malformed = 0;
  for (;;) {
    const LineRead r = read_line(in, line);
    if (r == LineRead::kEnd) break;
    ++line_no;
    if (r == LineRead::kTooLong) {
      io.err << "ranger_can decode: line " << line_no << ": longer than " << kMaxLineLength
             << " characters, skipped\n";
      ++malformed;
      continue;
    }
    if (is_blank(line)) continue;
    const Result<LogEntry> entry = parse_candump_line(line);
    if (!entry) {
      io.err << "ranger_can decode: line " << line_no << ": " << entry.error().message << "\n";
      ++malformed;
      continue;
    }
    out.clear();
    if (json) {
      append_frame_json(out, entry->frame, entry->iface);
    } else {
      append_frame_text(out, entry->frame, entry->iface);
    }
    out += '\n';
    io.out << out;
  }
  io.out.flush();
  if (malformed > 0) {
    io.err << "ranger_can decode: " << malformed << " malformed line(s) skipped\n";
  }
  if (in.bad()) {
    io.err << "ranger_can decode: read error after line " << line_no << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int run_decode(const Args& args, Io io) {
  bool json = false;
  std::string path;
  bool have_path = false;
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
    } else if (have_path) {
      io.err << "ranger_can decode: more than one input file ('" << path << "', '" << a << "')\n\n"
             << kUsage;
      return 2;
    } else {
      path = a;
      have_path = true;
    }
  }

  if (!have_path || path == "-") return decode_stream(io.in, json, io);

  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    io.err << "ranger_can decode: cannot read '" << path << "': is a directory\n";
    return 1;
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    io.err << "ranger_can decode: cannot open '" << path << "': " << std::strerror(errno) << "\n";
    return 1;
  }
  return decode_stream(file, json, io);
}

}  // namespace ranger::cli
