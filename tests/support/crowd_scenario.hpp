// A fixed crowd scenario for controller tests: Bandai locomotion, 50
// characters on a grid, each walking, running or standing in its own
// direction, all turning by 90 degrees at t = 1 s; 2 s at 30 Hz. The run
// records every tick's played frames, so backends can be compared tick by
// tick.
#pragma once

#include <cmath>
#include <filesystem>
#include <functional>
#include <vector>

#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"

namespace mmvk::test {

inline constexpr std::uint32_t kCrowdCharacters = 50;
inline constexpr int kCrowdTicks = 60;
inline constexpr float kCrowdDt = 1.0f / 30.0f;

inline Result<Database> build_locomotion(const std::filesystem::path& data) {
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc/locomotion-normal");
  if (!manifest.ok()) return manifest.error();
  ThreadPool pool(2);
  BuildOptions options;
  options.pool = &pool;
  return build_database(*manifest, options);
}

// The desired velocity of character b at tick t (world, m/s).
inline glm::vec3 crowd_velocity(std::uint32_t b, int tick) {
  const float speeds[] = {1.3f, 3.5f, 0.0f, 1.0f, 2.2f};
  const float angle = 0.7f * float(b) + (tick >= 30 ? 1.5707963f : 0.0f);
  const float speed = speeds[b % 5];
  return {speed * std::sin(angle), 0.0f, speed * std::cos(angle)};
}

struct CrowdRun {
  std::vector<std::uint32_t> frames;  // [ticks x characters]
  std::vector<SearchKind> searched;  // [ticks x characters]
  std::vector<TickStats> ticks;
  TickStats totals;
  float worst_root_gap = 0.0f;  // largest animated-to-simulated root distance, metres
};

// Places the crowd, then runs the ticks; `step` performs one tick (sync or
// deferred, any backend). `observe` (optional) sees the controller after
// every tick.
inline Result<CrowdRun> run_crowd(CrowdController& controller,
                                  const std::function<Status(CrowdController&, const CrowdInput&)>& step,
                                  const std::function<void(const CrowdController&, int)>& observe = {}) {
  const std::uint32_t n = controller.size();
  const std::uint32_t frames = controller.database().frame_count();
  for (std::uint32_t b = 0; b < n; ++b) {
    MMVK_TRY(controller.place(b, glm::vec3(5.0f * float(b % 10), 0.0f, 5.0f * float(b / 10)), 0.3f * float(b),
                              (b * 7919u) % frames));
  }
  CrowdRun run;
  std::vector<glm::vec3> velocities(n);
  for (int t = 0; t < kCrowdTicks; ++t) {
    for (std::uint32_t b = 0; b < n; ++b) velocities[b] = crowd_velocity(b, t);
    MMVK_TRY(step(controller, CrowdInput{velocities, {}}));
    run.frames.insert(run.frames.end(), controller.frames().begin(), controller.frames().end());
    run.searched.insert(run.searched.end(), controller.searched().begin(), controller.searched().end());
    run.ticks.push_back(controller.last_tick());
    for (std::uint32_t b = 0; b < n; ++b) {
      const glm::vec3 gap = controller.simulation()[b].position - controller.root_positions()[b];
      run.worst_root_gap = std::max(run.worst_root_gap, std::sqrt(gap.x * gap.x + gap.z * gap.z));
    }
    if (observe) observe(controller, t);
  }
  run.totals = controller.totals();
  return run;
}

}  // namespace mmvk::test
