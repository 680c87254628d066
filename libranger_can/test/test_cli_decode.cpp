// `ranger_can decode`: golden output on the bundled sample log, the JSON contract, and garbage in
// (random bytes, huge lines, empty input) without a crash and with numbered errors on stderr;
// padded frames decode and say so.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cli_commands.hpp"
#include "cli_input.hpp"
#include "cli_json.hpp"
#include "support/cli_run.hpp"

namespace ranger::cli {
namespace {

const std::string kSampleLog = std::string(RANGER_DATA_DIR) + "/sample.log";
const std::string kGoldenJson = std::string(RANGER_SOURCE_DIR) + "/test/data/sample.decode.jsonl";
const std::string kGoldenText = std::string(RANGER_SOURCE_DIR) + "/test/data/sample.decode.txt";
// To refresh the goldens after a deliberate output change (then review the diff):
//   ranger_can decode libranger_can/data/sample.log --json >
//   libranger_can/test/data/sample.decode.jsonl ranger_can decode libranger_can/data/sample.log >
//   libranger_can/test/data/sample.decode.txt

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

using Outcome = test::CliOutcome;
using test::lines_of;

Outcome run(const Args& args, const std::string& input = "") {
  return test::run_cli(run_decode, args, input);
}

// A strict JSON (RFC 8259) recogniser: enough to prove every output line parses.
class JsonRecogniser {
 public:
  static bool valid(std::string_view s) {
    JsonRecogniser r{s};
    r.ws();
    if (!r.value()) return false;
    r.ws();
    return r.i_ == s.size();
  }

 private:
  explicit JsonRecogniser(std::string_view s) : s_(s) {}
  bool more() const { return i_ < s_.size(); }
  char c() const { return more() ? s_[i_] : '\0'; }
  void ws() {
    while (more() && (c() == ' ' || c() == '\t' || c() == '\n' || c() == '\r'))
      ++i_;
  }
  bool eat(char ch) {
    if (c() != ch) return false;
    ++i_;
    return true;
  }
  bool literal(std::string_view w) {
    if (s_.substr(i_, w.size()) != w) return false;
    i_ += w.size();
    return true;
  }
  bool digits() {
    const std::size_t start = i_;
    while (more() && c() >= '0' && c() <= '9')
      ++i_;
    return i_ > start;
  }
  bool number() {
    eat('-');
    if (eat('0')) {
    } else if (!digits()) {
      return false;
    }
    if (eat('.') && !digits()) return false;
    if (c() == 'e' || c() == 'E') {
      ++i_;
      if (!eat('+')) eat('-');
      if (!digits()) return false;
    }
    return true;
  }
  bool string() {
    if (!eat('"')) return false;
    while (more() && c() != '"') {
      const auto ch = static_cast<unsigned char>(c());
      if (ch < 0x20) return false;
      if (eat('\\')) {
        if (eat('u')) {
          for (int k = 0; k < 4; ++k, ++i_) {
            if (!std::isxdigit(static_cast<unsigned char>(c()))) return false;
          }
        } else if (std::string_view("\"\\/bfnrt").find(c()) == std::string_view::npos || !more()) {
          return false;
        } else {
          ++i_;
        }
      } else {
        ++i_;
      }
    }
    return eat('"');
  }
  bool value() {
    ws();
    switch (c()) {
      case '{': {
        ++i_;
        ws();
        if (eat('}')) return true;
        do {
          ws();
          if (!string()) return false;
          ws();
          if (!eat(':') || !value()) return false;
          ws();
        } while (eat(','));
        return eat('}');
      }
      case '[': {
        ++i_;
        ws();
        if (eat(']')) return true;
        do {
          if (!value()) return false;
          ws();
        } while (eat(','));
        return eat(']');
      }
      case '"':
        return string();
      case 't':
        return literal("true");
      case 'f':
        return literal("false");
      case 'n':
        return literal("null");
      default:
        return number();
    }
  }
  std::string_view s_;
  std::size_t i_ = 0;
};

void expect_all_valid_json(const std::string& out) {
  for (const auto& line : lines_of(out)) {
    EXPECT_TRUE(JsonRecogniser::valid(line)) << line;
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    EXPECT_EQ(line.find("inf"), std::string::npos) << line;
  }
}

// ---- Golden output ----------------------------------------------------------------------------

TEST(CliDecode, GoldenJsonOnTheSampleLog) {
  const Outcome r = run({kSampleLog, "--json"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, read_file(kGoldenJson));
  expect_all_valid_json(r.out);
}

TEST(CliDecode, GoldenTextOnTheSampleLog) {
  const Outcome r = run({kSampleLog});
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, read_file(kGoldenText));
}

TEST(CliDecode, StdinGivesTheSameOutput) {
  const std::string log = read_file(kSampleLog);
  EXPECT_EQ(run({"--json"}, log).out, read_file(kGoldenJson));
  EXPECT_EQ(run({"-"}, log).out, read_file(kGoldenText));
}

TEST(CliDecode, SampleLogShowsEveryPartOfTheContract) {
  const std::string out = run({kSampleLog, "--json"}).out;
  const auto has = [&](const std::string& s) { return out.find(s) != std::string::npos; };
  // One line per input frame.
  EXPECT_EQ(lines_of(out).size(), lines_of(read_file(kSampleLog)).size());
  EXPECT_TRUE(has(R"("t":1700000000.030050,"iface":"can0","id":273,"name":"motion_command")"));
  EXPECT_TRUE(has(R"("linear_speed":0.15,"yaw_rate":0.0,"spin_speed":0.0,)"
                  R"("steering_angle":0.17453292519943295)"));
  EXPECT_TRUE(has(R"("vehicle_status":0,"vehicle_status_name":"normal","control_mode":1)"));
  EXPECT_TRUE(
      has(R"("battery_voltage":51.2,"error_bits":512,"errors":["host_communication_lost"])"));
  EXPECT_TRUE(has(R"("name":"motion_feedback","dlc":8,"data":"00980000000003E8","speed":0.152,)"
                  R"("yaw_rate":0.0,"lateral_speed":0.0,"steering_angle":0.17453292519943295})"));
  EXPECT_TRUE(has(R"("name":"steering_angles")"));
  EXPECT_TRUE(has(R"("angles":[0.19320794819577225,-0.19320794819577225,)"));
  EXPECT_TRUE(has(R"("speeds":[0.136,0.136,0.168,0.168])"));
  EXPECT_TRUE(has(R"("name":"motion_mode","dlc":2,"data":"0000","mode":0,"mode_name":"ackermann",)"
                  R"("switching":false)"));
  EXPECT_TRUE(has(R"("battery":0,"soc":87.0,"soh":98.0,"voltage":51.2,"current":-2.4,)"
                  R"("temperature":25.3)"));
  EXPECT_TRUE(has(R"("id":1793,"name":"unknown","dlc":1,"data":"05","error":)"));
  EXPECT_TRUE(has(R"("name":"motion_feedback","dlc":4,"data":"00960000",)"
                  R"("error":"0x221 (motion_feedback): DLC 4, expected 8 or more")"));
  EXPECT_EQ(out.find("extra_bytes"), std::string::npos) << "no padded frame in the sample";
}

TEST(CliDecode, RealExecutableMatchesTheGolden) {
  const std::string cmd =
      std::string("'") + RANGER_CLI_PATH + "' decode --json '" + kSampleLog + "' 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;)
    out.append(buf, n);
  EXPECT_EQ(pclose(pipe), 0);
  EXPECT_EQ(out, read_file(kGoldenJson));
}

// ---- Bad input --------------------------------------------------------------------------------

TEST(CliDecode, MalformedLinesAreNumberedAndDecodingGoesOn) {
  const std::string input =
      "(1.000000) can0 111#0096000000000000\n"
      "this is not candump\n"
      "\n"
      "(1.020000) can0 221#00960000000000\n"  // 7 bytes: a parsed frame, too short
      "(1.040000) can0 221#0G\n"
      "  can0  291   [2]  00 01\n";
  const Outcome r = run({"--json"}, input);
  EXPECT_EQ(r.rc, 0);
  const auto out = lines_of(r.out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NE(out[0].find("\"motion_command\""), std::string::npos);
  EXPECT_NE(out[1].find("\"error\":\"0x221 (motion_feedback): DLC 7, expected 8 or more\""),
            std::string::npos);
  EXPECT_NE(out[2].find("\"t\":0.000000"), std::string::npos);  // no timestamp in that format
  EXPECT_NE(out[2].find("\"switching\":true"), std::string::npos);
  const auto err = lines_of(r.err);
  ASSERT_EQ(err.size(), 3u);
  EXPECT_EQ(err[0].rfind("ranger_can decode: line 2: ", 0), 0u) << err[0];
  EXPECT_EQ(err[1], "ranger_can decode: line 5: bad hex digit in data '0G'");
  EXPECT_EQ(err[2], "ranger_can decode: 2 malformed line(s) skipped");
}

TEST(CliDecode, InputWithoutFramesFailsWithOneLineReason) {
  struct Case {
    std::string input;
    std::string reason;
  };
  const Case cases[] = {
      {"", "ranger_can decode: nothing to decode: the input is empty"},
      {"\n\n  \n\r\n",
       "ranger_can decode: nothing to decode: no RANGER frames in 4 line(s) (all blank)"},
      {"(1.0) can0 1ABCDEF0#00\n",
       "ranger_can decode: nothing to decode: no RANGER frames in 1 line(s) (1 with extended IDs "
       "(other devices))"},
  };
  for (const auto& c : cases) {
    for (const Args& args : {Args{}, Args{"--json"}}) {
      const Outcome r = run(args, c.input);
      EXPECT_EQ(r.rc, 1);
      EXPECT_EQ(r.out, "");
      ASSERT_FALSE(lines_of(r.err).empty());
      EXPECT_EQ(lines_of(r.err).back(), c.reason);
    }
  }
  // Garbage only: the bad lines (at most 20), their count, and the reason.
  const Outcome garbage = run({}, "garbage\nmore garbage\n");
  EXPECT_EQ(garbage.rc, 1);
  EXPECT_EQ(garbage.out, "");
  EXPECT_EQ(lines_of(garbage.err).size(), 4u) << garbage.err;
  EXPECT_EQ(lines_of(garbage.err).back(),
            "ranger_can decode: nothing to decode: no RANGER frames in 2 line(s) (2 malformed)");
}

TEST(CliDecode, AtMostTwentyBadLinesAreReportedThenACount) {
  std::string input;
  for (int i = 0; i < 100000; ++i)
    input += "not a candump line\n";
  input += "(1.0) can0 45A#01\n";
  const Outcome r = run({"--json"}, input);
  EXPECT_EQ(r.rc, 0);  // one frame: the input held what decode needs
  EXPECT_EQ(lines_of(r.out).size(), 1u);
  const auto err = lines_of(r.err);
  ASSERT_EQ(err.size(), kMaxReportedLines + 1) << r.err.substr(0, 2000);
  EXPECT_EQ(kMaxReportedLines, 20u);
  EXPECT_EQ(err[0].rfind("ranger_can decode: line 1: ", 0), 0u) << err[0];
  EXPECT_EQ(err[19].rfind("ranger_can decode: line 20: ", 0), 0u) << err[19];
  EXPECT_EQ(err[20], "ranger_can decode: 100000 malformed line(s) skipped (the first 20 shown)");
}

TEST(CliDecode, ExtendedIdsAreForeignFramesNotErrors) {
  const Outcome r = run({"--json"},
                        "(1.000000) can0 18FF1234#0102\n"  // another device (J1939-like)
                        "(1.010000) can0 221#0096000000000000\n"
                        "  can0  1ABCDEF0   [2]  01 02\n");
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(lines_of(r.out).size(), 1u);
  EXPECT_NE(r.out.find("\"motion_feedback\""), std::string::npos);
  EXPECT_EQ(r.err,
            "ranger_can decode: 2 frame(s) with extended (29-bit) IDs skipped: other devices' "
            "frames, not RANGER's\n");
}

TEST(CliDecode, HugeLineIsSkippedWithoutBufferingIt) {
  std::string input(8 * 1024 * 1024, 'A');  // 8 MiB without a newline
  input += "\n(2.000000) can0 45A#01\n";
  input += std::string(5000, '(');  // a second over-long line, unterminated at end of input
  const Outcome r = run({"--json"}, input);
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(lines_of(r.out).size(), 1u);
  EXPECT_NE(r.out.find("\"enabled\":true"), std::string::npos);
  EXPECT_NE(r.err.find("line 1: longer than 4096 characters"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 3: longer than 4096 characters"), std::string::npos) << r.err;
}

TEST(CliDecode, RandomBytesNeverCrashAndOutputStaysValidJson) {
  std::mt19937 rng(99);
  const std::string valid = "(1.000000) can0 211#0001020000002001\n";
  for (int round = 0; round < 20; ++round) {
    std::string input;
    for (int i = 0; i < 20000; ++i) {
      const auto v = rng() % 300;
      input += v < 256 ? static_cast<char>(v) : (v < 290 ? valid[rng() % valid.size()] : '\n');
    }
    input += "\n" + valid;
    for (bool json : {true, false}) {
      const Outcome r = run(json ? Args{"--json"} : Args{}, input);
      EXPECT_EQ(r.rc, 0);
      EXPECT_FALSE(r.out.empty());  // at least the valid last line
      if (json) expect_all_valid_json(r.out);
      for (const auto& line : lines_of(r.err)) {
        EXPECT_EQ(line.rfind("ranger_can decode: ", 0), 0u) << line;
        for (char ch : line)
          EXPECT_TRUE(ch >= 0x20 && ch < 0x7F) << "raw byte on stderr";
      }
    }
  }
}

TEST(CliDecode, StrangeInterfaceNamesStayValidJson) {
  const Outcome r = run({"--json"}, "(1.0) a\"b\\\x01\xff 291#0000\n");
  EXPECT_EQ(r.rc, 0);
  expect_all_valid_json(r.out);
  EXPECT_NE(r.out.find(R"("iface":"a\"b\\\u0001\u00ff")"), std::string::npos) << r.out;
}

TEST(CliDecode, ExtremeValuesAndErrorFrames) {
  const Outcome r = run({"--json"},
                        "(1.0) can0 281#7FFF800000000001\n"
                        "(1.0) can0 20000004#0004000000000000\n"
                        "(1.0) can0 211#FFFFFFFFFFFFFFFF\n");
  EXPECT_EQ(r.rc, 0);
  expect_all_valid_json(r.out);
  EXPECT_NE(r.out.find(R"("speeds":[32.767,-32.768,0.0,0.001])"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("name":"error_frame")"), std::string::npos);
  EXPECT_NE(r.out.find(R"("error_bits":4294967295)"), std::string::npos);
  EXPECT_NE(r.out.find(R"("vehicle_status":255,"vehicle_status_name":"abnormal")"),
            std::string::npos);
}

// ---- Arguments --------------------------------------------------------------------------------

TEST(CliDecode, Arguments) {
  const Outcome help = run({"--help"});
  EXPECT_EQ(help.rc, 0);
  EXPECT_NE(help.out.find("usage: ranger_can decode"), std::string::npos);
  EXPECT_EQ(run({"-h"}).rc, 0);
  const Outcome bad = run({"--frobnicate"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("unknown option '--frobnicate'"), std::string::npos);
  EXPECT_EQ(run({"a.log", "b.log"}).rc, 2);
  const Outcome missing = run({"/nonexistent/ranger.log"});
  EXPECT_EQ(missing.rc, 1);
  EXPECT_NE(missing.err.find("cannot open '/nonexistent/ranger.log'"), std::string::npos);
  const Outcome directory = run({RANGER_DATA_DIR});
  EXPECT_EQ(directory.rc, 1);
  EXPECT_NE(directory.err.find("is a directory"), std::string::npos) << directory.err;
}

// A stream whose reads fail the way std::filebuf's do (it throws from underflow).
class ThrowingBuf : public std::streambuf {
 protected:
  int_type underflow() override { throw std::ios_base::failure("simulated read error"); }
};

TEST(CliDecode, ReadErrorIsReportedNotThrown) {
  ThrowingBuf buf;
  std::istream in(&buf);
  std::ostringstream out, err;
  EXPECT_EQ(run_decode({"--json"}, Io{in, out, err}), 1);
  EXPECT_NE(err.str().find("read error"), std::string::npos) << err.str();
}

// ---- JSON helpers -----------------------------------------------------------------------------

TEST(CliJson, NumbersAreAlwaysValidJson) {
  std::string s;
  append_json_number(s, std::nan(""));
  s += ' ';
  append_json_number(s, -std::numeric_limits<double>::infinity());
  s += ' ';
  append_json_number(s, 0.0);
  s += ' ';
  append_json_number(s, -2.0);
  s += ' ';
  append_json_number(s, 1e300);
  s += ' ';
  append_json_number(s, 0.1);
  EXPECT_EQ(s, "null null 0.0 -2.0 1e+300 0.1");
}

TEST(CliJson, WriterPlacesCommas) {
  std::string s;
  JsonWriter w(s);
  w.begin_object().key("a").integer(-1).key("b").begin_array().number(1.5).boolean(true).null();
  w.begin_object().end_object().end_array().key("c").string("x\ny").key("t");
  w.seconds(Timestamp{-1500000}).end_object();
  EXPECT_EQ(s, R"({"a":-1,"b":[1.5,true,null,{}],"c":"x\ny","t":-0.001500})");
  EXPECT_TRUE(JsonRecogniser::valid(s));
}

}  // namespace
}  // namespace ranger::cli
