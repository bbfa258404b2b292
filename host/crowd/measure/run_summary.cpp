#include "measure/run_summary.hpp"

#include <cmath>
#include <span>
#include <string>

#include "measure/data_notes.hpp"
#include "mmvk/database/gait_coverage.hpp"
#include "steering/gait_plan.hpp"

namespace mmvk::crowd {

CrowdSummary summarize_run(const RunParts& run) {
  CrowdSummary s;
  s.agents = run.controller.size();
  s.ticks = run.ticks;
  s.seconds = double(run.ticks) / run.rate_hz;
  s.rate_hz = run.rate_hz;
  s.search_interval_s = run.search_interval_s;
  s.seed = run.seed;
  s.scenario = run.scenario.source;
  s.database_frames = run.database.frame_count();
  s.walk_mps = run.speeds.walk_mps;
  s.run_mps = run.speeds.has_run ? run.speeds.run_mps : std::nan("");  // null in the JSON
  s.runners = count_runners(run.scenario);
  if (!run.speeds.has_run) {
    s.notes.push_back("run_mps is null: the data has no run (" + run.speeds.no_run_reason + ")");
  }
  s.backend = std::string(run.search.backend->name());
  s.device = run.search.device;
  s.backend_choice = run.search.choice;
  s.forced_searches = run.controller.totals().forced;
  s.no_candidate = run.controller.totals().no_candidate;
  s.foot_ik = run.foot_ik;
  s.speed_from_animation = run.speed_from_animation;
  // 0.07, not 0.0700000003.
  s.correction_half_life_s = std::round(double(run.params.correction_half_life) * 1e6) / 1e6;
  // What the data lacks for this crowd: the scenario's speeds only when the
  // crowd's own steering asked for them (a host's commands are measured
  // instead, below).
  const std::span<const float> preferred =
      run.steering.updates() > 0 ? run.steering.preferred_speeds() : std::span<const float>();
  for (std::string& note : data_notes(measure_gait_coverage(run.database), run.database.gait_bands(), run.params,
                                      preferred)) {
    s.notes.push_back(std::move(note));
  }
  run.quality.summarize(s);
  for (std::string& note : missed_speed_notes(s.command)) s.notes.push_back(std::move(note));
  s.clips = run.clips.figures;
  s.planted_height_m = run.clips.planted_height;
  s.goals_reached = run.steering.goals_reached();
  return s;
}

}  // namespace mmvk::crowd
