// What the crowd is asked to do: where each character starts, the goal points
// it walks to in turn, how fast it likes to go and which clips it may use.
// Either drawn from a seed (make_random_scenario) or read from JSON:
//
// {
//   "world_size_m": 60,                  // optional: side of the square ground plane
//   "wait_s": 2,                         // optional, default 0: every agent's wait_s unless it sets its own
//   "agents": [
//     { "start": [x, z],                 // metres on the ground plane (Y up)
//       "goals": [[x, z], ...],          // visited in order, then from the first again
//       "speed": "walk" | "run" | 1.3,   // optional, default "walk"; metres/second
//                                        //   when a number, capped to the database's run speed;
//                                        //   "run" on data without a run is an error (gait_plan.hpp)
//       "require_tags": ["walk"],        // optional: every searched frame carries all of them
//       "exclude_tags": ["run"],         // optional: and none of these
//       "wait_s": 1.5 }                  // optional, default the top-level wait_s, else 0: seconds it
//                                        //   stands at each goal (desired velocity 0) before it leaves
//                                        //   for the next; 0 to kMaxGoalWaitS (an hour, crowd_limits.hpp)
//   ]
// }
// Unknown fields, duplicate keys and bytes after the JSON are errors; the
// file is at most 64 MiB (kMaxJsonBytes) and kMaxAgents agents
// (crowd_limits.hpp). Every error names the file and the field:
// "crowd.json: agents[2].goals[1]: expected [x, z] numbers".
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

enum class Gait : std::uint8_t { Walk, Run, Metres };

// The preferred speed: a gait scaled by `value` (Walk, Run), or `value`
// metres/second (Metres). Resolved against the database's speeds later.
struct SpeedPreference {
  Gait gait = Gait::Walk;
  float value = 1.0f;
};

struct AgentPlan {
  std::array<float, 2> start{};               // (x, z), metres
  std::vector<std::array<float, 2>> goals;    // >= 1
  SpeedPreference speed;
  std::vector<std::string> require_tags;
  std::vector<std::string> exclude_tags;
  // Seconds to stand at each goal before leaving for the next (steering.hpp);
  // 0: leave at once, as the crowd always did.
  float wait_s = 0.0f;
  // The gait tag resolve_gaits added to require_tags for the crowd's own
  // steering (gait_plan.hpp), or empty.
  std::string steering_gait_tag;
};

struct Scenario {
  std::string source;        // the file, or "seed N" (for messages and the summary)
  float world_size_m = 0.0f; // side of the square ground plane centred on the origin
  std::vector<AgentPlan> agents;
};

struct RandomScenarioOptions {
  std::uint32_t agents = 1000;
  std::uint64_t seed = 1;
  std::uint32_t goals_per_agent = 8;
  float area_per_agent_m2 = 12.0f;  // sets the world size: sqrt(agents x this)
  float run_fraction = 0.2f;        // share of characters that prefer to run
  float min_goal_distance_m = 5.0f; // each goal lies this far from the previous one ...
  float max_goal_distance_m = 15.0f;// ... up to this, in a random direction
  float wait_s = 0.0f;              // every character's wait at each goal, seconds (AgentPlan::wait_s)
};

// Deterministic for a given seed on every platform (own generator, no
// std:: distributions, whose output is implementation-defined).
Scenario make_random_scenario(const RandomScenarioOptions& options);

Result<Scenario> parse_scenario_json(std::string_view json_text, std::string_view source);
Result<Scenario> load_scenario(const std::filesystem::path& path);

}  // namespace mmvk::crowd
