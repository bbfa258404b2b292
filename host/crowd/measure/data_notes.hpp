// The summary's notes on what the data cannot do for a run (summary.hpp's
// `notes`), each a sentence for the user:
//   - no idle: the data cannot stand (mmvk/database/gait_coverage.hpp's
//     no_idle_note, the words `mmvk inspect` uses), so a character told to
//     stop or stand holds a frame instead;
//   - speeds the scenario asks for beyond what the data can play: the
//     crowd's own steering's preferred speeds against the data's moving
//     speeds (5th to 95th percentile) scaled by the controller's play-rate
//     and stride bounds (playable_speeds);
//   - speeds the run played more than 20% off a held command
//     (command_meter.hpp's missed speeds), for the crowd's steering or a
//     host's.
// The first two are known before a tick, the last only after.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "measure/command_meter.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/gait_coverage.hpp"

namespace mmvk::crowd {

// The moving speeds the controller plays from the data, m/s: the moving
// frames' 5th percentile x min_play_rate x min_stride_scale to their 95th
// x max_play_rate x max_stride_scale. `known` false when the coverage has
// no moving speeds (not measured, or no moving frames).
struct PlayableSpeeds {
  bool known = false;
  double min_mps = 0.0, max_mps = 0.0;
};
PlayableSpeeds playable_speeds(const GaitCoverage& coverage, const ControllerParams& params);

// The notes known before a tick, in this order: no idle (`bands`:
// Database::gait_bands()), then the preferred speeds ([characters], m/s;
// empty: none asked, as when a host steers) above and below the playable
// speeds.
std::vector<std::string> data_notes(const GaitCoverage& coverage, const GaitBandParams* bands,
                                    const ControllerParams& params, std::span<const float> preferred_mps);

// The notes of the speeds held commands missed (CommandFigures' too_fast and
// too_slow): "the data lacks slower motion: held commands of 0.80 m/s ...".
std::vector<std::string> missed_speed_notes(const CommandFigures& command);

}  // namespace mmvk::crowd
