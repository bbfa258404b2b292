// One subcommand's command line: its options declared once (CLI11), the help
// text generated from those declarations, and every parse error reported as
// "mmvk COMMAND: ..." with the command's exit code.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::cli {

// The exit code of a usage error: an unknown option, a missing argument, a
// bad value.
inline constexpr int kUsageExit = 2;

class CommandLine {
 public:
  // `description`: the paragraph under the usage line, word-wrapped.
  CommandLine(const Command& command, std::string_view description);

  // Options declared next are listed under `name` in the help ("options"
  // until the first call).
  void group(std::string name) { group_ = std::move(name); }
  // The exit code of a bad value for the options declared next (kUsageExit
  // until the first call): some commands report bad values as failures (1).
  void value_error_exit(int code) { value_exit_ = code; }
  // The sections after the option list, verbatim; made only when the help
  // is shown.
  void footer(std::function<std::string()> make) { app_.footer(std::move(make)); }
  // Said after "unexpected argument 'X'" for a stray positional argument.
  void stray_argument_hint(std::string hint) { stray_hint_ = std::move(hint); }

  // A required positional argument, listed in the usage line only.
  void positional(const std::string& name, std::string& target);

  // `names`: "--out" or "-o,--output"; `value_name`: "FILE" in the help.
  // `target`: a std::string, or a std::optional of a string or a path.
  template <typename Target>
  CLI::Option* text(const std::string& names, Target& target, const std::string& value_name, const std::string& help) {
    return add(names, value_name, help, [&target](const std::string& text) { target = text; });
  }
  CLI::Option* flag(const std::string& names, bool& target, const std::string& help);

  // A value converted by `convert` (cli_args.hpp's parsers): its error
  // message is reported as is, with the exit code set by value_error_exit.
  template <typename Target, typename Convert>
  CLI::Option* value(const std::string& names, Target& target, const std::string& value_name, const std::string& help,
                     Convert convert) {
    const int exit_code = value_exit_;
    return add(names, value_name, help, [&target, convert, exit_code](const std::string& text) {
      auto converted = convert(text);
      if (!converted) throw_value_error(converted.message(), exit_code);
      target = static_cast<Target>(std::move(*converted));
    });
  }

  // An integer in [min, max]: "--k expects an integer in [1, 16], got 'x'".
  template <typename Target>
  CLI::Option* integer(const std::string& names, Target& target, const std::string& value_name,
                       const std::string& help, std::uint64_t min = 0,
                       std::uint64_t max = std::numeric_limits<std::uint32_t>::max()) {
    return value(names, target, value_name, help, integer_parser(names, min, max));
  }
  // A finite number > 0: "--fps expects a positive number, got '0'".
  template <typename Target>
  CLI::Option* positive(const std::string& names, Target& target, const std::string& value_name,
                        const std::string& help) {
    return value(names, target, value_name, help, positive_parser(names));
  }
  // A finite float: "--continuing-bias expects a finite number, got 'nan'".
  template <typename Target>
  CLI::Option* finite(const std::string& names, Target& target, const std::string& value_name,
                      const std::string& help) {
    return value(names, target, value_name, help, finite_parser(names));
  }

  // Parses `args`. Returns the exit code to end with when the command must
  // not run (its help was asked for: 0, printed to stdout; a usage error:
  // reported on stderr), else nullopt.
  std::optional<int> parse(Args args);

  // Whether the option named `name` ("--nprobe") was given.
  bool given(const std::string& name) const { return app_.count(name) > 0; }

  // The help, generated from the declarations.
  std::string help() const { return app_.help(); }
  // A usage error the declarations cannot express (one of two options):
  // prints the help to stderr and returns kUsageExit.
  int usage_error() const;

 private:
  CLI::Option* add(const std::string& names, const std::string& value_name, const std::string& help,
                   std::function<void(const std::string&)> store);
  [[noreturn]] static void throw_value_error(const std::string& message, int exit_code);
  // The help flag, added last so that the help lists it last.
  void add_help_flag();
  static std::function<Result<std::uint64_t>(const std::string&)> integer_parser(const std::string& names,
                                                                                 std::uint64_t min, std::uint64_t max);
  static std::function<Result<double>(const std::string&)> positive_parser(const std::string& names);
  static std::function<Result<float>(const std::string&)> finite_parser(const std::string& names);
  // Reports a stray argument or an unknown option left over by the parse.
  std::optional<int> check_leftovers();

  std::string command_;
  CLI::App app_;
  std::string group_ = "options";
  int value_exit_ = kUsageExit;
  std::string stray_hint_;
};

}  // namespace mmvk::cli
