// candump's text formats: both layouts, their variants, and whatever else a log file may hold.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>

#include "ranger_can/wire/candump_log.hpp"

namespace ranger {
namespace {

LogEntry parse_ok(std::string_view line) {
  auto r = parse_candump_line(line);
  EXPECT_TRUE(r.ok()) << "'" << line << "': " << (r.ok() ? "" : r.error().message);
  return r.ok() ? *r : LogEntry{};
}

std::string parse_error(std::string_view line) {
  auto r = parse_candump_line(line);
  EXPECT_FALSE(r.ok()) << "'" << line << "' was accepted";
  if (r.ok()) return "";
  EXPECT_EQ(r.error().code, Errc::kParseError);
  return r.error().message;
}

TEST(CandumpLog, LogFormat) {
  const LogEntry e = parse_ok("(1700000000.123456) can0 221#0096000000000000");
  EXPECT_TRUE(e.has_timestamp);
  EXPECT_EQ(e.frame.stamp.count(), 1700000000123456000LL);
  EXPECT_EQ(e.iface, "can0");
  EXPECT_EQ(e.frame.id, 0x221u);
  EXPECT_EQ(e.frame.dlc, 8);
  EXPECT_EQ(e.frame.data[1], 0x96);
  EXPECT_FALSE(e.frame.is_error);
}

TEST(CandumpLog, LogFormatShortAndEmptyPayloads) {
  const LogEntry one = parse_ok("(0.000001) vcan1 421#01");
  EXPECT_EQ(one.frame.stamp.count(), 1000);
  EXPECT_EQ(one.frame.dlc, 1);
  EXPECT_EQ(one.frame.data[0], 0x01);
  for (std::size_t i = 1; i < 8; ++i)
    EXPECT_EQ(one.frame.data[i], 0);
  const LogEntry none = parse_ok("(1.5) can0 7FF#");
  EXPECT_EQ(none.frame.dlc, 0);
  EXPECT_EQ(none.frame.stamp.count(), 1500000000);
  EXPECT_EQ(parse_ok("(1.0) can0 291#0a0B").frame.data[1], 0x0B);  // either hex case
  EXPECT_EQ(parse_ok("(1.0) can0 291#00.01").frame.dlc, 2);        // cansend-style dots
  EXPECT_EQ(parse_ok("(1.0) can0 291#0001 R").frame.dlc, 2);       // direction flag
  EXPECT_EQ(parse_ok("(1.0) can0 291#0001\r").frame.dlc, 2);       // CRLF files
}

TEST(CandumpLog, DefaultFormatWithAndWithoutTimestamp) {
  const LogEntry plain = parse_ok("  can0  221   [8]  00 96 00 00 00 00 03 E8");
  EXPECT_FALSE(plain.has_timestamp);
  EXPECT_EQ(plain.frame.stamp.count(), 0);
  EXPECT_EQ(plain.iface, "can0");
  EXPECT_EQ(plain.frame.id, 0x221u);
  EXPECT_EQ(plain.frame.dlc, 8);
  EXPECT_EQ(plain.frame.data[7], 0xE8);

  const LogEntry stamped = parse_ok("(1700000000.000100)  can0  291   [2]  01 00");
  EXPECT_TRUE(stamped.has_timestamp);
  EXPECT_EQ(stamped.frame.stamp.count(), 1700000000000100000LL);
  EXPECT_EQ(stamped.frame.dlc, 2);

  const LogEntry ascii = parse_ok("  can0  111   [2]  41 42                     'AB'");
  EXPECT_EQ(ascii.frame.dlc, 2);
  const LogEntry x = parse_ok(" (1.000000)  can0  TX - -  111   [1]  05");
  EXPECT_EQ(x.frame.id, 0x111u);
  EXPECT_EQ(x.frame.data[0], 0x05);
  EXPECT_EQ(parse_ok("can0 141 [0]").frame.dlc, 0);
}

TEST(CandumpLog, ErrorFrames) {
  const LogEntry e = parse_ok("(1.0) can0 20000004#0004000000000000");
  EXPECT_TRUE(e.frame.is_error);
  EXPECT_EQ(e.frame.id, 0x4u);
  const LogEntry d = parse_ok("  can0  20000080   [8]  00 00 00 00 00 00 00 00   ERRORFRAME");
  EXPECT_TRUE(d.frame.is_error);
}

TEST(CandumpLog, ExtendedIdsAreForeignFramesNotParseErrors) {
  for (const char* line : {"(1.0) can0 1ABCDEF0#00", "  can0  1ABCDEF0   [1]  00"}) {
    const auto r = parse_candump_line(line);
    ASSERT_FALSE(r.ok()) << line;
    EXPECT_EQ(r.error().code, Errc::kUnknownId) << line;
    EXPECT_EQ(r.error().message, "extended ID 0x1ABCDEF0 is not a RANGER frame");
  }
  // A malformed line stays malformed, whatever its ID.
  EXPECT_NE(parse_error("(1.0) can0 1ABCDEF0#0G").find("bad hex digit"), std::string::npos);
}

TEST(CandumpLog, RejectsWhatRangerNeverSends) {
  EXPECT_NE(parse_error("(1.0) can0 111#R").find("RTR"), std::string::npos);
  EXPECT_NE(parse_error("  can0  111   [8]  remote request").find("RTR"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 111##1001122").find("FD"), std::string::npos);
  EXPECT_NE(parse_error("  can0  111  [08]  00 11 22 33 44 55 66 77").find("FD"),
            std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 111#00_9").find("len8_dlc"), std::string::npos);
}

TEST(CandumpLog, ClearMessagesForBrokenLines) {
  EXPECT_EQ(parse_error(""), "empty line");
  EXPECT_EQ(parse_error("   \t "), "empty line");
  EXPECT_NE(parse_error("(1.0) can0 221#00960000000000000000").find("more than 8 data bytes"),
            std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 221#0G").find("bad hex digit in data"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 221#009").find("odd number of hex digits"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 2X1#00").find("bad hex digit in CAN ID"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 2211#00").find("3 or 8 hex digits"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 800#00").find("exceeds 0x7FF"), std::string::npos);
  EXPECT_NE(parse_error("(1.0 can0 221#00").find("without ')'"), std::string::npos);
  EXPECT_NE(parse_error("(abc) can0 221#00").find("bad timestamp"), std::string::npos);
  EXPECT_NE(parse_error("(2023-11-14 22:13:20.123456) can0 221#00").find("not supported"),
            std::string::npos);
  EXPECT_NE(parse_error("(1.0)").find("missing interface"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0").find("missing CAN frame"), std::string::npos);
  EXPECT_NE(parse_error("(1.0) can0 221#00 trailing").find("unexpected text"), std::string::npos);
  EXPECT_NE(parse_error("  can0  221   [3]  00 11").find("found 2"), std::string::npos);
  EXPECT_NE(parse_error("  can0  221   [9]  00").find("bad data length"), std::string::npos);
  EXPECT_NE(parse_error("  can0  221   8  00").find("expected data length"), std::string::npos);
  EXPECT_NE(parse_error("  can0  221   [1]  0x").find("bad hex byte"), std::string::npos);
  EXPECT_NE(parse_error("  can0  221   [1]  00 extra").find("unexpected text"), std::string::npos);
  EXPECT_NE(parse_error("averyveryverylongifacename 221#00").find("bad interface name"),
            std::string::npos);
}

TEST(CandumpLog, GarbageNeverCrashesAndAlwaysExplains) {
  std::mt19937 rng(11);
  const std::string alphabet = "()#[]. 0123456789abcdefABCDEFRTXcan\t\r'-_:";
  for (int i = 0; i < 20000; ++i) {
    std::string line;
    const int len = static_cast<int>(rng() % 64);
    for (int j = 0; j < len; ++j) {
      line += (rng() % 4 == 0) ? static_cast<char>(rng() % 256) : alphabet[rng() % alphabet.size()];
    }
    const auto r = parse_candump_line(line);
    if (r.ok()) {
      EXPECT_LE(r->frame.dlc, 8);
      EXPECT_FALSE(r->iface.empty());
    } else {
      EXPECT_EQ(r.error().code, Errc::kParseError);
      EXPECT_FALSE(r.error().message.empty());
      for (char c : r.error().message)
        EXPECT_TRUE(c >= 0x20 && c < 0x7F) << r.error().message;
    }
  }
}

TEST(CandumpLog, FormatThenParseRoundTrips) {
  CanFrame f;
  f.id = 0x36A;
  f.dlc = 4;
  f.data = {0x82, 0x01, 0x18, 0x00, 0, 0, 0, 0};
  f.stamp = Timestamp{1700000000123456000LL};
  const std::string line = format_candump_line(f, "can0");
  EXPECT_EQ(line, "(1700000000.123456) can0 36A#82011800");
  const LogEntry e = parse_ok(line);
  EXPECT_EQ(e.frame, f);
  EXPECT_EQ(e.frame.stamp, f.stamp);
  EXPECT_EQ(e.iface, "can0");

  CanFrame empty;
  empty.id = 0x5;
  EXPECT_EQ(format_candump_line(empty, "vcan0"), "(0.000000) vcan0 005#");
  CanFrame err;
  err.is_error = true;
  err.id = 0x4;
  err.dlc = 8;
  EXPECT_EQ(format_candump_line(err, "can0"), "(0.000000) can0 20000004#0000000000000000");
  EXPECT_EQ(parse_ok(format_candump_line(err, "can0")).frame, err);
}

TEST(CandumpLog, BundledLogsParseAndFormatBackLineByLine) {
  // The logs of both revisions (padded to 8 and unpadded) and the original sample.
  for (const char* name :
       {"sample.log", "sample_padded.log", "sample_agx_v2.log", "sample_agx_v2_unpadded.log"}) {
    std::ifstream in(std::string(RANGER_DATA_DIR) + "/" + name);
    ASSERT_TRUE(in.good()) << name;
    std::size_t lines = 0, eight = 0;
    for (std::string line; std::getline(in, line);) {
      ++lines;
      const LogEntry e = parse_ok(line);
      EXPECT_TRUE(e.has_timestamp) << name << ": " << line;
      EXPECT_EQ(format_candump_line(e.frame, e.iface), line) << name;
      eight += e.frame.dlc == 8;
    }
    EXPECT_GT(lines, 100u) << name;
    if (std::string(name) == "sample_padded.log" || std::string(name) == "sample_agx_v2.log") {
      EXPECT_EQ(eight, lines) << name << ": every frame padded to 8";
    }
  }
}

}  // namespace
}  // namespace ranger
