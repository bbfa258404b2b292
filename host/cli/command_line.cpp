#include "command_line.hpp"

#include <cstdio>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_args.hpp"
#include "help_format.hpp"

namespace mmvk::cli {

namespace {

// A bad option value, in the words of cli_args.hpp's parsers.
class ValueError : public CLI::ParseError {
 public:
  ValueError(std::string message, int exit_code) : CLI::ParseError("ValueError", std::move(message), exit_code) {}
};

// "-o,--output" -> "--output": the name the value messages use.
std::string message_name(const std::string& names) { return names.substr(names.rfind(',') + 1); }

}  // namespace

CommandLine::CommandLine(const Command& command, std::string_view description)
    : command_(command.name), app_(std::string(description), "mmvk " + std::string(command.name)) {
  std::string usage = "mmvk " + std::string(command.name);
  if (!command.arguments.empty()) usage += " " + std::string(command.arguments);
  app_.formatter(make_help_formatter(usage + " [options]"));
  // Unknown options and stray arguments are left over and reported in
  // mmvk's words (check_leftovers); CLI11's help flag is added last.
  app_.allow_extras();
  app_.set_help_flag();
  // An option given twice takes its last value, as a shell alias expects.
  app_.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

void CommandLine::positional(const std::string& name, std::string& target) {
  app_.add_option(name, target)->required()->group("");
}

CLI::Option* CommandLine::add(const std::string& names, const std::string& value_name, const std::string& help,
                              std::function<void(const std::string&)> store) {
  return app_.add_option_function<std::string>(names, std::move(store), help)->type_name(value_name)->group(group_);
}

CLI::Option* CommandLine::flag(const std::string& names, bool& target, const std::string& help) {
  return app_.add_flag(names, target, help)->group(group_);
}

void CommandLine::throw_value_error(const std::string& message, int exit_code) { throw ValueError(message, exit_code); }

std::function<Result<std::uint64_t>(const std::string&)> CommandLine::integer_parser(const std::string& names,
                                                                                    std::uint64_t min,
                                                                                    std::uint64_t max) {
  return [name = message_name(names), min, max](const std::string& text) { return parse_integer(name, text, min, max); };
}

std::function<Result<double>(const std::string&)> CommandLine::positive_parser(const std::string& names) {
  return [name = message_name(names)](const std::string& text) { return parse_positive(name, text); };
}

std::function<Result<float>(const std::string&)> CommandLine::finite_parser(const std::string& names) {
  return [name = message_name(names)](const std::string& text) { return parse_float(name, text); };
}

void CommandLine::add_help_flag() {
  if (app_.get_help_ptr() == nullptr) app_.set_help_flag("-h,--help", "show this help")->group("options");
}

std::optional<int> CommandLine::parse(Args args) {
  add_help_flag();
  // CLI11 takes the arguments last first. "--name=" with nothing after the
  // '=' is an empty value here (CLI11 would call it a missing one), which
  // the option's parser names: "--exclusion-window expects ..., got ''".
  std::vector<std::string> reversed;
  for (auto arg = args.rbegin(); arg != args.rend(); ++arg) {
    if (arg->starts_with("--") && arg->find('=') == arg->size() - 1) {
      reversed.emplace_back();
      reversed.emplace_back(arg->substr(0, arg->size() - 1));
    } else {
      reversed.emplace_back(*arg);
    }
  }
  try {
    app_.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    std::fputs(help().c_str(), stdout);
    return 0;
  } catch (const ValueError& error) {
    return report_error(command_, error.what(), error.get_exit_code());
  } catch (const CLI::RequiredError&) {
    return usage_error();  // a missing argument or required option
  } catch (const CLI::ArgumentMismatch& error) {
    // "--k: 1 required TEXT missing": the option was last, or followed by
    // another option.
    const std::string what = error.what();
    return report_error(command_, what.substr(0, what.find(':')) + " needs a value", kUsageExit);
  } catch (const CLI::ParseError& error) {
    return report_error(command_, std::string(error.what()) + " (see mmvk " + command_ + " --help)", kUsageExit);
  }
  return check_leftovers();
}

std::optional<int> CommandLine::check_leftovers() {
  std::vector<std::string> left = app_.remaining();
  // "--" ends the options (POSIX): CLI11 reads what follows as positionals
  // but keeps the "--" itself among the extras, where it was reported as
  // "unknown option '--'".
  std::erase(left, std::string("--"));
  for (const std::string& arg : left) {
    if (arg.size() > 1 && arg[0] == '-') {
      return report_error(command_, "unknown option '" + arg + "' (see mmvk " + command_ + " --help)", kUsageExit);
    }
  }
  if (left.empty()) return std::nullopt;
  const std::string hint = stray_hint_.empty() ? "" : " (" + stray_hint_ + ")";
  std::fprintf(stderr, "mmvk %s: unexpected argument '%s'%s\n\n", command_.c_str(), left[0].c_str(), hint.c_str());
  return usage_error();
}

int CommandLine::usage_error() const {
  std::fputs(help().c_str(), stderr);
  return kUsageExit;
}

}  // namespace mmvk::cli
