#include "cli_input.hpp"

#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace ranger::cli {

namespace {

enum class LineRead { kLine, kTooLong, kEnd };

// Reads one line into `line` (without its newline), bounded by kMaxCandumpLineLength; an
// over-long line is consumed to its end and reported as kTooLong.
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
    if (line.size() < kMaxCandumpLineLength) {
      line += static_cast<char>(c);
    } else {
      too_long = true;
    }
  }
  return too_long ? LineRead::kTooLong : LineRead::kLine;
}

bool is_blank(const std::string& s) {
  return s.find_first_not_of(" \t\r") == std::string::npos;
}

}  // namespace

CandumpReadSummary read_candump(std::istream& in, std::string_view command, std::ostream& err,
                                const std::function<void(const LogEntry&)>& on_entry) {
  CandumpReadSummary summary;
  std::string line;
  auto malformed = [&](const std::string& reason) {
    if (++summary.malformed <= kMaxReportedLines) {
      err << "ranger_can " << command << ": line " << summary.lines << ": " << reason << "\n";
    }
  };
  for (;;) {
    const LineRead r = read_line(in, line);
    if (r == LineRead::kEnd) break;
    ++summary.lines;
    if (r == LineRead::kTooLong) {
      malformed("longer than " + std::to_string(kMaxCandumpLineLength) + " characters, skipped");
      continue;
    }
    if (is_blank(line)) continue;
    const Result<LogEntry> entry = parse_candump_line(line);
    if (!entry) {
      if (entry.error().code == Errc::kUnknownId) {
        ++summary.foreign;  // another device's frame (extended ID): not an error
      } else {
        malformed(entry.error().message);
      }
      continue;
    }
    ++summary.frames;
    on_entry(*entry);
  }
  summary.read_error = in.bad();
  return summary;
}

bool report_candump_end(const CandumpReadSummary& summary, std::string_view command,
                        std::ostream& err) {
  if (summary.malformed > kMaxReportedLines) {
    err << "ranger_can " << command << ": " << summary.malformed
        << " malformed line(s) skipped (the first " << kMaxReportedLines << " shown)\n";
  } else if (summary.malformed > 0) {
    err << "ranger_can " << command << ": " << summary.malformed << " malformed line(s) skipped\n";
  }
  if (summary.foreign > 0) {
    err << "ranger_can " << command << ": " << summary.foreign
        << " frame(s) with extended (29-bit) IDs skipped: other devices' frames, not RANGER's\n";
  }
  if (summary.read_error) {
    err << "ranger_can " << command << ": read error after line " << summary.lines << "\n";
    return false;
  }
  return true;
}

std::string describe_no_frames(const CandumpReadSummary& summary) {
  if (summary.read_error) return "the input could not be read";
  if (summary.lines == 0) return "the input is empty";
  std::string what = "no RANGER frames in " + std::to_string(summary.lines) + " line(s)";
  std::string parts;
  if (summary.malformed > 0) parts += std::to_string(summary.malformed) + " malformed";
  if (summary.foreign > 0) {
    parts += (parts.empty() ? "" : ", ") + std::to_string(summary.foreign) +
             " with extended IDs (other devices)";
  }
  if (parts.empty()) parts = "all blank";
  return what + " (" + parts + ")";
}

int with_input(const std::optional<std::string>& path, std::string_view command, Io io,
               const std::function<int(std::istream&)>& read) {
  if (!path || *path == "-") return read(io.in);
  std::error_code ec;
  if (std::filesystem::is_directory(*path, ec)) {
    io.err << "ranger_can " << command << ": cannot read '" << *path << "': is a directory\n";
    return 1;
  }
  std::ifstream file(*path, std::ios::binary);
  if (!file) {
    io.err << "ranger_can " << command << ": cannot open '" << *path
           << "': " << std::strerror(errno) << "\n";
    return 1;
  }
  return read(file);
}

}  // namespace ranger::cli
