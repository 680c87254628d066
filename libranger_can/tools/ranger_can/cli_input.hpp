// Reading a candump log for the sub-commands that take one (decode, odom): the input named on
// the command line, and a line loop that survives anything.
//
// Robust by construction: lines are read with a length bound (a file without newlines cannot
// exhaust memory), every line goes through the bounds-checked candump parser, and a bad line is
// reported on stderr with its number ("ranger_can decode: line 7: bad hex digit in data") while
// reading goes on -- the first kMaxReportedLines of them; the rest are counted, so no input makes
// the tool print without bound. A frame with an extended (29-bit) identifier is another device's
// on a shared bus: counted as foreign, not an error. A read error (e.g. a directory, or a failing
// device) ends the loop and is reported, never thrown.
#pragma once

#include <cstddef>
#include <functional>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "cli_commands.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger::cli {

// Longer than any line candump writes (about 100 characters with -x and -a).
inline constexpr std::size_t kMaxCandumpLineLength = 4096;
// Bad lines reported one by one; the rest are counted in the closing summary.
inline constexpr std::size_t kMaxReportedLines = 20;

struct CandumpReadSummary {
  std::size_t lines = 0;      // lines read, blank and malformed ones included
  std::size_t frames = 0;     // well-formed lines handed to on_entry
  std::size_t malformed = 0;  // skipped; the first kMaxReportedLines reported
  std::size_t foreign = 0;    // well-formed frames with extended IDs (not RANGER's), skipped
  bool read_error = false;    // the stream failed before its end
};

// Parses `in` line by line to its end and calls `on_entry` for each well-formed line with a
// RANGER (standard 11-bit) or error frame; blank lines are ignored; frames with extended IDs are
// counted as foreign; malformed and over-long lines are reported on `err` as "ranger_can
// <command>: line N: reason" (the first kMaxReportedLines) and skipped.
CandumpReadSummary read_candump(std::istream& in, std::string_view command, std::ostream& err,
                                const std::function<void(const LogEntry&)>& on_entry);

// Reports the end of a read on `err` (how many lines were skipped and how many of them were not
// shown; the foreign frames; a read error). Returns false after a read error (exit status 1).
bool report_candump_end(const CandumpReadSummary& summary, std::string_view command,
                        std::ostream& err);

// Calls `read` with the input a command line names: standard input (io.in) when `path` is absent
// or "-", otherwise the file. A directory or a file that cannot be opened is reported on io.err
// ("ranger_can <command>: cannot open 'PATH': reason") and gives exit status 1.
// The one-line reason why a read without a single frame (summary.frames == 0) gave the command
// nothing to work on: "the input is empty", "no RANGER frames in 12 line(s) (10 malformed, 2 with
// extended IDs (other devices))".
std::string describe_no_frames(const CandumpReadSummary& summary);

int with_input(const std::optional<std::string>& path, std::string_view command, Io io,
               const std::function<int(std::istream&)>& read);

}  // namespace ranger::cli
