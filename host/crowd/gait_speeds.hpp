// The speeds the database can animate, measured from its own trajectory
// features, so that steering never asks for a speed no clip has.
#pragma once

#include "mmvk/database.hpp"
#include "mmvk/status.hpp"

namespace mmvk::crowd {

struct GaitSpeeds {
  float walk_mps = 0.0f;  // typical walking speed
  float run_mps = 0.0f;   // typical running speed; == walk_mps when nothing runs
  float max_mps = 0.0f;   // the cap: the 95th percentile of all frames' speeds
  bool has_run = false;
};

// Speed of a frame = the horizontal distance of its furthest trajectory
// position feature divided by that offset (metres over seconds), taken over
// frames that may be search results. Walk = the median of the speeds in
// [0.4, 2.0) m/s, run = the median of those >= 2.0 m/s (adults switch from
// walking to running near 2 m/s); a gait needs 5% of the moving frames to
// count. Error: no trajectory_position channel, or nothing that moves.
Result<GaitSpeeds> measure_gait_speeds(const Database& database);

}  // namespace mmvk::crowd
