// Small shared helpers for the mmvk subcommands: the parsers of option values
// (command_line.hpp declares the options with them) and output.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mmvk/common/status.hpp"

namespace mmvk::cli {

// Number parsing for every command, in one place: the whole text must be
// the number, and the error message names the option and what it expects
// ("--k expects an integer in [1, 16], got 'x'").
Result<std::uint64_t> parse_integer(std::string_view option, std::string_view text, std::uint64_t min = 0,
                                    std::uint64_t max = std::numeric_limits<std::uint64_t>::max());
Result<std::uint32_t> parse_u32(std::string_view option, std::string_view text, std::uint32_t min = 0,
                                std::uint32_t max = std::numeric_limits<std::uint32_t>::max());
// A finite float.
Result<float> parse_float(std::string_view option, std::string_view text);
// A finite number > 0.
Result<double> parse_positive(std::string_view option, std::string_view text);

// "a,b,,c" -> {"a", "b", "c"}.
std::vector<std::string> split_list(const std::string& text);
// "CHANNEL=W,CHANNEL=W" -> (channel, weight) pairs, each weight a finite
// float; a malformed item or a channel named twice is an error naming `option`.
Result<std::vector<std::pair<std::string, float>>> parse_weight_list(std::string_view option, const std::string& text);

// Prints "mmvk <command>: <message>" to stderr and returns `exit_code`.
int report_error(std::string_view command, std::string_view message, int exit_code);

// "1,234,567"
std::string thousands(unsigned long long value);

// "1 clip", "0 clips", "1,234 clips": the count with thousands separators and
// the noun in the singular only for exactly one.
std::string counted(unsigned long long count, std::string_view noun);

// "[#########.....................]": `fraction` of 30 cells (clamped to
// [0, 1]), for the progress lines of long commands.
std::string progress_bar(double fraction);

bool stderr_is_terminal();

}  // namespace mmvk::cli
