// Fills the viewer's Recording (recording.hpp) while a crowd runs: the
// sampled roots, frames, desired trajectories and legs as displayed, each
// search and each change of the feet (contacts, locks) as an event, the
// whole displayed pose of a few characters (--detail-agents,
// setup/detail_agents.hpp) after every tick and why each of their searches
// chose its frame, and at the end the
// character-space poses of every frame that was played.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/animation/crowd_controller.hpp"
#include "output/recording.hpp"
#include "steering/scenario.hpp"
#include "output/search_why.hpp"

namespace mmvk::crowd {

class CrowdRecorder {
 public:
  // Records every `ticks_per_sample`-th tick (ticks of `dt` seconds), and
  // every tick of the characters `detail_agents` (ascending, unique, each
  // below controller.size(): resolve_detail_agents).
  CrowdRecorder(const CrowdController& controller, const Scenario& scenario, std::string title, float dt,
                std::uint32_t ticks_per_sample, std::vector<std::uint32_t> detail_agents);

  // After each tick `tick` (0-based, its end at (tick + 1) * dt):
  // `collected` are the matches the tick applied, for the characters that
  // searched in the tick before (`searched_before`, ascending), with that
  // tick's CrowdController::searched() (`kinds_before`, [characters]:
  // SearchKind::Forced marks a forced search), `frames_before` the frames they played when
  // they searched, and `world` the displayed world joint positions
  // [characters x joints] after the tick (CrowdController::world_positions).
  void record_tick(std::uint64_t tick, std::span<const Match> collected,
                   std::span<const std::uint32_t> searched_before, std::span<const SearchKind> kinds_before,
                   std::span<const std::uint32_t> frames_before, std::span<const glm::vec3> world);

  // After record_tick: the batch the tick submitted, query i searched by
  // character characters[i] (ascending).
  void record_submitted(std::span<const std::uint32_t> characters, const QueryBatch& batch) {
    why_.submitted(characters, batch);
  }

  // Adds the poses of the frames seen and the searches explained, and
  // returns the recording. Errors: those of explain_query.
  Result<Recording> finish(ThreadPool& pool);

 private:
  void sample(std::span<const glm::vec3> world);
  void sample_detail(std::span<const glm::vec3> world);
  void record_feet(float time_s);

  const CrowdController& controller_;
  Recording recording_;
  float dt_;
  std::uint32_t ticks_per_sample_;
  std::vector<std::uint8_t> frame_seen_;  // [database frames]
  // The database's trajectory_position features, to draw the matched
  // trajectory: first dim of each offset's (x, z), or empty.
  std::vector<std::uint32_t> matched_dims_;
  std::vector<FootEvent> feet_now_;  // [characters] the state of the last event
  SearchWhyRecorder why_;
};

}  // namespace mmvk::crowd
