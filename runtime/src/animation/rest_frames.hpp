// The frame a character comes to rest on where the data has no idle
// (crowd_controller_gait.cpp): in each clip, its slowest frame with both
// feet down, unless that is far faster than the slowest of all.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"

namespace mmvk::detail {

// How much faster (stride speed, m/s) than the best of all a clip's own
// rest frame may be and still be its rest. Within it a character rests in
// the clip it plays, which blends least; beyond it (a run, whose slowest
// double support is still mid-stride) on the best of all.
inline constexpr float kRestSpeedMargin = 0.25f;

// The frame to rest on in each clip, [clips], among the frames a search with
// these masks could jump to: both feet planted and the lowest stride speed
// (stride_speeds, [frames] m/s). A clip without such a frame, or whose best
// is more than kRestSpeedMargin faster than the best of all, rests on the
// best of all (with both feet down if any frame has them, else the
// slowest); kNoFrame everywhere when no frame is allowed.
std::vector<std::uint32_t> find_rest_frames(const Database& database, std::span<const float> stride_speeds,
                                            TagMask require, TagMask exclude);

}  // namespace mmvk::detail
