#include "cli_args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <unistd.h>

namespace mmvk::cli {

namespace {
std::string expected(std::string_view option, std::string_view what, std::string_view text) {
  return std::string(option) + " expects " + std::string(what) + ", got '" + std::string(text) + "'";
}
}  // namespace

Result<std::uint64_t> parse_integer(std::string_view option, std::string_view text, std::uint64_t min,
                                    std::uint64_t max) {
  const std::string range = max == std::numeric_limits<std::uint64_t>::max()
                                ? (min == 0 ? "a non-negative integer" : "an integer >= " + std::to_string(min))
                                : "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  std::uint64_t value = 0;
  // from_chars takes no sign, no spaces and no base prefix: "-1", " 2" and
  // "2.5" are errors instead of wrapping around or being cut short.
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc{} || end != text.data() + text.size() || value < min || value > max) {
    return make_error(expected(option, range, text));
  }
  return value;
}

Result<std::uint32_t> parse_u32(std::string_view option, std::string_view text, std::uint32_t min, std::uint32_t max) {
  MMVK_ASSIGN_OR_RETURN(const std::uint64_t value, parse_integer(option, text, min, max));
  return static_cast<std::uint32_t>(value);
}

Result<float> parse_float(std::string_view option, std::string_view text) {
  const std::string copy(text);
  char* end = nullptr;
  const float value = std::strtof(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size() || !std::isfinite(value)) {
    return make_error(expected(option, "a finite number", text));
  }
  return value;
}

Result<double> parse_positive(std::string_view option, std::string_view text) {
  const std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size() || !std::isfinite(value) || !(value > 0.0)) {
    return make_error(expected(option, "a positive number", text));
  }
  return value;
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

Result<std::vector<std::pair<std::string, float>>> parse_weight_list(std::string_view option, const std::string& text) {
  std::vector<std::pair<std::string, float>> weights;
  for (const std::string& item : split_list(text)) {
    const std::size_t equals = item.find('=');
    if (equals == std::string::npos) {
      return make_error(std::string(option) + ": expected CHANNEL=WEIGHT, got '" + item + "'");
    }
    std::string channel = item.substr(0, equals);
    MMVK_ASSIGN_OR_RETURN(const float weight, parse_float(option, item.substr(equals + 1)));
    for (const auto& seen : weights) {
      if (seen.first == channel) return make_error(std::string(option) + ": channel '" + channel + "' is given twice");
    }
    weights.emplace_back(std::move(channel), weight);
  }
  return weights;
}

int report_error(std::string_view command, std::string_view message, int exit_code) {
  std::fprintf(stderr, "mmvk %.*s: %.*s\n", int(command.size()), command.data(), int(message.size()), message.data());
  return exit_code;
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

std::string counted(unsigned long long count, std::string_view noun) {
  return thousands(count) + " " + std::string(noun) + (count == 1 ? "" : "s");
}

std::string progress_bar(double fraction) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * std::clamp(fraction, 0.0, 1.0));
  std::string bar = "[";
  bar.append(static_cast<std::size_t>(filled), '#');
  bar.append(static_cast<std::size_t>(kWidth - filled), '.');
  return bar + "]";
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

}  // namespace mmvk::cli
