// The bounds a crowd checks before any work (docs/files-and-limits.md;
// validate() in crowd_settings.hpp checks the settings against them): the
// time options, the tick count and the memory a run would need. Without
// them `--rate 1e-6` stepped the controller through a million frames a tick,
// `--seconds 0.01` ran 0 ticks and printed nan figures, and the documented
// maximum --agents died of an uncaught bad_alloc after about 9 GB.
#pragma once

#include <cstdint>
#include <string>

#include "setup/crowd_settings.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "steering/scenario.hpp"

namespace mmvk::crowd {

// --agents and a scenario's agent count: the controller searches every
// character in one batch, so at most the search's batch limit.
inline constexpr std::uint32_t kMaxAgents = std::uint32_t(kMaxBatch);
// --rate, Hz: a tick of at most 1 s (the controller plays at most one
// second of motion per tick) and at least 1 ms.
inline constexpr double kMinRateHz = 1.0;
inline constexpr double kMaxRateHz = 1000.0;
// --search-interval, seconds.
inline constexpr double kMinSearchIntervalS = 0.001;
inline constexpr double kMaxSearchIntervalS = 3600.0;
// --wait-at-goals and a scenario's wait_s, seconds at each goal: 0 to an
// hour; more is a typo (milliseconds given as seconds), not a plan.
inline constexpr double kMaxGoalWaitS = 3600.0;
// round(--seconds x --rate): at least one tick, at most this many.
inline constexpr std::uint64_t kMaxTicks = 10'000'000;
// The share of the memory limit (memory_limit_bytes) a run may plan to use;
// the rest is left to the system and to what the estimate leaves out.
inline constexpr double kMemoryShare = 0.8;

// round(seconds x rate), after validate().
std::uint64_t tick_count(const CrowdSettings& settings);

// What a run keeps besides its characters, for the memory estimate.
struct RunOutputs {
  bool html = false;              // the viewer's recording of settings.seconds
  std::uint32_t trace_agents = 0;  // characters traced every tick; 0: no trace
  std::uint32_t export_agents = 0;  // characters whose poses are exported (--bvh, --gltf); 0: none
  // A scenario file still to be read: its count is checked once it is loaded.
  bool scenario_file = false;
};

// The bytes a run of `agents` characters over `database` with `options`
// allocates, over-estimated: the controller and its inertializer, the
// host's per-character arrays, the search's batch buffers, the quality
// meter, the per-tick timings and, with --html, the recording and the page.
std::uint64_t estimate_crowd_bytes(const CrowdSettings& settings, const RunOutputs& outputs, const Database& database,
                                   std::uint64_t agents, std::uint64_t goals);
// The memory this process may use: the smallest of the physical memory,
// the cgroup's memory.max and RLIMIT_AS / RLIMIT_DATA.
std::uint64_t memory_limit_bytes();
// Refuses a run whose estimate is over kMemoryShare of the limit, with both
// figures and what to lower, named as `names` says. `scenario` null: the
// random scenario settings.agents would draw, checked before it is drawn (a
// file scenario is checked once loaded; its size is capped by the file's).
Status check_crowd_memory(const CrowdSettings& settings, const RunOutputs& outputs, const Database& database,
                          const Scenario* scenario, SettingNames names);

}  // namespace mmvk::crowd
