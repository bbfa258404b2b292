#include "setup/crowd_limits.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mmvk/common/file_io.hpp"
#include "mmvk/common/number_text.hpp"
#include "mmvk/query/query_assembly.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/animation/trajectory.hpp"
#include "setup/crowd_defaults.hpp"
#include "output/recording.hpp"

namespace mmvk::crowd {

namespace {

std::string gib(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f GiB", double(bytes) / double(std::uint64_t{1} << 30));
  return text;
}

// cgroup v2's limit for this process's group ("max" or bytes); none when
// the file is absent (cgroup v1, no limit, not Linux).
std::uint64_t cgroup_limit() {
  const Result<std::string> text = read_file("/sys/fs/cgroup/memory.max", ReadOptions{4096, false});
  if (!text) return std::numeric_limits<std::uint64_t>::max();
  std::uint64_t value = 0;
  const char* first = text->data();
  const auto [end, error] = std::from_chars(first, first + text->size(), value);
  return error == std::errc{} && end != first ? value : std::numeric_limits<std::uint64_t>::max();
}

std::uint64_t rlimit_bytes(int resource) {
  struct rlimit limit {};
  if (::getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) {
    return std::numeric_limits<std::uint64_t>::max();
  }
  return std::uint64_t(limit.rlim_cur);
}

// Trajectory points per character: the controller predicts each distinct
// offset once, and the trajectory channels share theirs (positions and
// directions at the same times): the longest list, at least one.
std::uint64_t trajectory_points(const Database& database) {
  std::uint64_t points = 1;
  for (const FeatureChannel& channel : database.schema().channels) {
    points = std::max<std::uint64_t>(points, channel.offsets_seconds.size());
  }
  return points;
}

}  // namespace

std::uint64_t tick_count(const CrowdSettings& options) {
  return std::uint64_t(std::llround(options.seconds * options.rate_hz));
}

// Measured against the peak resident size (/usr/bin/time) on the shipped
// CMU walks (5,752 frames, 31 joints, fast-box, foot IK on): 100,000
// agents for 2 s used 726 MiB (estimate 863), 1,543 MiB with --html
// (estimate 2,257); 20,000 agents for 20 s 159 MiB (estimate 227) and
// 1,614 MiB with --html (estimate 2,831); 1,000 agents for 2 s 23 MiB
// (estimate 76). Over, never under; the per-joint term is the one to
// revisit when the controller keeps more per joint.
std::uint64_t estimate_crowd_bytes(const CrowdSettings& options, const RunOutputs& outputs, const Database& database,
                                   std::uint64_t agents, std::uint64_t goals) {
  const std::uint64_t joints = database.animation() ? database.animation()->joint_count() : 1;
  const std::uint64_t dims = database.dims();
  const std::uint64_t points = trajectory_points(database);
  const std::uint64_t params = sizeof(QueryParams);
  const std::uint64_t ticks = tick_count(options);
  // The controller: its per-character state, two copies of the query
  // parameters, the predicted trajectory, the batch, and per joint the
  // animated and displayed poses, their world positions, the inertializer's
  // offsets and velocities, the interpolation and foot locking (measured:
  // about 170 bytes per joint in all).
  const std::uint64_t controller = 200 + sizeof(SimulationState) + sizeof(QueryFrame) + 2 * params + points * 16 +
                                   joints * 180 + dims * 4;
  // crowd_run's per-tick arrays, world positions per joint, steering, the
  // scenario's plan and the quality meter's 1 s ring.
  const std::uint64_t host = 160 + joints * 12 + 40 + 160 + std::uint64_t(std::llround(options.rate_hz)) * 8;
  // The search: each slot's queries, parameters and results (two slots on
  // Vulkan, where the host also stages them).
  const std::uint64_t search = 3 * (dims * 4 + params + 16);
  // 64 MiB for the process itself: code, libraries, thread stacks, allocator slack.
  std::uint64_t bytes = (std::uint64_t{64} << 20) + agents * (controller + host + search) + goals * 8 * 3 + ticks * 16;
  // The database as loaded (features, per-frame arrays, animation) and the
  // backend's copy or upload of the features.
  const std::uint64_t frames = database.frame_count();
  bytes += frames * (dims * 4 * 2 + 32 + joints * 16 + 24);
  if (outputs.html) {
    // The recording: every sample of every character (root, facing, frame,
    // desired and matched trajectories, up to 6 displayed leg joints), each
    // search and foot change as an event, the poses of the frames played;
    // encoding the page holds the recording, its raw and deflated payload,
    // the base64 text and the page, at most about four recordings' worth at
    // once (measured above).
    const std::uint64_t per_sample = std::max<std::uint64_t>(1, std::uint64_t(std::llround(options.rate_hz / 10.0)));
    const std::uint64_t samples = ticks / per_sample + 1;
    const auto searches = std::uint64_t(std::ceil(options.seconds / options.search_interval_s)) + 2;
    const auto steps = std::uint64_t(std::ceil(options.seconds * 8.0)) + 2;
    // The detailed characters (--detail-agents) also keep their whole pose
    // after every tick, and each of their searches its query until it is
    // explained and then its two frames' channel costs (crowd_recorder.hpp).
    const std::uint64_t detailed = detail_agent_count(options.detail_agents, agents);
    const std::uint64_t channels = database.schema().channels.size();
    const std::uint64_t recording =
        agents * (samples * (16 + points * 16 + 6 * 12) + searches * sizeof(SearchEvent) + steps * 16 + 48) +
        frames * joints * 12 +
        detailed * ((ticks + 1) * joints * 12 + searches * (dims * 4 + params + 160 + channels * 12));
    bytes += recording * 4;
  }
  if (outputs.trace_agents > 0) {
    // --trace: the traced characters' world joints and contact bits per tick.
    bytes += ticks * std::min<std::uint64_t>(outputs.trace_agents, agents) * (joints * 12 + 2);
  }
  if (outputs.export_agents > 0) {
    // --bvh / --gltf: the exported characters' roots and local poses per
    // tick (pose_recording.hpp), and while the glTF is written its binary
    // chunk and the file, each about the recording's size (a BVH is smaller).
    bytes += 3 * ticks * std::min<std::uint64_t>(outputs.export_agents, agents) * (joints * 16 + 40);
  }
  return bytes;
}

std::uint64_t memory_limit_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  std::uint64_t limit = pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page)
                                              : std::numeric_limits<std::uint64_t>::max();
  limit = std::min({limit, cgroup_limit(), rlimit_bytes(RLIMIT_AS), rlimit_bytes(RLIMIT_DATA)});
  return limit;
}

Status check_crowd_memory(const CrowdSettings& options, const RunOutputs& outputs, const Database& database,
                          const Scenario* scenario, SettingNames names) {
  if (!scenario && outputs.scenario_file) return {};
  std::uint64_t agents = 0;
  std::uint64_t goals = 0;
  if (scenario) {
    agents = scenario->agents.size();
    for (const AgentPlan& plan : scenario->agents) goals += plan.goals.size();
  } else {
    const RandomScenarioOptions random;
    agents = options.agents.value_or(kDefaultAgents);
    goals = agents * random.goals_per_agent;
  }
  const std::uint64_t estimate = estimate_crowd_bytes(options, outputs, database, agents, goals);
  const std::uint64_t limit = memory_limit_bytes();
  if (double(estimate) <= kMemoryShare * double(limit)) return {};
  const std::string html = outputs.html ? setting_name(names, "html") : std::string();
  const std::string lower = "; lower " + setting_name(names, "agents");
  return make_error(std::to_string(agents) + " agents for " + number_text(options.seconds) + " s" +
                    (outputs.html ? " with " + html : "") + " would need about " + gib(estimate) + ", over " +
                    number_text(kMemoryShare * 100.0) + "% of the " + gib(limit) +
                    " this process may use (physical memory, cgroup and ulimit)" + lower +
                    (outputs.html ? ", " + setting_name(names, "seconds") + ", " +
                                        setting_name(names, "detail-agents") + " or leave out " + html
                                  : " or " + setting_name(names, "seconds")));
}

}  // namespace mmvk::crowd
