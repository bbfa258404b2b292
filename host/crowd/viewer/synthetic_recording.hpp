// A synthetic but realistic Recording, so the viewer can be built and tested
// without a simulation: agents walk (a few run) circles around their own
// centres, with a procedural 19-joint walk cycle, staggered searches every
// 0.1 s and a jump about once a second; its legs are recorded as displayed
// and each planted foot is locked where its toe touched down; a few
// agents (the first, or a chosen set) also have their whole pose at the simulation rate and made-up
// explanations of their searches.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "output/recording.hpp"

namespace mmvk::crowd {

struct SyntheticRecordingParams {
  std::size_t agents = 50;
  float seconds = 10.0f;
  float sample_rate_hz = 10.0f;
  float simulation_rate_hz = 30.0f;  // also the fps of the synthetic "database"
  float search_interval_s = 0.1f;
  // Agents recorded with their whole pose at the simulation rate, and whose
  // searches are explained (Recording::detail_agents, Recording::why): the
  // first `detail_agents`, or when `detail_set` is not empty its agents
  // (ascending, unique, each below `agents`).
  std::size_t detail_agents = 8;
  std::vector<std::uint32_t> detail_set;
  uint32_t seed = 1234;
};

// Deterministic for a seed. Precondition: positive rates and seconds.
Recording make_synthetic_recording(const SyntheticRecordingParams& params);

}  // namespace mmvk::crowd
