// One `mmvk crowd` run: a session (crowd_session.hpp: the settings checked,
// the database's motion, the scenario, the controller, the search and the
// observers, set up as mmvk.Crowd sets them up), a loop of its own steering
// at a fixed rate (trace and progress line after each tick) and its outputs.
// The command line is a thin layer over run_crowd().
//
// Each tick (dt = 1 / rate_hz):
//   1. steering: desired velocities from the characters' animated roots
//      (seek the current goal, separate on a uniform grid);
//   2. the controller's deferred tick: apply the previous tick's matches,
//      play, predict, assemble the due characters' queries and submit them
//      as one batch (on Vulkan the search runs while the host goes on);
//   3. outside the timed step: the quality figures, the viewer's samples,
//      the trace and the progress line.
#pragma once

#include <cstdio>

#include "setup/crowd_options.hpp"
#include "mmvk/common/status.hpp"
#include "measure/summary.hpp"

namespace mmvk::crowd {

// Notes for the user (database, device, cache) go to `log` (may be null);
// the progress line goes there too when options.progress is set.
// Errors name the option, file or field at fault.
Result<CrowdSummary> run_crowd(const CrowdOptions& options, std::FILE* log);

}  // namespace mmvk::crowd
