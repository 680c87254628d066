// The one option table of the `ranger_can` CLI: every sub-command declares its positional
// arguments and options (each with a help line and a value rule) in a CommandSpec; one parser
// reads every sub-command's arguments against its table, and the help text is generated from the
// same table, so the help cannot omit what the parser accepts.
//
// Syntax, the same for every sub-command:
//   --name VALUE, --name=VALUE   an option with a value (the value may start with '-')
//   --flag                       a flag takes no value ("--flag=x" is an error)
//   -x                           a short alias where the table declares one
//   --                           ends the options: every later argument is positional
//   -                            a positional argument (standard input, by convention)
//   -1.5, -.5                    a positional argument: a negative number is never an option
//   -h, --help                   anywhere before `--`: print the help, exit 0
// An option given twice is an error unless the table marks it repeatable; a missing or surplus
// positional argument, an unknown option and a value its rule refuses are usage errors (exit 2)
// whose one-line message names the argument.
//
// Adding an option: one entry in the command's table (flag(...) or option(...) with a rule),
// then read it in the command's run function (`args.has("--x")`, `args.number("--x", 1.0)`).
// An option several sub-commands share (e.g. a future --protocol) is a function returning its
// OptionSpec, listed in each table that takes it.
// Adding a sub-command: a cmd_<name>.cpp that defines its CommandSpec (name, summary,
// description, positionals, options, run function) and a `run_<name>(Args, Io)` entry point
// (`return run_command(spec, args, io)`), declared in cli_commands.hpp and listed in
// all_commands() (cli_main.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli_commands.hpp"
#include "ranger_can/control/parameters.hpp"
#include "ranger_can/result.hpp"

namespace ranger::cli {

// What a value (of an option or a positional argument) must look like. The parser checks it, so
// a run function reads only values its table accepted.
struct ValueRule {
  enum class Kind { kAny, kNonEmpty, kNumber, kInteger, kChoice, kCustom, kParameter };
  Kind kind = Kind::kNonEmpty;
  double min = 0.0;  // kNumber: inclusive range
  double max = 0.0;
  std::int64_t int_min = 0;  // kInteger: inclusive range
  std::int64_t int_max = 0;
  std::vector<std::string> choices;                 // kChoice
  std::function<Status(const std::string&)> check;  // kCustom: the error names the problem
  const Parameter* parameter = nullptr;             // kParameter: a row of the parameter table
};

ValueRule any_text();                                      // anything, the empty string included
ValueRule non_empty();                                     // any non-empty text (the default)
ValueRule number_in(double min, double max);               // a finite number inside [min, max]
ValueRule integer_in(std::int64_t min, std::int64_t max);  // decimal or 0x..., inside [min, max]
ValueRule one_of(std::vector<std::string> choices);        // exactly one of these words
ValueRule checked_by(std::function<Status(const std::string&)> check);
// What the node accepts for its parameter `name` (a row of ranger::node_parameters(): its type,
// range or values), for an option that takes the same value (`sim --soc`: sim/initial_soc).
ValueRule parameter_rule(std::string_view name);

struct OptionSpec {
  std::string name;        // the long form, "--soc"
  std::string value_name;  // "PCT" as the help shows it; empty: a flag, which takes no value
  std::string help;        // wrapped to the terminal width; '\n' forces a line break
  ValueRule rule;
  char short_name = 0;      // 'n' for "-n"; 0: none
  bool repeatable = false;  // may be given more than once (all values are kept, in order)

  OptionSpec& alias(char c) {
    short_name = c;
    return *this;
  }
  OptionSpec& repeated() {
    repeatable = true;
    return *this;
  }
};

OptionSpec flag(std::string name, std::string help);
OptionSpec option(std::string name, std::string value_name, std::string help,
                  ValueRule rule = non_empty());

struct PositionalSpec {
  enum class Arity { kRequired, kOptional, kRest };  // kRest: any number, only as the last one
  std::string name;                                  // "IFACE"
  std::string help;
  Arity arity = Arity::kRequired;
  ValueRule rule;
  std::string example;  // "can0": completes "missing IFACE (e.g. can0)"
};

PositionalSpec required_arg(std::string name, std::string help, std::string example = "",
                            ValueRule rule = non_empty());
PositionalSpec optional_arg(std::string name, std::string help, ValueRule rule = non_empty());
PositionalSpec rest_args(std::string name, std::string help);

class ParsedArgs;

struct CommandSpec {
  std::string name;         // "decode"
  std::string summary;      // one line: the command list of `ranger_can --help`
  std::string description;  // the help's paragraphs after the usage line (verbatim)
  std::vector<PositionalSpec> positionals;
  std::vector<OptionSpec> options;  // -h/--help is implicit
  std::string epilogue;             // after the option list (verbatim): sub-languages, exit status
  int (*run)(const ParsedArgs& args, Io io) = nullptr;
};

// The values of one command line, as the command's table declared them.
class ParsedArgs {
 public:
  explicit ParsedArgs(const CommandSpec& spec) : spec_(&spec) {}

  // Every accessor takes a name the table declares ("--soc", "IFACE"); any other name is a
  // programming error (std::logic_error, which main reports as an internal error).
  bool has(std::string_view name) const;                        // given at least once
  std::optional<std::string> get(std::string_view name) const;  // the last value given
  std::string get_or(std::string_view name, const std::string& fallback) const;
  const std::vector<std::string>& all(std::string_view name) const;  // every value, in order
  double number(std::string_view name, double fallback) const;       // a kNumber option
  std::int64_t integer(std::string_view name, std::int64_t fallback) const;  // a kInteger one

  const CommandSpec& spec() const { return *spec_; }
  void add(const std::string& name, std::string value) {
    values_[name].push_back(std::move(value));
  }

 private:
  const std::vector<std::string>* find(std::string_view name) const;
  const CommandSpec* spec_;
  std::map<std::string, std::vector<std::string>, std::less<>> values_;
};

struct ParseOutcome {
  enum class Kind { kRun, kHelp, kUsageError };
  Kind kind;
  ParsedArgs args;
  std::string error;  // kUsageError: one line, without the "ranger_can NAME: " prefix
};

ParseOutcome parse_command_line(const CommandSpec& spec, const Args& args);

// A two-column list as the help prints arguments and options ("heading:" then each row, the
// right column wrapped), for a command's own lists (e.g. the commands `send` knows).
struct HelpRow {
  std::string left;  // "  mode ackermann|oblique|spin"
  std::string help;
};
std::string format_rows(const std::string& heading, const std::vector<HelpRow>& rows);

// "ranger_can decode [FILE] [options]"
std::string usage_synopsis(const CommandSpec& spec);
// The full help: usage line, description, arguments, options, epilogue.
std::string help_text(const CommandSpec& spec);
// Reports a usage error ("ranger_can NAME: message" and the usage line) on io.err; returns 2.
int usage_error(const CommandSpec& spec, Io io, const std::string& message);
// Parses and runs: the help (0), a usage error (2), or spec.run's exit status.
int run_command(const CommandSpec& spec, const Args& args, Io io);

}  // namespace ranger::cli
