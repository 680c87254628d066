// The one option table of the ranger_can CLI: the parser's syntax (values, flags, `--`, negative
// numbers, short aliases, repeats), its usage errors, and the help generated from the same table
// -- for a test table and for every real sub-command.
#include <gtest/gtest.h>

#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cli_commands.hpp"
#include "cli_options.hpp"
#include "ranger_can/parse.hpp"
#include "support/cli_run.hpp"

namespace ranger::cli {
namespace {

using Kind = ParseOutcome::Kind;
using test::lines_of;

int run_nothing(const ParsedArgs&, Io) {
  return 0;
}

const CommandSpec& test_command() {
  static const CommandSpec spec{
      "demo",
      "a command for the tests",
      "Does nothing.",
      {required_arg("IFACE", "an interface", "can0"), optional_arg("FILE", "a file")},
      {
          flag("--json", "JSON output"),
          option("--rate", "HZ", "a rate", number_in(0.1, 100.0)),
          option("--count", "N", "a count", integer_in(1, 10)),
          option("--source", "wheels|motion", "a choice", one_of({"wheels", "motion"})),
          option("--even", "N", "a custom rule", checked_by([](const std::string& t) -> Status {
                   if (t.size() % 2 == 0) return ok_status();
                   return Error{Errc::kInvalidArgument, "'" + t + "' has an odd length"};
                 })),
          option("--tag", "T", "repeatable").repeated(),
          flag("--dry-run", "short alias").alias('n'),
      },
      "The end.",
      run_nothing,
  };
  return spec;
}

ParseOutcome parse(const Args& args) {
  return parse_command_line(test_command(), args);
}

std::string error_of(const Args& args) {
  const ParseOutcome p = parse(args);
  EXPECT_EQ(p.kind, Kind::kUsageError);
  return p.error;
}

TEST(CliOptions, ValuesFlagsAndPositionals) {
  const ParseOutcome p = parse({"can0", "--rate", "2.5", "--count=3", "--json", "log.txt", "-n"});
  ASSERT_EQ(p.kind, Kind::kRun) << p.error;
  EXPECT_EQ(p.args.get("IFACE"), "can0");
  EXPECT_EQ(p.args.get("FILE"), "log.txt");
  EXPECT_DOUBLE_EQ(p.args.number("--rate", 0.0), 2.5);
  EXPECT_EQ(p.args.integer("--count", 0), 3);
  EXPECT_TRUE(p.args.has("--json"));
  EXPECT_TRUE(p.args.has("--dry-run"));
  EXPECT_FALSE(p.args.has("--source"));
  EXPECT_EQ(p.args.get_or("--source", "wheels"), "wheels");
  EXPECT_DOUBLE_EQ(p.args.number("--rate", 0.0), 2.5);
}

TEST(CliOptions, DoubleDashEndsOptionsAndNegativeNumbersArePositional) {
  const ParseOutcome dashed = parse({"--", "--json", "-n"});
  ASSERT_EQ(dashed.kind, Kind::kRun) << dashed.error;
  EXPECT_EQ(dashed.args.get("IFACE"), "--json");
  EXPECT_EQ(dashed.args.get("FILE"), "-n");
  EXPECT_FALSE(dashed.args.has("--json"));
  // --help after `--` is an argument, not a request for help.
  EXPECT_EQ(parse({"x", "--", "--help"}).kind, Kind::kRun);
  const ParseOutcome negative = parse({"-1.5", "-.5"});
  ASSERT_EQ(negative.kind, Kind::kRun) << negative.error;
  EXPECT_EQ(negative.args.get("IFACE"), "-1.5");
  EXPECT_EQ(negative.args.get("FILE"), "-.5");
  const ParseOutcome stdin_dash = parse({"can0", "-"});
  ASSERT_EQ(stdin_dash.kind, Kind::kRun);
  EXPECT_EQ(stdin_dash.args.get("FILE"), "-");
  // An option's value may start with '-'.
  EXPECT_EQ(parse({"can0", "--even", "-x"}).kind, Kind::kRun);
}

TEST(CliOptions, HelpAnywhereBeforeDoubleDash) {
  EXPECT_EQ(parse({"--help"}).kind, Kind::kHelp);
  EXPECT_EQ(parse({"can0", "--bogus", "-h"}).kind, Kind::kHelp);
  const test::CliOutcome r = test::run_cli(
      [](const Args& a, Io io) { return run_command(test_command(), a, io); }, {"-h"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.out, help_text(test_command()));
  EXPECT_EQ(r.err, "");
}

TEST(CliOptions, RepeatsAreErrorsUnlessRepeatable) {
  EXPECT_EQ(error_of({"can0", "--rate", "1", "--rate=2"}), "--rate given more than once");
  const ParseOutcome tags = parse({"can0", "--tag", "a", "--tag=b", "--tag", "c"});
  ASSERT_EQ(tags.kind, Kind::kRun);
  EXPECT_EQ(tags.args.all("--tag"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(tags.args.get("--tag"), "c");
  EXPECT_TRUE(tags.args.all("--json").empty());
}

TEST(CliOptions, UsageErrorsNameTheArgument) {
  EXPECT_EQ(error_of({}), "missing IFACE (e.g. can0)");
  EXPECT_EQ(error_of({"a", "b", "c"}), "unexpected argument 'c'");
  EXPECT_EQ(error_of({"can0", "--frobnicate"}), "unknown option '--frobnicate'");
  EXPECT_EQ(error_of({"can0", "--rat", "1"}), "unknown option '--rat' (did you mean --rate?)");
  EXPECT_EQ(error_of({"can0", "-x"}), "unknown option '-x'");
  EXPECT_EQ(error_of({"can0", "--rate"}), "--rate needs a value (HZ)");
  EXPECT_EQ(error_of({"can0", "--json=yes"}), "--json takes no value");
  EXPECT_EQ(error_of({"can0", "--rate", "0"}), "--rate: '0' is outside [0.1, 100]");
  EXPECT_EQ(error_of({"can0", "--rate", "nan"}), "--rate: 'nan' is not a finite number");
  EXPECT_EQ(error_of({"can0", "--count", "2.5"}), "--count: '2.5' is not an integer");
  EXPECT_EQ(error_of({"can0", "--count", "11"}), "--count: '11' is outside [1, 10]");
  EXPECT_EQ(error_of({"can0", "--source", "imu"}), "--source: 'imu' is not one of wheels, motion");
  EXPECT_EQ(error_of({"can0", "--even", "abc"}), "--even: 'abc' has an odd length");
  EXPECT_EQ(error_of({"can0", "--tag="}), "--tag: empty value");
  EXPECT_EQ(error_of({""}), "IFACE: empty value");

  const test::CliOutcome r = test::run_cli(
      [](const Args& a, Io io) { return run_command(test_command(), a, io); }, {"can0", "--bad"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(
      r.err,
      "ranger_can demo: unknown option '--bad'\n"
      "usage: ranger_can demo IFACE [FILE] [options]   ('ranger_can demo --help' for more)\n");
}

TEST(CliOptions, AskingForAnUndeclaredNameIsAProgrammingError) {
  const ParseOutcome p = parse({"can0"});
  EXPECT_THROW(p.args.has("--jsn"), std::logic_error);
  EXPECT_THROW(p.args.get("IFAC"), std::logic_error);
}

TEST(CliOptions, HelpIsGeneratedFromTheTable) {
  const std::string help = help_text(test_command());
  EXPECT_EQ(help,
            "usage: ranger_can demo IFACE [FILE] [options]\n"
            "\n"
            "Does nothing.\n"
            "\n"
            "arguments:\n"
            "  IFACE  an interface\n"
            "  FILE   a file\n"
            "\n"
            "options:\n"
            "  --json                  JSON output\n"
            "  --rate HZ               a rate\n"
            "  --count N               a count\n"
            "  --source wheels|motion  a choice\n"
            "  --even N                a custom rule\n"
            "  --tag T                 repeatable (repeatable)\n"
            "  -n, --dry-run           short alias\n"
            "  -h, --help              this text\n"
            "\n"
            "The end.\n");
}

TEST(CliOptions, LongHelpIsWrappedAndLongNamesGetALineOfTheirOwn) {
  const std::string words =
      "one two three four five six seven eight nine ten eleven twelve thirteen fourteen "
      "fifteen sixteen seventeen eighteen nineteen twenty";
  const std::string rows = format_rows(
      "list", {{"  short", words + " " + words}, {"  " + std::string(40, 'x'), "help"}});
  for (const auto& line : lines_of(rows))
    EXPECT_LE(line.size(), 100u) << line;
  const auto lines = lines_of(rows);
  EXPECT_EQ(lines[0], "list:");
  // The help column starts at most 32 characters in; a longer name gets a line of its own.
  EXPECT_EQ(lines[1].rfind("  short" + std::string(25, ' ') + "one two", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind(std::string(32, ' ') + "t", 0), 0u) << lines[2];  // continuation
  EXPECT_EQ(lines.back(), std::string(32, ' ') + "help");
}

// ---- every real sub-command -------------------------------------------------------------------

// A value the option's rule accepts, when one can be made from the rule alone.
std::optional<std::string> valid_value(const OptionSpec& o) {
  switch (o.rule.kind) {
    case ValueRule::Kind::kAny:
    case ValueRule::Kind::kNonEmpty:
      return std::string("value");
    case ValueRule::Kind::kNumber:
      return std::to_string(o.rule.max);
    case ValueRule::Kind::kInteger:
      return std::to_string(o.rule.int_min);
    case ValueRule::Kind::kChoice:
      return o.rule.choices.front();
    case ValueRule::Kind::kCustom:
      return std::nullopt;
    case ValueRule::Kind::kParameter: {  // the node's default
      const ParameterValue& d = o.rule.parameter->default_value;
      return d.kind == ParameterValue::Kind::kText ? d.text : number_text(*d.as_number());
    }
  }
  return std::nullopt;
}

TEST(CliCommands, EveryOptionInTheHelpIsAcceptedByTheParser) {
  for (const CommandSpec* c : all_commands()) {
    SCOPED_TRACE(c->name);
    Args required;
    for (const auto& p : c->positionals)
      if (p.arity == PositionalSpec::Arity::kRequired) required.push_back("x");
    const std::string help = help_text(*c);
    EXPECT_EQ(parse_command_line(*c, required).kind, Kind::kRun);
    for (const auto& o : c->options) {
      SCOPED_TRACE(o.name);
      const std::string shown = (o.short_name != 0 ? std::string("-") + o.short_name + ", " : "") +
                                o.name + (o.value_name.empty() ? "" : " " + o.value_name);
      // A long left column puts the help on the next line (format_rows).
      EXPECT_TRUE(help.find("  " + shown + " ") != std::string::npos ||
                  help.find("  " + shown + "\n") != std::string::npos);
      Args args = required;
      args.push_back(o.name);
      if (!o.value_name.empty()) {
        const auto v = valid_value(o);
        if (!v) continue;
        args.push_back(*v);
      }
      const ParseOutcome p = parse_command_line(*c, args);
      EXPECT_EQ(p.kind, Kind::kRun) << p.error;
    }
    for (const auto& p : c->positionals)
      EXPECT_NE(help.find("  " + p.name + " "), std::string::npos) << p.name;
    EXPECT_NE(help.find("  -h, --help"), std::string::npos);
    for (const auto& line : lines_of(help))
      EXPECT_LE(line.size(), 100u) << line;
  }
}

TEST(CliCommands, SendListsEveryCommandItKnows) {
  const std::string help = help_text(send_command());
  for (const char* command : {"mode ", "control ", "clear-errors ", "ultrasonic ", "motion "})
    EXPECT_NE(help.find("  " + std::string(command)), std::string::npos) << command;
  EXPECT_NE(send_command().summary.find("motion"), std::string::npos);
}

}  // namespace
}  // namespace ranger::cli
