// libFuzzer target: the crowd's scenario JSON (host/crowd/steering/scenario.cpp,
// compiled into this target). Every input ends in an error naming the file
// and field, or in a scenario the crowd can run: at most kMaxAgents agents,
// each with at least one goal, every coordinate and speed finite, every
// wait within 0 to kMaxGoalWaitS, and a positive world size.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "setup/crowd_limits.hpp"
#include "steering/scenario.hpp"

namespace {

void check(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "a scenario that parsed breaks: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mmvk::Result<mmvk::crowd::Scenario> scenario = mmvk::crowd::parse_scenario_json(text, "fuzz.json");
  if (!scenario.ok()) {
    check(scenario.message().rfind("fuzz.json", 0) == 0, "an error that does not name the file");
    return 0;
  }
  check(!scenario->agents.empty() && scenario->agents.size() <= mmvk::crowd::kMaxAgents, "agent count");
  check(std::isfinite(scenario->world_size_m) && scenario->world_size_m > 0.0f, "world size");
  for (const mmvk::crowd::AgentPlan& plan : scenario->agents) {
    check(!plan.goals.empty(), "an agent without goals");
    check(std::isfinite(plan.start[0]) && std::isfinite(plan.start[1]), "a start");
    for (const auto& goal : plan.goals) check(std::isfinite(goal[0]) && std::isfinite(goal[1]), "a goal");
    check(std::isfinite(plan.speed.value) && plan.speed.value > 0.0f, "a speed");
    check(plan.wait_s >= 0.0f && plan.wait_s <= float(mmvk::crowd::kMaxGoalWaitS), "a wait");
  }
  return 0;
}
