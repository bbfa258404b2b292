// The characters the viewer's recording keeps in detail: after every tick
// their whole displayed pose, and every search of theirs explained
// (crowd_recorder.hpp). The others are kept at 10 Hz only, which is what
// keeps a page of 1,000 characters x 20 s within its budget
// (docs/viewer.md, "Size"). `mmvk crowd --detail-agents SPEC` and
// mmvk.Crowd(detail_agents=...) choose them; by default the first
// kDefaultDetailAgents.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// The default: the first 32 characters (fewer in a smaller crowd), which
// keep 1,000 characters x 20 s at 60 Hz within the page's budget.
inline constexpr std::uint32_t kDefaultDetailAgents = 32;

// A choice as the user gave it, before the crowd's size is known: the first
// `count` characters, or the characters of `ranges` (inclusive [first,
// last] pairs, ascending and disjoint).
struct DetailAgents {
  std::optional<std::uint64_t> count;
  std::vector<std::array<std::uint64_t, 2>> ranges;
};

// SPEC: a count N ("32"; "0": none), or a comma-separated list of
// character indices and inclusive ranges ("0-9,42,100-104"; one character
// k alone is "k-k", since "k" is a count), spaces around items allowed.
// Errors name `option`: a malformed item, an empty list, a reversed range,
// a character listed twice.
Result<DetailAgents> parse_detail_agents(std::string_view spec, std::string_view option);
// The same choice from a list of indices, in any order (mmvk.Crowd's
// sequence). Errors name `option`: an empty list, a negative index, a
// character listed twice.
Result<DetailAgents> detail_agents_from_list(std::span<const std::int64_t> indices, std::string_view option);

// The characters chosen in a crowd of `agents`, ascending: `choice`, or
// without one the first kDefaultDetailAgents (fewer in a smaller crowd).
// Errors name `option`: a count or an index beyond the crowd.
Result<std::vector<std::uint32_t>> resolve_detail_agents(const std::optional<DetailAgents>& choice,
                                                         std::uint64_t agents, std::string_view option);
// How many characters that is, without listing them (for the memory
// estimate; clamped to the crowd, whose excess resolve_detail_agents refuses).
std::uint64_t detail_agent_count(const std::optional<DetailAgents>& choice, std::uint64_t agents);

}  // namespace mmvk::crowd
