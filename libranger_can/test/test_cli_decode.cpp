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
#include "ranger_can/json.hpp"
#include "ranger_can/wire/protocol.hpp"
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

// ---- The bundled logs of both revisions, padded and unpadded ----------------------------------
// (written by test_cli_odom.cpp's generator: one drive, encoded under each profile)

const std::string kPaddedLog = std::string(RANGER_DATA_DIR) + "/sample_padded.log";
const std::string kAgxLog = std::string(RANGER_DATA_DIR) + "/sample_agx_v2.log";
const std::string kAgxUnpaddedLog = std::string(RANGER_DATA_DIR) + "/sample_agx_v2_unpadded.log";

// The value of `"key":` in a JSON line, as text up to the next ',' or '}' ("" when absent).
std::string json_value(const std::string& line, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const auto at = line.find(k);
  if (at == std::string::npos) return "";
  const auto start = at + k.size();
  return line.substr(start, line.find_first_of(",}", start) - start);
}

TEST(CliDecode, PaddedLogDecodesEveryFrameAndCountsTheIgnoredBytes) {
  const Outcome r = run({kPaddedLog, "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  expect_all_valid_json(r.out);
  const auto lines = lines_of(r.out);
  EXPECT_EQ(lines.size(), lines_of(read_file(kPaddedLog)).size());
  std::size_t padded = 0;
  for (const auto& line : lines) {
    EXPECT_EQ(line.find("\"error\""), std::string::npos) << line;
    EXPECT_EQ(json_value(line, "dlc"), "8") << line;
    const int id = std::stoi(json_value(line, "id"));
    const int extra = 8 - protocol::layout_dlc(static_cast<std::uint32_t>(id));
    if (extra > 0) {
      EXPECT_EQ(json_value(line, "extra_bytes"), std::to_string(extra)) << line;
      ++padded;
    } else {
      EXPECT_EQ(line.find("extra_bytes"), std::string::npos) << line;
    }
  }
  EXPECT_GT(padded, 150u);  // every 0x291 (6 bytes), and the one-byte commands
  EXPECT_NE(r.out.find(R"("name":"motion_mode","dlc":8,"data":"0000000000000000","extra_bytes":6,)"
                       R"("mode":0,"mode_name":"ackermann","switching":false)"),
            std::string::npos);
  // Text: the same frames, each padded one saying so.
  const Outcome text = run({kPaddedLog});
  ASSERT_EQ(text.rc, 0);
  EXPECT_NE(text.out.find("motion_mode                  mode=0 (ackermann) switching=no  "
                          "[+6 bytes ignored]\n"),
            std::string::npos);
  EXPECT_NE(text.out.find("control_mode_command         mode=1 (can)  [+7 bytes ignored]\n"),
            std::string::npos);
  EXPECT_EQ(text.out.find(" error: "), std::string::npos);
}

TEST(CliDecode, AgxV2LogTourUnderItsProfile) {
  const Outcome r = run({kAgxLog, "--protocol", "agx_v2"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto lines = lines_of(r.out);
  const std::vector<std::string> tour = {
      "1700000000.000000 can0 421 control_mode_command         mode=1 (can)  [+7 bytes ignored]",
      "1700000000.010000 can0 4A1 version                      request  [+7 bytes ignored]",
      "1700000000.020000 can0 4A1 version                      text=\"V2.3.1\"",
      "1700000000.030000 can0 121 light_command                enable=yes front=on/0 "
      "rear=breathing/0 counter=0",
      "1700000000.040000 can0 231 light_state                  enable=yes front=on/0 "
      "rear=breathing/0 counter=1",
      "1700000000.050000 can0 241 remote_control               swa=up swb=up swc=middle swd=down "
      "right_h=0 right_v=0 left_v=12 left_h=0 var_a=0 counter=7",
      "1700000000.060000 can0 311 odometer                     left=12345 right=12400 (raw)",
      "1700000000.070000 can0 211 system_status                vehicle=normal control=can "
      "battery=51.2 V errors=0x0200 [host_communication_lost] counter=200",
      "1700000000.080000 can0 261 motor_low_speed              motor=1 voltage=51.0 V driver=33 "
      "degC motor=29 degC status=none",
      "1700000000.090000 can0 361 bms                          battery=pack soc=87% soh=98% "
      "voltage=51.20 V current=-2.4 A temperature=25.3 degC",
      "1700000000.100000 can0 362 bms_alarm                    battery=pack alarms=none "
      "warnings=none  [+4 bytes ignored]",
      "1700000000.110000 can0 141 motion_mode_command          mode=0 (ackermann)  [+7 bytes "
      "ignored]",
      "1700000000.120000 can0 111 motion_command               linear=0.500 m/s yaw_rate=0.000 "
      "rad/s spin=0.000 m/s steering=0.00 deg",
  };
  ASSERT_GT(lines.size(), tour.size());
  for (std::size_t i = 0; i < tour.size(); ++i)
    EXPECT_EQ(lines[i], tour[i]);
  EXPECT_EQ(r.out.find(" error: "), std::string::npos);
}

TEST(CliDecode, AgxV2LogCounterIsNoFault) {
  const Outcome r = run({kAgxLog, "--json", "--protocol", "agx_v2"});
  ASSERT_EQ(r.rc, 0) << r.err;
  expect_all_valid_json(r.out);
  std::size_t statuses = 0, faults = 0;
  for (const auto& line : lines_of(r.out)) {
    EXPECT_EQ(line.find("\"error\""), std::string::npos) << line;
    if (json_value(line, "name") != "\"system_status\"") continue;
    ++statuses;
    EXPECT_FALSE(json_value(line, "counter").empty()) << line;
    EXPECT_EQ(json_value(line, "critical"), "false") << line;
    if (json_value(line, "error_bits") != "0") ++faults;
  }
  EXPECT_GT(statuses, 170u);
  EXPECT_EQ(faults, 1u) << "only the tour's host_communication_lost";
  // Units: 0.1 V BMS, wheel angles in mrad (left positive) read back in rad (right positive).
  EXPECT_NE(r.out.find(R"("voltage":51.2,"current":-2.4)"), std::string::npos);
}

TEST(CliDecode, AgxV2LogUnderTheManualShowsWhyTheProfileMatters) {
  const Outcome r = run({kAgxLog, "--json", "--protocol", "manual"});
  ASSERT_EQ(r.rc, 0) << r.err;
  std::size_t phantom = 0;
  for (const auto& line : lines_of(r.out)) {
    if (json_value(line, "name") == "\"system_status\"" && json_value(line, "error_bits") != "0") {
      ++phantom;  // the counter in byte 7, read as the low byte of a 32-bit error word
    }
  }
  EXPECT_GT(phantom, 100u);
  EXPECT_NE(r.out.find(R"("voltage":5.12,)"), std::string::npos) << "0.1 V read as 0.01 V";
  EXPECT_EQ(r.out.find(R"("voltage":51.2,)"), std::string::npos);
}

TEST(CliDecode, AgxV2LogPaddedAndUnpaddedDecodeAlike) {
  const auto padded = lines_of(run({kAgxLog, "--json", "--protocol", "agx_v2"}).out);
  const auto unpadded = lines_of(run({kAgxUnpaddedLog, "--json", "--protocol", "agx_v2"}).out);
  ASSERT_EQ(padded.size(), unpadded.size());
  // Equal after the frame part (dlc, data, extra_bytes): the same messages.
  auto message_part = [](const std::string& line) {
    const auto data = line.find("\"data\":");
    const auto after = line.find(',', line.find('"', data + 8) + 1);
    std::string rest = line.substr(after);
    const auto extra = rest.find(",\"extra_bytes\":");
    if (extra != std::string::npos) rest.erase(extra, rest.find(',', extra + 1) - extra);
    return line.substr(0, line.find("\"dlc\":")) + rest;
  };
  for (std::size_t i = 0; i < padded.size(); ++i) {
    EXPECT_EQ(message_part(padded[i]), message_part(unpadded[i])) << padded[i];
    EXPECT_EQ(unpadded[i].find("extra_bytes"), std::string::npos) << unpadded[i];
  }
}

TEST(CliDecode, ProtocolOptions) {
  const Outcome help = run({"--help"});
  EXPECT_NE(help.out.find("--protocol auto|manual|agx_v2"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--set NAME=VALUE"), std::string::npos);
  EXPECT_NE(help.out.find("steering_unit_271=centideg|millirad"), std::string::npos);
  const Outcome bad = run({kAgxLog, "--protocol", "vendor"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_EQ(bad.out, "");
  EXPECT_NE(bad.err.find("--protocol: 'vendor' is not one of auto, manual, agx_v2"), std::string::npos)
      << bad.err;
  const Outcome value = run({kAgxLog, "--set", "error_word=agx32"});
  EXPECT_EQ(value.rc, 2);
  EXPECT_NE(value.err.find("protocol setting error_word = 'agx32' is invalid (valid: "
                           "manual32|agx16)"),
            std::string::npos)
      << value.err;
  const Outcome name = run({kAgxLog, "--set", "counter=yes"});
  EXPECT_EQ(name.rc, 2);
  EXPECT_NE(name.err.find("unknown protocol setting 'counter' (valid: steering_unit_111, "),
            std::string::npos)
      << name.err;
  // One setting on top of the manual: the 16-bit word alone removes the phantom faults.
  const Outcome word =
      run({kAgxLog, "--json", "--protocol", "manual", "--set", "error_word=agx16", "--set",
           "bms_voltage_scale=0.1"});
  ASSERT_EQ(word.rc, 0) << word.err;
  EXPECT_NE(word.out.find(R"("voltage":51.2,)"), std::string::npos);
  EXPECT_NE(word.out.find(R"("errors":[],"critical":false,"counter":1})"), std::string::npos);
  // Later --set wins.
  const Outcome twice =
      run({kAgxLog, "--json", "--set", "bms_voltage_scale=0.1", "--set", "bms_voltage_scale=0.01"});
  EXPECT_NE(twice.out.find(R"("voltage":5.12,)"), std::string::npos);
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

TEST(CliDecode, UltrasonicZeroIsNoReading) {
  const std::string line = "(1.0) can0 342#0000FFFF04B00000\n";
  const Outcome text = run({}, line);
  EXPECT_NE(text.out.find("s1=no_reading s2=offline s3=1200 mm s4=no_reading"), std::string::npos)
      << text.out;
  const Outcome json = run({"--json"}, line);
  EXPECT_NE(json.out.find(R"("raw":[0,-1,1200,0],"status":["no_reading","offline","ok",)"
                          R"("no_reading"])"),
            std::string::npos)
      << json.out;
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
