#include "measure/run_summary.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "steering/gait_plan.hpp"

namespace mmvk::crowd {

namespace {

// The speeds held commands asked for that the animation did not play
// within 20% (command_meter.hpp), as notes.
void add_missed_speed_notes(CrowdSummary& s) {
  const CommandFigures& c = s.command;
  const struct {
    const CommandFigures::Missed& missed;
    const char* what;
  } kinds[] = {{c.too_fast, "slower"}, {c.too_slow, "faster"}};
  for (const auto& k : kinds) {
    if (k.missed.windows == 0) continue;
    char speeds[64], text[256];
    if (k.missed.max_mps - k.missed.min_mps < 0.005) {
      std::snprintf(speeds, sizeof(speeds), "%.2f", k.missed.min_mps);
    } else {
      std::snprintf(speeds, sizeof(speeds), "%.2f-%.2f", k.missed.min_mps, k.missed.max_mps);
    }
    std::snprintf(text, sizeof(text),
                  "the data lacks %s motion: held commands of %s m/s played more than 20%% %s than asked "
                  "(%llu of %llu 1 s windows), beyond its play-rate and stride bounds",
                  k.what, speeds, k.what[0] == 's' ? "faster" : "slower",
                  static_cast<unsigned long long>(k.missed.windows), static_cast<unsigned long long>(c.windows));
    s.notes.push_back(text);
  }
}

}  // namespace

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
  run.quality.summarize(s);
  add_missed_speed_notes(s);
  s.clips = run.clips.figures;
  s.planted_height_m = run.clips.planted_height;
  s.goals_reached = run.steering.goals_reached();
  return s;
}

}  // namespace mmvk::crowd
