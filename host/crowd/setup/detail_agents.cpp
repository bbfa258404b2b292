#include "setup/detail_agents.hpp"

#include <algorithm>
#include <charconv>

namespace mmvk::crowd {

namespace {

constexpr const char* kExpected = "expected a count N or a list of indices and ranges such as 0-9,42,100-104";

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(' ');
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(' ') - first + 1);
}

// Digits only: from_chars alone would take a sign-less prefix of "3x".
std::optional<std::uint64_t> whole_number(std::string_view text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string_view::npos) return std::nullopt;
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  return value;
}

// "A" or "A-B" as an inclusive range.
std::optional<std::array<std::uint64_t, 2>> parse_item(std::string_view item) {
  const auto dash = item.find('-');
  const auto first = whole_number(dash == std::string_view::npos ? item : item.substr(0, dash));
  const auto last = dash == std::string_view::npos ? first : whole_number(item.substr(dash + 1));
  if (!first || !last) return std::nullopt;
  return std::array<std::uint64_t, 2>{*first, *last};
}

// Sorted by their first character, ranges that overlap name a character
// listed twice.
Result<DetailAgents> from_ranges(std::vector<std::array<std::uint64_t, 2>> ranges, const std::string& named) {
  std::sort(ranges.begin(), ranges.end());
  for (std::size_t i = 1; i < ranges.size(); ++i) {
    if (ranges[i][0] <= ranges[i - 1][1]) {
      return make_error(named + ": character " + std::to_string(ranges[i][0]) + " is listed twice");
    }
  }
  DetailAgents choice;
  choice.ranges = std::move(ranges);
  return choice;
}

}  // namespace

Result<DetailAgents> parse_detail_agents(std::string_view spec, std::string_view option) {
  const std::string named = std::string(option) + " '" + std::string(spec) + "'";
  const std::string_view text = trimmed(spec);
  if (text.empty()) return make_error(named + ": an empty list; " + kExpected);
  if (text.find_first_of(",-") == std::string_view::npos) {
    const auto count = whole_number(text);
    if (!count) return make_error(named + ": " + kExpected);
    DetailAgents choice;
    choice.count = *count;
    return choice;
  }
  std::vector<std::array<std::uint64_t, 2>> ranges;
  for (std::size_t begin = 0; begin <= text.size();) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    const std::string_view item = trimmed(text.substr(begin, comma - begin));
    const auto range = parse_item(item);
    if (!range) {
      // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive)
      // on "'" + std::string(item).
      std::string message = named + ": ";
      if (item.empty()) {
        message += "an empty item";
      } else {
        message.append("'").append(item).append("'");
      }
      return make_error(message + " is not an index or a range A-B; " + kExpected);
    }
    if ((*range)[1] < (*range)[0]) {
      return make_error(named + ": the range " + std::string(item) + " runs backwards; write it " +
                        std::to_string((*range)[1]) + "-" + std::to_string((*range)[0]));
    }
    ranges.push_back(*range);
    begin = comma + 1;
  }
  return from_ranges(std::move(ranges), named);
}

Result<DetailAgents> detail_agents_from_list(std::span<const std::int64_t> indices, std::string_view option) {
  const std::string named(option);
  if (indices.empty()) return make_error(named + ": an empty list; give a count N or character indices");
  std::vector<std::array<std::uint64_t, 2>> ranges;
  ranges.reserve(indices.size());
  for (const std::int64_t index : indices) {
    if (index < 0) return make_error(named + ": " + std::to_string(index) + " is not a character index");
    ranges.push_back({std::uint64_t(index), std::uint64_t(index)});
  }
  return from_ranges(std::move(ranges), named);
}

Result<std::vector<std::uint32_t>> resolve_detail_agents(const std::optional<DetailAgents>& choice,
                                                         std::uint64_t agents, std::string_view option) {
  std::vector<std::uint32_t> chosen;
  if (!choice || choice->count) {
    const std::uint64_t count = choice ? *choice->count : std::min<std::uint64_t>(kDefaultDetailAgents, agents);
    if (count > agents) {
      return make_error(std::string(option) + " " + std::to_string(count) + ": the crowd has " +
                        std::to_string(agents) + " characters");
    }
    for (std::uint64_t b = 0; b < count; ++b) chosen.push_back(std::uint32_t(b));
    return chosen;
  }
  // Ascending: the last range holds the largest index.
  if (!choice->ranges.empty() && choice->ranges.back()[1] >= agents) {
    const std::string crowd = agents == 0 ? "it has no characters" : "0 to " + std::to_string(agents - 1);
    return make_error(std::string(option) + ": character " + std::to_string(choice->ranges.back()[1]) +
                      " is beyond the crowd (" + crowd + ")");
  }
  for (const auto& range : choice->ranges) {
    for (std::uint64_t b = range[0]; b <= range[1]; ++b) chosen.push_back(std::uint32_t(b));
  }
  return chosen;
}

std::uint64_t detail_agent_count(const std::optional<DetailAgents>& choice, std::uint64_t agents) {
  if (!choice) return std::min<std::uint64_t>(kDefaultDetailAgents, agents);
  if (choice->count) return std::min(*choice->count, agents);
  std::uint64_t count = 0;
  for (const auto& range : choice->ranges) {
    if (range[0] < agents) count += std::min(range[1], agents - 1) - range[0] + 1;
  }
  return std::min(count, agents);
}

}  // namespace mmvk::crowd
