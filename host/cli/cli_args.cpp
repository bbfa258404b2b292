#include "cli_args.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <unistd.h>

namespace mmvk::cli {

std::optional<std::string> ParsedArgs::value(std::string_view option) const {
  auto it = values.find(option);
  if (it == values.end()) return std::nullopt;
  return it->second;
}

std::optional<ParsedArgs> parse_args(std::string_view command, Args args, const std::set<std::string_view>& with_value,
                                     const std::set<std::string_view>& without_value) {
  ParsedArgs parsed;
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string_view arg = args[i];
    if (arg.size() < 2 || arg[0] != '-') {
      parsed.positional.emplace_back(arg);
      continue;
    }
    std::string_view name = arg;
    std::optional<std::string_view> inline_value;
    if (const std::size_t eq = arg.find('='); eq != std::string_view::npos && arg.starts_with("--")) {
      name = arg.substr(0, eq);
      inline_value = arg.substr(eq + 1);
    }
    if (with_value.count(name)) {
      if (inline_value) {
        parsed.values[std::string(name)] = std::string(*inline_value);
      } else if (i + 1 < args.size()) {
        parsed.values[std::string(name)] = std::string(args[++i]);
      } else {
        std::fprintf(stderr, "mmvk %.*s: %.*s needs a value\n", int(command.size()), command.data(), int(name.size()),
                     name.data());
        return std::nullopt;
      }
    } else if (without_value.count(name) && !inline_value) {
      parsed.flags.insert(std::string(name));
    } else {
      std::fprintf(stderr, "mmvk %.*s: unknown option '%.*s' (see mmvk %.*s --help)\n", int(command.size()),
                   command.data(), int(arg.size()), arg.data(), int(command.size()), command.data());
      return std::nullopt;
    }
  }
  return parsed;
}

std::optional<double> parse_positive(std::string_view command, std::string_view option, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value) || !(value > 0.0)) {
    std::fprintf(stderr, "mmvk %.*s: %.*s expects a positive number, got '%s'\n", int(command.size()), command.data(),
                 int(option.size()), option.data(), text.c_str());
    return std::nullopt;
  }
  return value;
}

std::string thousands(unsigned long long value) {
  std::string digits = std::to_string(value);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

}  // namespace mmvk::cli
