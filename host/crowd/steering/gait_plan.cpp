#include "steering/gait_plan.hpp"

#include <algorithm>

namespace mmvk::crowd {

namespace {

bool names(const std::vector<std::string>& tags, const char* tag) {
  return std::find(tags.begin(), tags.end(), tag) != tags.end();
}

bool runs(const SpeedPreference& speed, const GaitSpeeds& speeds) {
  if (speed.gait == Gait::Metres) return speed.value >= 0.5f * (speeds.walk_mps + speeds.run_mps);
  return speed.gait == Gait::Run;
}

}  // namespace

Status resolve_gaits(Scenario& scenario, const GaitSpeeds& speeds) {
  for (std::size_t a = 0; a < scenario.agents.size(); ++a) {
    AgentPlan& plan = scenario.agents[a];
    if (plan.speed.gait == Gait::Run && !speeds.has_run) {
      return make_error(scenario.source + ": agents[" + std::to_string(a) +
                        "].speed: asks for the 'run' gait, but the motion data has no run (" + speeds.no_run_reason +
                        ")");
    }
    if (!speeds.tagged) continue;
    const bool named = names(plan.require_tags, kWalkTag) || names(plan.require_tags, kRunTag) ||
                       names(plan.exclude_tags, kWalkTag) || names(plan.exclude_tags, kRunTag);
    if (named) continue;
    plan.steering_gait_tag = runs(plan.speed, speeds) ? kRunTag : kWalkTag;
    plan.require_tags.push_back(plan.steering_gait_tag);
  }
  return {};
}

std::uint64_t count_runners(const Scenario& scenario) {
  return std::uint64_t(std::count_if(scenario.agents.begin(), scenario.agents.end(),
                                     [](const AgentPlan& plan) { return plan.speed.gait == Gait::Run; }));
}

Status apply_plan_tags(const Scenario& scenario, const Database& database, std::span<QueryParams> params) {
  for (std::size_t a = 0; a < scenario.agents.size(); ++a) {
    const AgentPlan& plan = scenario.agents[a];
    const std::string where = scenario.source + ": agents[" + std::to_string(a) + "].";
    Result<TagMask> require = database.tag_mask(plan.require_tags);
    if (!require) return make_error(where + "require_tags: " + require.message());
    Result<TagMask> exclude = database.tag_mask(plan.exclude_tags);
    if (!exclude) return make_error(where + "exclude_tags: " + exclude.message());
    params[a].require_all = *require;
    params[a].exclude_any = *exclude;
  }
  return {};
}

}  // namespace mmvk::crowd
