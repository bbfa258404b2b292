// What a database's frames can do, read from its measured gait tags
// (gait_bands.hpp): whether it can stand (and on how many frames with both
// feet planted), which speed bands it covers, whether it has starts and
// stops. `mmvk inspect` prints it; a controller can ask the same before it
// commands a stand.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "mmvk/database/database.hpp"

namespace mmvk {

// A database can stand (hold an idle) when one of its clips does: a looping
// clip whose every frame stands, or this long a run of consecutive stand
// candidates. Frames that merely pass under the threshold (the first steps of
// a walk that starts from rest) are no idle.
inline constexpr float kMinIdleSeconds = 0.5f;

struct GaitCoverage {
  bool measured = false;  // the database carries the gait tags (Database::gait_bands)
  // Candidate frames (neither do-not-use nor edge-excluded) per band, and
  // those tagged start and stop.
  std::array<std::uint64_t, kGaitBandCount> band_frames{};
  std::uint64_t start_frames = 0;
  std::uint64_t stop_frames = 0;
  // Candidate stand frames with both feet planted (the animation's contact
  // bits); 0 without an animation section.
  std::uint64_t stand_both_feet_frames = 0;
  bool has_contacts = false;
  float longest_stand_seconds = 0.0f;  // the longest run of consecutive stand candidates in a clip
  bool stand_loop = false;             // a looping clip stands on every frame
  // The root speed (smoothed as the bands are) of candidate frames: the 5th
  // and 95th percentiles of the moving ones, m/s; 0 without an animation
  // section or moving frames.
  float moving_p5_mps = 0.0f;
  float moving_p95_mps = 0.0f;

  bool can_stand() const { return stand_loop || longest_stand_seconds >= kMinIdleSeconds; }
};

// The bit of each measured tag in a database (kGaitTagNames' order), 0 where
// a name is missing; all: their union.
struct GaitTagBits {
  std::array<TagMask, kGaitTagNames.size()> bit{};
  TagMask all = 0;
};
GaitTagBits gait_tag_bits(const Database& database);

// Over the candidate frames whose tags include all of require_all and none
// of exclude_any (a character's own tags; 0 and 0: every candidate).
GaitCoverage measure_gait_coverage(const Database& database, TagMask require_all = 0, TagMask exclude_any = 0);

// One line for people and help text, the same facts in the same words:
// "stands: yes, starts: no, stops: yes, speeds: walk, jog, run" (the moving
// bands with candidate frames);
// "stands" is can_stand(); "not measured (a database built before format 7 or with gait_bands off)".
std::string gait_capabilities(const GaitCoverage& coverage);

// The long form for `mmvk inspect`: frame counts per band, the standing
// frames with both feet down, the speed range, and what the data lacks
// ("the data has no idle: ...").
std::string describe_gait_coverage(const GaitCoverage& coverage, const GaitBandParams* params);

// What the data lacks to stand, one line in the words of
// describe_gait_coverage ("the data has no idle: ..., a character told to
// stop or stand must hold a frame instead"), for every report that says it
// (`mmvk inspect`, the crowd summary's notes); empty when it can stand.
// Unmeasured coverage has no idle known either, and says why.
std::string no_idle_note(const GaitCoverage& coverage, const GaitBandParams* params);

}  // namespace mmvk
