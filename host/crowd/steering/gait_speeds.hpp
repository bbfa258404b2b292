// The speeds the database can animate, measured from its own trajectory
// features, so that steering never asks for a speed no clip has; and whether
// it can run at all.
#pragma once

#include <string>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

struct GaitSpeeds {
  float walk_mps = 0.0f;  // typical walking speed
  float run_mps = 0.0f;   // typical running speed; 0 when nothing runs (has_run false)
  float max_mps = 0.0f;   // the cap: the 95th percentile of all frames' speeds
  bool has_run = false;
  // Both gaits are tagged ("walk" and "run") and the run separates: walkers
  // and runners each search the frames of their own tag.
  bool tagged = false;
  // Why there is no run, for the user (empty when has_run).
  std::string no_run_reason{};
};

// The tags a database names its gaits with.
inline constexpr const char* kWalkTag = "walk";
inline constexpr const char* kRunTag = "run";

// Speed of a frame = the horizontal distance of its furthest trajectory
// position feature divided by that offset (metres over seconds), taken over
// frames that may be search results. Frames below 0.4 m/s stand or shuffle
// and count for neither gait.
//
// With both a "walk" and a "run" tag: walk = the median speed of the moving
// frames tagged walk, run = that of the moving frames tagged run, and the
// run counts when its median is at least 2 m/s (adults switch from walking
// to running near 2 m/s) and 1.25 x the walk's. Otherwise by speed alone:
// walk = the median of the speeds in [0.4, 2.0) m/s, run = the median of
// those >= 2.0 m/s, and a gait needs 5% of the moving frames to count. A
// database with a "run" tag whose frames do not separate, or without one
// whose speeds do not, has no run: run_mps 0 and no_run_reason says why.
// Error: no trajectory_position channel, or nothing that moves.
Result<GaitSpeeds> measure_gait_speeds(const Database& database);

}  // namespace mmvk::crowd
