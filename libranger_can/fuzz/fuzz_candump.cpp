// Fuzzes the candump text parser (both formats, every byte sequence a log file can hold) and the
// writer against it.
//
// Properties (each a FUZZ_CHECK):
//  * parse_candump_line never crashes; a rejection is kParseError (or kUnknownId for another
//    device's extended-ID frame) with a message;
//  * an accepted line yields a well-formed frame: DLC <= 8, zero bytes past the DLC, an 11-bit ID
//    (29-bit only for error frames), a plausible interface name, stamp 0 without a timestamp;
//  * writing the entry back (format_candump_line) and reading that line gives the same frame and
//    interface, and the timestamp to the microsecond the log format carries.
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_input.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace {

using ranger::CanFrame;

void check_well_formed(const ranger::LogEntry& e) {
  FUZZ_CHECK(e.frame.dlc <= CanFrame::kMaxDlc);
  for (std::size_t i = e.frame.dlc; i < CanFrame::kMaxDlc; ++i)
    FUZZ_CHECK(e.frame.data[i] == 0);
  FUZZ_CHECK(e.frame.id <= (e.frame.is_error ? 0x1FFFFFFFu : 0x7FFu));
  FUZZ_CHECK(!e.iface.empty() && e.iface.size() <= 15);
  for (char c : e.iface)
    FUZZ_CHECK(c != ' ' && c != '\t' && c != '\n' && c != '#');
  if (!e.has_timestamp) FUZZ_CHECK(e.frame.stamp.count() == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  const auto entry = ranger::parse_candump_line(line);
  if (!entry.ok()) {
    FUZZ_CHECK(entry.error().code == ranger::Errc::kParseError ||
               entry.error().code == ranger::Errc::kUnknownId);
    FUZZ_CHECK(!entry.error().message.empty());
    return 0;
  }
  check_well_formed(*entry);

  const std::string written = ranger::format_candump_line(entry->frame, entry->iface);
  const auto reread = ranger::parse_candump_line(written);
  if (!reread.ok()) {
    std::fprintf(stderr, "cannot re-read '%s': %s\n", written.c_str(),
                 reread.error().message.c_str());
  }
  FUZZ_CHECK(reread.ok());
  check_well_formed(*reread);
  FUZZ_CHECK(reread->frame == entry->frame);
  FUZZ_CHECK(reread->iface == entry->iface);
  FUZZ_CHECK(reread->has_timestamp);
  // The log format has microseconds: the writer truncates towards zero.
  const std::int64_t ns = entry->frame.stamp.count();
  FUZZ_CHECK(reread->frame.stamp.count() == ns / 1000 * 1000);
  // And what was written once is written identically again.
  FUZZ_CHECK(ranger::format_candump_line(reread->frame, reread->iface) == written);
  return 0;
}
