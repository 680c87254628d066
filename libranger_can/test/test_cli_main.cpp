// The top level of `ranger_can` (command list, --help, --version, `help COMMAND`, unknown
// commands) in-process, and the real executable's exit statuses and stderr on inputs that hold
// nothing a command needs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "cli_commands.hpp"
#include "cli_options.hpp"
#include "support/cli_run.hpp"

namespace ranger::cli {
namespace {

using test::lines_of;

test::CliOutcome run(const Args& args, const std::string& input = "") {
  return test::run_cli(run_main, args, input);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Process {
  int rc;
  std::string out;
};

// Runs the real ranger_can with a shell command line (arguments already quoted).
Process run_binary(const std::string& args) {
  const std::string cmd = std::string("'") + RANGER_CLI_PATH + "' " + args;
  FILE* pipe = popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  if (pipe == nullptr) return {-1, ""};
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, pipe)) > 0;)
    out.append(buf, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(CliMain, HelpListsEveryCommandWithItsSummary) {
  const test::CliOutcome r = run({"--help"});
  EXPECT_EQ(r.rc, 0);
  for (const CommandSpec* c : all_commands())
    EXPECT_NE(r.out.find("  " + c->name + " "), std::string::npos) << c->name;
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("\n  send +send one command: mode, park, lights, version, control, "
                        "clear-errors, ultrasonic, motion, drive_mode\n")))
      << r.out;
  EXPECT_EQ(run({"-h"}).out, r.out);
  EXPECT_EQ(run({"help"}).out, r.out);
}

TEST(CliMain, HelpCommandEqualsCommandHelp) {
  for (const CommandSpec* c : all_commands()) {
    const test::CliOutcome a = run({"help", c->name});
    const test::CliOutcome b = run({c->name, "--help"});
    EXPECT_EQ(a.rc, 0);
    EXPECT_EQ(b.rc, 0);
    EXPECT_EQ(a.out, b.out);
    EXPECT_EQ(a.out, help_text(*c));
  }
}

TEST(CliMain, VersionIsTheProjectVersion) {
  const test::CliOutcome r = run({"--version"});
  EXPECT_EQ(r.rc, 0);
  // package.xml carries the same version as CMake's project().
  std::smatch m;
  const std::string package = read_file(std::string(RANGER_SOURCE_DIR) + "/package.xml");
  ASSERT_TRUE(std::regex_search(package, m, std::regex("<version>([^<]+)</version>")));
  EXPECT_EQ(r.out, "ranger_can " + m[1].str() + "\n");
  EXPECT_EQ(std::string(version()), m[1].str());
  EXPECT_EQ(run_binary("--version").out, r.out);
}

TEST(CliMain, UnknownOrMissingCommandIsAUsageError) {
  const test::CliOutcome none = run({});
  EXPECT_EQ(none.rc, 2);
  EXPECT_NE(none.err.find("usage: ranger_can COMMAND"), std::string::npos);
  const test::CliOutcome unknown = run({"decod"});
  EXPECT_EQ(unknown.rc, 2);
  EXPECT_EQ(lines_of(unknown.err).front(), "ranger_can: unknown command 'decod'");
  EXPECT_EQ(run({"help", "decod"}).rc, 2);
}

TEST(CliMain, DoubleDashReachesTheSubCommand) {
  // A file whose name starts with '-': after `--` it is a file (that does not exist), not an
  // option.
  const test::CliOutcome r = run({"decode", "--", "--no-such-file"});
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.err.find("cannot open '--no-such-file'"), std::string::npos) << r.err;
}

// ---- the real executable fails loudly -----------------------------------------------------------

class CliBinary : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "ranger_cli_main_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".log";
  }
  void TearDown() override { std::remove(path_.c_str()); }
  void write(const std::string& text) {
    std::ofstream f(path_, std::ios::binary);
    f << text;
  }
  std::string path_;
};

TEST_F(CliBinary, DecodeOfGarbageExitsNonZeroWithBoundedOutput) {
  std::string garbage;
  for (int i = 0; i < 20000; ++i)
    garbage += "\x01\x02 no frame here #" + std::to_string(i) + "\n";
  write(garbage);
  const Process p = run_binary("decode '" + path_ + "' 2>&1");
  EXPECT_EQ(p.rc, 1);
  const auto lines = lines_of(p.out);
  ASSERT_EQ(lines.size(), 22u) << p.out.substr(0, 3000);  // 20 lines, the count, the reason
  EXPECT_EQ(lines[20], "ranger_can decode: 20000 malformed line(s) skipped (the first 20 shown)");
  EXPECT_EQ(lines[21],
            "ranger_can decode: nothing to decode: no RANGER frames in 20000 line(s) (20000 "
            "malformed)");
}

TEST_F(CliBinary, DecodeAndOdomOfAnEmptyFileFail) {
  write("");
  const Process decode = run_binary("decode '" + path_ + "' 2>&1");
  EXPECT_EQ(decode.rc, 1);
  EXPECT_EQ(decode.out, "ranger_can decode: nothing to decode: the input is empty\n");
  const Process odom = run_binary("odom '" + path_ + "' 2>&1");
  EXPECT_EQ(odom.rc, 1);
  EXPECT_EQ(odom.out, "ranger_can odom: no pose: the input is empty\n");  // and no pose
}

TEST_F(CliBinary, DecodeOfTheSampleLogSucceedsQuietly) {
  const Process p =
      run_binary("decode '" + std::string(RANGER_DATA_DIR) + "/sample.log' 2>&1 >/dev/null");
  EXPECT_EQ(p.rc, 0);
  EXPECT_EQ(p.out, "");
}

TEST_F(CliBinary, UsageErrorsExitTwoWithOneLineAndTheUsage) {
  const Process p = run_binary("odom --every 0 2>&1");
  EXPECT_EQ(p.rc, 2);
  EXPECT_EQ(p.out,
            "ranger_can odom: --every: '0' is outside [1, 2147483647]\n"
            "usage: ranger_can odom [FILE] [options]   ('ranger_can odom --help' for more)\n");
}

}  // namespace
}  // namespace ranger::cli
