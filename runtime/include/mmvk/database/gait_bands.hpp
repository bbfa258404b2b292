// Gait bands: each database frame tagged, at build time, with the band its
// root speed falls in (stand, walk, jog, run) and whether it starts from or
// stops to a stand, so that a controller can choose frames by the commanded
// speed with the search's ordinary tag constraints, on every backend.
//
// The rule, per clip (mirrored copies measure the same):
//   1. speed = the character root's horizontal speed (character.hpp: the
//      hips on the ground), central differences (one-sided at a clip's ends;
//      a looping clip wraps), m/s;
//   2. smoothed by a centred moving average over smoothing_seconds (cut at
//      a non-looping clip's ends, wrapped on a looping one): a walking
//      root speeds up and slows down within each step, by 10-20%;
//   3. banded with hysteresis: the first frame takes the band its smoothed
//      speed lies in; afterwards a band is left upwards only when the speed
//      reaches the next threshold x (1 + hysteresis), downwards only when it
//      falls under the band's own threshold x (1 - hysteresis), so a speed
//      that wavers around a threshold does not flicker between two bands;
//   4. start: a moving frame (walk, jog or run) within transition_seconds
//      after the clip's band was stand; stop: a moving frame within
//      transition_seconds before it becomes stand.
// Bands partition the frames; start and stop overlay them. The tags are the
// names in kGaitTagNames, added after the manifest's own tags (they count
// towards kMaxTags); a manifest tag that begins with kGaitTagPrefix is an
// error naming the field.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/common/status.hpp"

namespace mmvk {

enum class GaitBand : std::uint8_t { Stand, Walk, Jog, Run };
inline constexpr std::size_t kGaitBandCount = 4;

// The measured tags, in this order: the four bands, then start and stop.
// Bit i of a GaitTags value is kGaitTagNames[i].
inline constexpr std::string_view kGaitTagPrefix = "gait:";
inline constexpr std::array<std::string_view, 6> kGaitTagNames = {"gait:stand", "gait:walk", "gait:jog",
                                                                  "gait:run",   "gait:start", "gait:stop"};
inline constexpr std::size_t kGaitStartTag = 4;
inline constexpr std::size_t kGaitStopTag = 5;
using GaitTags = std::uint8_t;

// The manifest's "gait_bands" block; every field optional. Speeds in m/s.
// The defaults: people stand still under ~0.15 m/s (a standing body sways
// its hips at 0.01-0.06 m/s on CMU subject 131), walk up to the walk-run
// transition of adults near 2 m/s, jog up to ~3 m/s and run above.
struct GaitBandParams {
  bool enabled = true;             // false: no measured tags (a manifest out of tags)
  float walk_from_mps = 0.15f;     // below: stand
  float jog_from_mps = 2.0f;       // below: walk
  float run_from_mps = 3.0f;       // below: jog
  float hysteresis = 0.1f;         // fraction of a threshold, in [0, 0.5)
  float smoothing_seconds = 0.25f; // >= 0; 0 = unsmoothed
  float transition_seconds = 1.0f; // > 0: how long after a stand a start lasts, before one a stop
};

// Errors name `where` and the field: a threshold that is not finite or not
// > 0, thresholds out of order (walk_from < jog_from < run_from), a
// hysteresis outside [0, 0.5) or one that makes two thresholds' margins
// overlap, a negative or non-finite smoothing, a transition not > 0.
Status validate_gait_band_params(const GaitBandParams& params, const std::string& where);

// The band a smoothed speed lies in without hysteresis (the first frame's,
// and a controller's reading of a commanded speed).
GaitBand gait_band_of_speed(const GaitBandParams& params, float speed_mps);

// The measured tags of every frame of one clip from its root positions
// ([frames], metres, y ignored) at `fps`. Preconditions: valid params, fps > 0.
std::vector<GaitTags> measure_gait_tags(std::span<const glm::vec3> root_positions, float fps, bool loop,
                                        const GaitBandParams& params);

// The root speeds measure_gait_tags bands (steps 1 and 2), [frames], m/s.
std::vector<float> smoothed_root_speeds(std::span<const glm::vec3> root_positions, float fps, bool loop,
                                        float smoothing_seconds);

}  // namespace mmvk
