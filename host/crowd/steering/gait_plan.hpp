// Each character's gait against what the database can do: running is asked
// only of data that runs, and where the data tags its gaits, walkers and
// runners each search the frames of their own gait.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "steering/gait_speeds.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "steering/scenario.hpp"

namespace mmvk::crowd {

// Checks and completes the plans in place:
//   - a plan that prefers to run ("speed": "run") on data without a run
//     (speeds.has_run false) is an error naming the file, the agent and the
//     'run' gait, with speeds.no_run_reason;
//   - with speeds.tagged, a plan that names neither gait tag in its
//     require_tags or exclude_tags requires its gait's tag: "run" for a plan
//     that prefers to run or asks for metres/second nearer the run speed
//     than the walk speed, else "walk" (also kept in steering_gait_tag).
//     Plans that name a gait tag keep theirs: the scenario knows best. The
//     tag serves the crowd's own steering, whose walkers keep to the walk
//     clips (fewer jumps than a controller free to pick a jog's slow
//     frames); a host's commands choose the gait instead
//     (CrowdSession::step with velocities lifts it).
// Random scenarios are drawn without runners when the data has no run (the
// caller sets RandomScenarioOptions::run_fraction), so they never fail here.
Status resolve_gaits(Scenario& scenario, const GaitSpeeds& speeds);

// Each plan's require_tags and exclude_tags, by name, into the masks of
// params[agent] (the controller's query parameters, [agents]); an unknown
// tag is an error naming the file, the agent and the field.
Status apply_plan_tags(const Scenario& scenario, const Database& database, std::span<QueryParams> params);

// Plans that prefer to run.
std::uint64_t count_runners(const Scenario& scenario);

}  // namespace mmvk::crowd
