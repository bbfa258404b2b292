// Rest frames ranked by stride speed (rest_frames.hpp).
#include "rest_frames.hpp"

#include <limits>

#include "mmvk/features/foot_contacts.hpp"

namespace mmvk::detail {

std::vector<std::uint32_t> find_rest_frames(const Database& database, std::span<const float> stride_speeds,
                                            TagMask require, TagMask exclude) {
  const AnimationData& animation = *database.animation();
  constexpr float kNoBothFeet = 1e6f;  // ranks a frame without both feet down after every one with them
  constexpr float kUnranked = std::numeric_limits<float>::infinity();
  // What a search with these masks could jump to (no continuing frame).
  QueryParams allowed;
  allowed.require_all = require;
  allowed.exclude_any = exclude;
  std::vector<std::uint32_t> rest(database.clips().size(), kNoFrame);
  std::vector<float> clip_ranks(database.clips().size(), kUnranked);
  std::uint32_t best = kNoFrame;
  float best_rank = kUnranked;
  for (std::size_t c = 0; c < database.clips().size(); ++c) {
    const Clip& clip = database.clips()[c];
    for (std::uint32_t f = clip.first_frame; f < clip.first_frame + clip.frame_count; ++f) {
      if (!is_candidate(database, f, allowed)) continue;
      const bool both_feet = both_feet_planted(animation.contacts[f]);
      const float rank = stride_speeds[f] + (both_feet ? 0.0f : kNoBothFeet);
      if (both_feet && rank < clip_ranks[c]) {
        clip_ranks[c] = rank;
        rest[c] = f;
      }
      if (rank < best_rank) {
        best_rank = rank;
        best = f;
      }
    }
  }
  for (std::size_t c = 0; c < rest.size(); ++c) {
    if (rest[c] == kNoFrame || !(clip_ranks[c] <= best_rank + kRestSpeedMargin)) rest[c] = best;
  }
  return rest;
}

}  // namespace mmvk::detail
