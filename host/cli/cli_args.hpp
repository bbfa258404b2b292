// Small shared helpers for the mmvk subcommands: option parsing and output.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "commands.hpp"

namespace mmvk::cli {

struct ParsedArgs {
  std::vector<std::string> positional;
  std::map<std::string, std::string, std::less<>> values;  // "--fps" -> "30"
  std::set<std::string, std::less<>> flags;                // "--mirror"

  bool has(std::string_view flag) const { return flags.count(flag) != 0; }
  std::optional<std::string> value(std::string_view option) const;
};

// Parses `args`: options in `with_value` take the next argument (or
// "--opt=value"), those in `without_value` are flags; anything else starting
// with '-' is an error. Returns nullopt after printing "mmvk <command>: ..."
// to stderr.
std::optional<ParsedArgs> parse_args(std::string_view command, Args args, const std::set<std::string_view>& with_value,
                                     const std::set<std::string_view>& without_value);

// Parses a positive finite number, or prints an error naming the option.
std::optional<double> parse_positive(std::string_view command, std::string_view option, const std::string& text);

// "1,234,567"
std::string thousands(unsigned long long value);

bool stderr_is_terminal();

}  // namespace mmvk::cli
