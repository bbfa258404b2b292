// What the crowd makes of a database's gaits: walk and run speeds by tag or
// by speed, no run when the data has none (and why), and the plans checked
// and given their gait's tag.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "steering/gait_plan.hpp"
#include "steering/gait_speeds.hpp"
#include "mmvk/database/database_build.hpp"
#include "steering/scenario.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk::crowd {
namespace {

struct Take {
  float speed;  // m/s
  std::vector<std::string> tags;
};

// One 3 s clip per take (the last second edge-excluded).
Database database_of(const std::vector<Take>& takes) {
  std::vector<MotionClip> clips;
  for (const Take& take : takes) {
    MotionClip clip;
    // Turning gently either way and swinging the legs, so that no feature
    // channel is constant over the database.
    const float turn = clips.size() % 2 ? 0.3f : -0.3f;
    clip.motion = test::walker(90, take.speed, 0.5f * float(clips.size()), turn, 0.4f);
    clip.meta.file = "take" + std::to_string(clips.size()) + ".bvh";
    clip.meta.name = clip.meta.file.stem().string();
    clip.meta.tags = take.tags;
    clips.push_back(std::move(clip));
  }
  Result<Database> db = build_database_from_motions(clips, {});
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

TEST(CrowdGaitSpeeds, WalkOnlyDataHasNoRunAndSaysWhy) {
  Result<GaitSpeeds> speeds = measure_gait_speeds(database_of({{1.3f, {"walk"}}, {1.1f, {"walk"}}}));
  ASSERT_TRUE(speeds.ok()) << speeds.message();
  EXPECT_FALSE(speeds->has_run);
  EXPECT_FALSE(speeds->tagged);
  EXPECT_EQ(speeds->run_mps, 0.0f);
  EXPECT_NEAR(speeds->walk_mps, 1.3f, 0.02f);
  EXPECT_NE(speeds->no_run_reason.find("no frame is tagged 'run'"), std::string::npos) << speeds->no_run_reason;
}

TEST(CrowdGaitSpeeds, TaggedGaitsAreMeasuredByTag) {
  // The jog (2.2 m/s, neither tag) counts for neither gait.
  Result<GaitSpeeds> speeds =
      measure_gait_speeds(database_of({{1.4f, {"walk"}}, {2.2f, {"jog"}}, {3.5f, {"run"}}}));
  ASSERT_TRUE(speeds.ok()) << speeds.message();
  EXPECT_TRUE(speeds->has_run);
  EXPECT_TRUE(speeds->tagged);
  EXPECT_NEAR(speeds->walk_mps, 1.4f, 0.02f);
  EXPECT_NEAR(speeds->run_mps, 3.5f, 0.02f);  // a chord of the gentle turn, not its arc
  EXPECT_TRUE(speeds->no_run_reason.empty());
}

TEST(CrowdGaitSpeeds, ARunTagThatDoesNotSeparateIsNoRun) {
  Result<GaitSpeeds> speeds = measure_gait_speeds(database_of({{1.4f, {"walk"}}, {1.5f, {"run"}}}));
  ASSERT_TRUE(speeds.ok()) << speeds.message();
  EXPECT_FALSE(speeds->has_run);
  EXPECT_EQ(speeds->run_mps, 0.0f);
  EXPECT_NE(speeds->no_run_reason.find("the frames tagged 'run' move at 1.4"), std::string::npos)
      << speeds->no_run_reason;
}

TEST(CrowdGaitSpeeds, UntaggedDataSeparatesBySpeed) {
  Result<GaitSpeeds> speeds = measure_gait_speeds(database_of({{1.4f, {}}, {3.5f, {}}}));
  ASSERT_TRUE(speeds.ok()) << speeds.message();
  EXPECT_TRUE(speeds->has_run);
  EXPECT_FALSE(speeds->tagged) << "no tags to search by";
  EXPECT_NEAR(speeds->run_mps, 3.5f, 0.02f);  // a chord of the gentle turn, not its arc
  // A run just over 2 m/s does not separate from a 1.9 m/s walk.
  Result<GaitSpeeds> close = measure_gait_speeds(database_of({{1.9f, {}}, {2.1f, {}}}));
  ASSERT_TRUE(close.ok()) << close.message();
  EXPECT_FALSE(close->has_run);
  EXPECT_NE(close->no_run_reason.find("the frames at 2 m/s or more"), std::string::npos) << close->no_run_reason;
}

Scenario three_plans() {
  Scenario scenario;
  scenario.source = "crowd.json";
  scenario.agents.resize(3);
  for (AgentPlan& plan : scenario.agents) plan.goals = {{1.0f, 1.0f}};
  scenario.agents[0].speed = {Gait::Walk, 1.0f};
  scenario.agents[1].speed = {Gait::Run, 0.9f};
  scenario.agents[2].speed = {Gait::Metres, 3.0f};
  return scenario;
}

TEST(CrowdGaitPlan, RunningOnDataWithoutARunIsAnErrorNamingTheGait) {
  const GaitSpeeds walk_only{.walk_mps = 1.3f, .max_mps = 1.5f, .no_run_reason = "no frame is tagged 'run'"};
  Scenario scenario = three_plans();
  const Status status = resolve_gaits(scenario, walk_only);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("crowd.json: agents[1].speed: asks for the 'run' gait, but the motion data has no "
                                  "run (no frame is tagged 'run')"),
            std::string::npos)
      << status.message();
  // Without runners, nothing fails and no tag is added (the data is untagged).
  scenario.agents[1].speed = {Gait::Walk, 0.9f};
  ASSERT_TRUE(resolve_gaits(scenario, walk_only).ok());
  for (const AgentPlan& plan : scenario.agents) EXPECT_TRUE(plan.require_tags.empty());
  EXPECT_EQ(count_runners(scenario), 0u);
}

TEST(CrowdGaitPlan, TaggedDataSendsEachPlanToItsGaitUnlessItNamesOne) {
  const GaitSpeeds tagged{.walk_mps = 1.5f, .run_mps = 3.5f, .max_mps = 3.6f, .has_run = true, .tagged = true};
  Scenario scenario = three_plans();
  scenario.agents.push_back(scenario.agents[0]);
  scenario.agents.back().exclude_tags = {"walk"};  // names a gait tag: left alone
  ASSERT_TRUE(resolve_gaits(scenario, tagged).ok());
  EXPECT_EQ(scenario.agents[0].require_tags, std::vector<std::string>{"walk"});
  EXPECT_EQ(scenario.agents[1].require_tags, std::vector<std::string>{"run"});
  EXPECT_EQ(scenario.agents[2].require_tags, std::vector<std::string>{"run"}) << "3 m/s is nearer the run";
  EXPECT_TRUE(scenario.agents[3].require_tags.empty());
  EXPECT_EQ(count_runners(scenario), 1u);
  EXPECT_EQ(scenario.agents[0].steering_gait_tag, "walk");
  EXPECT_EQ(scenario.agents[3].steering_gait_tag, "") << "the scenario's own";
}

TEST(CrowdGaitPlan, ARandomCrowdWithoutARunFractionHasNoRunners) {
  RandomScenarioOptions options;
  options.agents = 300;
  options.run_fraction = 0.0f;
  EXPECT_EQ(count_runners(make_random_scenario(options)), 0u);
  options.run_fraction = 0.2f;
  EXPECT_GT(count_runners(make_random_scenario(options)), 30u);
}

}  // namespace
}  // namespace mmvk::crowd
