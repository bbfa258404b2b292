// The summary figures that both hosts of the crowd fill the same way:
// `mmvk crowd` (crowd_run.cpp) and the stepped crowd (crowd_session.hpp,
// the Python module's mmvk.Crowd). Each adds what only it knows: the
// database's name, the ticks' timings (TickFigures) and the outputs written.
#pragma once

#include <cstdint>

#include "measure/clip_quality.hpp"
#include "backends/crowd_backend.hpp"
#include "steering/gait_speeds.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database.hpp"
#include "steering/scenario.hpp"
#include "steering/steering.hpp"
#include "measure/summary.hpp"
#include "measure/tick_observers.hpp"

namespace mmvk::crowd {

// What the run is made of, after its ticks, and how it was set up.
struct RunParts {
  const Database& database;
  const Scenario& scenario;
  const GaitSpeeds& speeds;
  const CrowdSearch& search;
  const CrowdController& controller;
  const ControllerParams& params;
  const QualityObserver& quality;
  const ClipQuality& clips;
  const Steering& steering;
  std::uint64_t ticks;
  double rate_hz;
  double search_interval_s;
  std::uint64_t seed;
  bool foot_ik;
  bool speed_from_animation;
};

CrowdSummary summarize_run(const RunParts& run);

}  // namespace mmvk::crowd
