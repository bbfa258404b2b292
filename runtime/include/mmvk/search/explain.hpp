// Debug output for one query: why the winner won, what any named frame
// costs channel by channel, and why a frame was not a candidate. It uses
// the reference rules (is_candidate, frame_cost) and the reference search,
// so it explains exactly what every exact backend answers.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// Why a frame is not a candidate: the first rule it fails, in the order
// is_candidate() checks them.
enum class Exclusion : std::uint8_t {
  None,             // a candidate
  DoNotUse,         // kFrameDoNotUse
  EdgeExcluded,     // kFrameEdgeExcluded
  BlockTransition,  // kFrameBlockTransition and not the continuing frame
  MissingTag,       // lacks a tag of require_all
  ExcludedTag,      // carries a tag of exclude_any
  ExclusionWindow,  // within exclusion_window of the continuing frame, same clip
};
inline constexpr std::size_t kExclusionCount = 7;

std::string_view exclusion_name(Exclusion exclusion);
Exclusion exclusion_of(const Database& database, std::uint32_t frame, const QueryParams& params);

struct ChannelCost {
  std::string name;
  float weight = 0.0f;    // the query's channel weight
  float sum = 0.0f;       // sum over the channel's dims of (x - q)^2, in order
  float weighted = 0.0f;  // weight * sum
};

struct FrameExplanation {
  std::uint32_t frame = kNoFrame;
  std::uint32_t clip = 0;
  std::uint32_t frame_in_clip = 0;
  Exclusion exclusion = Exclusion::None;
  std::vector<ChannelCost> channels;  // schema order
  float total = 0.0f;            // sum of weighted channel costs, in order
  float multiplier = 1.0f;       // the clip's
  float bias = 0.0f;             // the clip's
  bool continuing = false;       // this is the query's continuing frame
  float continuing_bias = 0.0f;  // the query's, when this is the continuing frame
  float continuing_multiplier = 1.0f;  // the query's, when this is the continuing frame
  float cost = 0.0f;             // frame_cost(): multiplier * total + bias (then * continuing_multiplier + continuing_bias)
};

struct Explanation {
  std::vector<Match> results;             // the best k (reference search)
  std::vector<FrameExplanation> frames;   // the winner (when there is one), then the named frames
  std::uint32_t candidates = 0;           // frames that may be results
  std::array<std::uint32_t, kExclusionCount> excluded{};  // frames per Exclusion (index 0 unused)
};

// Explains one normalized query [dims]. Errors: those of validate_search,
// and a named frame out of range.
Result<Explanation> explain_query(const Database& database, std::span<const float> query, const QueryParams& params,
                                  std::span<const std::uint32_t> frames, std::uint32_t k = 1);

// A readable multi-line report (clip names, per-channel costs, reasons).
std::string format_explanation(const Database& database, const Explanation& explanation);

}  // namespace mmvk
