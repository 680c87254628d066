#include "cli_options.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <limits>
#include <ostream>
#include <stdexcept>

#include "ranger_can/frontend/node_parameters.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/text.hpp"

namespace ranger::cli {

// ---- rules and table entries --------------------------------------------------------------------

ValueRule any_text() {
  ValueRule r;
  r.kind = ValueRule::Kind::kAny;
  return r;
}

ValueRule non_empty() {
  return ValueRule{};
}

ValueRule number_in(double min, double max) {
  ValueRule r;
  r.kind = ValueRule::Kind::kNumber;
  r.min = min;
  r.max = max;
  return r;
}

ValueRule integer_in(std::int64_t min, std::int64_t max) {
  ValueRule r;
  r.kind = ValueRule::Kind::kInteger;
  r.int_min = min;
  r.int_max = max;
  return r;
}

ValueRule one_of(std::vector<std::string> choices) {
  ValueRule r;
  r.kind = ValueRule::Kind::kChoice;
  r.choices = std::move(choices);
  return r;
}

ValueRule checked_by(std::function<Status(const std::string&)> check) {
  ValueRule r;
  r.kind = ValueRule::Kind::kCustom;
  r.check = std::move(check);
  return r;
}

ValueRule parameter_rule(std::string_view name) {
  ValueRule r;
  r.kind = ValueRule::Kind::kParameter;
  r.parameter = find_node_parameter(name);
  if (r.parameter == nullptr) {
    throw std::logic_error("'" + std::string(name) + "' is not a row of the parameter table");
  }
  return r;
}

OptionSpec flag(std::string name, std::string help) {
  OptionSpec o;
  o.name = std::move(name);
  o.help = std::move(help);
  return o;
}

OptionSpec option(std::string name, std::string value_name, std::string help, ValueRule rule) {
  OptionSpec o;
  o.name = std::move(name);
  o.value_name = std::move(value_name);
  o.help = std::move(help);
  o.rule = std::move(rule);
  return o;
}

PositionalSpec required_arg(std::string name, std::string help, std::string example,
                            ValueRule rule) {
  return PositionalSpec{std::move(name), std::move(help), PositionalSpec::Arity::kRequired,
                        std::move(rule), std::move(example)};
}

PositionalSpec optional_arg(std::string name, std::string help, ValueRule rule) {
  return PositionalSpec{std::move(name), std::move(help), PositionalSpec::Arity::kOptional,
                        std::move(rule), ""};
}

PositionalSpec rest_args(std::string name, std::string help) {
  return PositionalSpec{std::move(name), std::move(help), PositionalSpec::Arity::kRest, any_text(),
                        ""};
}

// ---- parsed values ------------------------------------------------------------------------------

const std::vector<std::string>* ParsedArgs::find(std::string_view name) const {
  const bool declared = std::any_of(spec_->options.begin(), spec_->options.end(),
                                    [&](const OptionSpec& o) { return o.name == name; }) ||
                        std::any_of(spec_->positionals.begin(), spec_->positionals.end(),
                                    [&](const PositionalSpec& p) { return p.name == name; });
  if (!declared) {
    throw std::logic_error("'" + std::string(name) + "' is not in the option table of '" +
                           spec_->name + "'");
  }
  const auto it = values_.find(name);
  return it == values_.end() ? nullptr : &it->second;
}

bool ParsedArgs::has(std::string_view name) const {
  return find(name) != nullptr;
}

std::optional<std::string> ParsedArgs::get(std::string_view name) const {
  const auto* v = find(name);
  if (v == nullptr || v->empty()) return std::nullopt;
  return v->back();
}

std::string ParsedArgs::get_or(std::string_view name, const std::string& fallback) const {
  return get(name).value_or(fallback);
}

const std::vector<std::string>& ParsedArgs::all(std::string_view name) const {
  static const std::vector<std::string> kNone;
  const auto* v = find(name);
  return v == nullptr ? kNone : *v;
}

double ParsedArgs::number(std::string_view name, double fallback) const {
  const auto v = get(name);
  if (!v) return fallback;
  const auto d = parse_double(name, *v);  // the rule accepted it already
  return d ? *d : fallback;
}

std::int64_t ParsedArgs::integer(std::string_view name, std::int64_t fallback) const {
  const auto v = get(name);
  if (!v) return fallback;
  const auto n = parse_integer(name, *v, std::numeric_limits<std::int64_t>::min(),
                               std::numeric_limits<std::int64_t>::max());
  return n ? *n : fallback;
}

// ---- parsing ------------------------------------------------------------------------------------

namespace {

Error usage(std::string message) {
  return Error{Errc::kInvalidArgument, std::move(message)};
}

// `text` read as the row's type, then checked against the row: "--soc = 150 is out of range:
// valid [0, 100] %".
Status check_parameter_text(const std::string& what, const Parameter& row,
                            const std::string& text) {
  ParameterValue v(text);
  if (row.type == ParameterType::kNumber || row.type == ParameterType::kSeconds) {
    auto d = parse_double(what, text);
    if (!d) return d.error();
    v = *d;
  } else if (row.type == ParameterType::kInteger) {
    auto n = parse_integer(what, text, std::numeric_limits<std::int64_t>::min(),
                           std::numeric_limits<std::int64_t>::max());
    if (!n) return n.error();
    v = static_cast<long long>(*n);
  } else if (row.type == ParameterType::kBool && (text == "true" || text == "false")) {
    v = text == "true";
  }
  if (auto checked = check_parameter(row, v); !checked) {
    return usage(what + " " + checked.error().message);
  }
  return ok_status();
}

Status check_value(const std::string& what, const ValueRule& rule, const std::string& value) {
  switch (rule.kind) {
    case ValueRule::Kind::kAny:
      return ok_status();
    case ValueRule::Kind::kNonEmpty:
      if (value.empty()) return usage(what + ": empty value");
      return ok_status();
    case ValueRule::Kind::kNumber: {
      auto v = parse_double_in(what, value, rule.min, rule.max);
      if (!v) return v.error();
      return ok_status();
    }
    case ValueRule::Kind::kInteger: {
      auto v = parse_integer(what, value, rule.int_min, rule.int_max);
      if (!v) return v.error();
      return ok_status();
    }
    case ValueRule::Kind::kChoice:
      if (std::find(rule.choices.begin(), rule.choices.end(), value) != rule.choices.end()) {
        return ok_status();
      }
      return usage(what + ": '" + value + "' is not one of " + text::join(rule.choices, ", "));
    case ValueRule::Kind::kCustom: {
      Status s = rule.check ? rule.check(value) : ok_status();
      if (!s) return usage(what + ": " + s.error().message);
      return ok_status();
    }
    case ValueRule::Kind::kParameter:
      return check_parameter_text(what, *rule.parameter, value);
  }
  return ok_status();
}

bool is_negative_number(const std::string& a) {
  if (a.size() < 2 || a[0] != '-') return false;
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  return digit(a[1]) || (a[1] == '.' && a.size() > 2 && digit(a[2]));
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string unknown_option(const CommandSpec& spec, const std::string& given) {
  std::string message = "unknown option '" + given + "'";
  const OptionSpec* best = nullptr;
  // Suggest only near misses: one edit per four characters typed (at least one).
  std::size_t best_distance = std::max<std::size_t>(1, given.size() / 4) + 1;
  for (const auto& o : spec.options) {
    const std::size_t d = edit_distance(given, o.name);
    if (d < best_distance) {
      best = &o;
      best_distance = d;
    }
  }
  if (best != nullptr) message += " (did you mean " + best->name + "?)";
  return message;
}

bool is_help(const std::string& a) {
  return a == "-h" || a == "--help";
}

// The option `a` names ("--name", "--name=value" or "-x"), and the value given inline.
const OptionSpec* find_option(const CommandSpec& spec, const std::string& a, std::string& name,
                              std::optional<std::string>& inline_value) {
  name = a;
  if (a.rfind("--", 0) == 0) {
    const auto eq = a.find('=');
    if (eq != std::string::npos) {
      inline_value = a.substr(eq + 1);
      name = a.substr(0, eq);
    }
    for (const auto& o : spec.options) {
      if (o.name == name) return &o;
    }
  } else if (a.size() == 2) {
    for (const auto& o : spec.options) {
      if (o.short_name == a[1]) return &o;
    }
  }
  return nullptr;
}

// The option args[i] names, with its value (inline, or the next argument: i moves past it).
Status take_option(const CommandSpec& spec, const Args& args, std::size_t& i, ParsedArgs& parsed) {
  std::string name;
  std::optional<std::string> inline_value;
  const OptionSpec* found = find_option(spec, args[i], name, inline_value);
  if (found == nullptr) return usage(unknown_option(spec, name));
  const OptionSpec& o = *found;
  if (!o.repeatable && parsed.has(o.name)) return usage(o.name + " given more than once");
  std::string value;
  if (o.value_name.empty()) {
    if (inline_value) return usage(o.name + " takes no value");
  } else if (inline_value) {
    value = *inline_value;
  } else if (i + 1 < args.size()) {
    value = args[++i];
  } else {
    return usage(o.name + " needs a value (" + o.value_name + ")");
  }
  if (!o.value_name.empty()) {
    if (Status s = check_value(o.name, o.rule, value); !s) return s;
  }
  parsed.add(o.name, std::move(value));
  return ok_status();
}

// The required positionals from `next` on are all given.
Status check_required(const CommandSpec& spec, std::size_t next, const ParsedArgs& parsed) {
  for (std::size_t k = next; k < spec.positionals.size(); ++k) {
    const PositionalSpec& p = spec.positionals[k];
    if (p.arity == PositionalSpec::Arity::kRequired && !parsed.has(p.name)) {
      return usage("missing " + p.name + (p.example.empty() ? "" : " (e.g. " + p.example + ")"));
    }
  }
  return ok_status();
}

}  // namespace

ParseOutcome parse_command_line(const CommandSpec& spec, const Args& args) {
  using Kind = ParseOutcome::Kind;
  const auto end_of_options = std::find(args.begin(), args.end(), "--");
  if (std::any_of(args.begin(), end_of_options, is_help))
    return {Kind::kHelp, ParsedArgs(spec), ""};

  ParsedArgs parsed(spec);
  auto fail = [&](const Error& e) {
    return ParseOutcome{Kind::kUsageError, ParsedArgs(spec), e.message};
  };
  std::size_t next_positional = 0;
  bool options_ended = false;

  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (!options_ended && a == "--") {
      options_ended = true;
      continue;
    }
    if (!options_ended && a.size() > 1 && a[0] == '-' && !is_negative_number(a)) {
      if (Status s = take_option(spec, args, i, parsed); !s) return fail(s.error());
      continue;
    }
    // A positional argument.
    if (next_positional >= spec.positionals.size()) {
      return fail(usage("unexpected argument '" + a + "'"));
    }
    const PositionalSpec& p = spec.positionals[next_positional];
    if (Status s = check_value(p.name, p.rule, a); !s) return fail(s.error());
    parsed.add(p.name, a);
    if (p.arity != PositionalSpec::Arity::kRest) ++next_positional;
  }
  if (Status s = check_required(spec, next_positional, parsed); !s) return fail(s.error());
  return {Kind::kRun, std::move(parsed), ""};
}

// ---- help ---------------------------------------------------------------------------------------

namespace {

constexpr std::size_t kWidth = 100;     // total line width of the help
constexpr std::size_t kMaxColumn = 32;  // where the help column starts at most

// Word-wraps `text` into `out`, every line indented to `column` (the first line's indent is what
// `out` already holds of that line). '\n' in `text` forces a break.
void append_wrapped(std::string& out, const std::string& text, std::size_t column) {
  const std::string indent(column, ' ');
  std::size_t line_length = column;
  std::size_t start = 0;
  bool first_line = true;
  while (start <= text.size()) {
    const std::size_t nl = std::min(text.find('\n', start), text.size());
    const std::string paragraph = text.substr(start, nl - start);
    if (!first_line) {
      out += '\n' + indent;
      line_length = column;
    }
    first_line = false;
    std::size_t pos = 0;
    bool line_empty = true;
    while (pos < paragraph.size()) {
      std::size_t word_end = paragraph.find(' ', pos);
      if (word_end == std::string::npos) word_end = paragraph.size();
      const std::string word = paragraph.substr(pos, word_end - pos);
      pos = word_end + 1;
      if (word.empty()) continue;
      if (!line_empty && line_length + 1 + word.size() > kWidth) {
        out += '\n' + indent;
        line_length = column;
        line_empty = true;
      }
      if (!line_empty) {
        out += ' ';
        ++line_length;
      }
      out += word;
      line_length += word.size();
      line_empty = false;
    }
    start = nl + 1;
  }
  out += '\n';
}

void append_rows(std::string& out, const std::string& heading, const std::vector<HelpRow>& rows) {
  if (rows.empty()) return;
  std::size_t column = 0;
  for (const auto& r : rows)
    column = std::max(column, r.left.size() + 2);
  column = std::min(column, kMaxColumn);
  out += '\n';
  out += heading;
  out += ":\n";
  for (const auto& r : rows) {
    out += r.left;
    if (r.left.size() + 2 > column) {  // too long: the help starts on the next line
      out += '\n' + std::string(column, ' ');
    } else {
      out += std::string(column - r.left.size(), ' ');
    }
    append_wrapped(out, r.help, column);
  }
}

std::string ensure_newline(std::string s) {
  if (!s.empty() && s.back() != '\n') s += '\n';
  return s;
}

}  // namespace

std::string format_rows(const std::string& heading, const std::vector<HelpRow>& rows) {
  std::string out;
  append_rows(out, heading, rows);
  return out.empty() ? out : out.substr(1);  // without the blank line before the heading
}

std::string usage_synopsis(const CommandSpec& spec) {
  std::string s = "ranger_can " + spec.name;
  for (const auto& p : spec.positionals) {
    switch (p.arity) {
      case PositionalSpec::Arity::kRequired:
        s += " " + p.name;
        break;
      case PositionalSpec::Arity::kOptional:
        s += " [" + p.name + "]";
        break;
      case PositionalSpec::Arity::kRest:
        s += " [" + p.name + "...]";
        break;
    }
  }
  if (!spec.options.empty()) s += " [options]";
  return s;
}

std::string help_text(const CommandSpec& spec) {
  std::string out = "usage: " + usage_synopsis(spec) + "\n";
  if (!spec.description.empty()) out += "\n" + ensure_newline(spec.description);
  std::vector<HelpRow> arguments;
  for (const auto& p : spec.positionals)
    arguments.push_back({"  " + p.name, p.help});
  append_rows(out, "arguments", arguments);
  std::vector<HelpRow> options;
  for (const auto& o : spec.options) {
    std::string left = "  ";
    if (o.short_name != 0) left += std::string("-") + o.short_name + ", ";
    left += o.name;
    if (!o.value_name.empty()) left += " " + o.value_name;
    options.push_back({left, o.help + (o.repeatable ? " (repeatable)" : "")});
  }
  options.push_back({"  -h, --help", "this text"});
  append_rows(out, "options", options);
  if (!spec.epilogue.empty()) out += "\n" + ensure_newline(spec.epilogue);
  return out;
}

int usage_error(const CommandSpec& spec, Io io, const std::string& message) {
  io.err << "ranger_can " << spec.name << ": " << message << "\n"
         << "usage: " << usage_synopsis(spec) << "   ('ranger_can " << spec.name
         << " --help' for more)\n";
  return 2;
}

int run_command(const CommandSpec& spec, const Args& args, Io io) {
  ParseOutcome parsed = parse_command_line(spec, args);
  switch (parsed.kind) {
    case ParseOutcome::Kind::kHelp:
      io.out << help_text(spec);
      return 0;
    case ParseOutcome::Kind::kUsageError:
      return usage_error(spec, io, parsed.error);
    case ParseOutcome::Kind::kRun:
      break;
  }
  return spec.run(parsed.args, io);
}

}  // namespace ranger::cli
