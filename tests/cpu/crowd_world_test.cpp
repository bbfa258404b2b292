// The crowd host's world without animation: scenarios (seeded and JSON, with
// errors naming file and field), the uniform grid against brute force, and
// steering (goals, waits at goals, separation, speed caps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "steering/random.hpp"
#include "steering/scenario.hpp"
#include "steering/spatial_grid.hpp"
#include "steering/steering.hpp"

namespace mmvk::crowd {
namespace {

constexpr float kDt = 1.0f / 30.0f;  // the crowd's default tick

TEST(CrowdScenario, SeededScenarioIsDeterministicAndInsideTheWorld) {
  RandomScenarioOptions options;
  options.agents = 200;
  options.seed = 7;
  const Scenario a = make_random_scenario(options);
  const Scenario b = make_random_scenario(options);
  ASSERT_EQ(a.agents.size(), 200u);
  const float half = 0.5f * a.world_size_m;
  std::size_t runners = 0;
  for (std::size_t i = 0; i < a.agents.size(); ++i) {
    EXPECT_EQ(a.agents[i].start, b.agents[i].start);
    EXPECT_EQ(a.agents[i].goals, b.agents[i].goals);
    EXPECT_EQ(a.agents[i].goals.size(), options.goals_per_agent);
    for (const auto& g : a.agents[i].goals) {
      EXPECT_LE(std::abs(g[0]), half);
      EXPECT_LE(std::abs(g[1]), half);
    }
    runners += a.agents[i].speed.gait == Gait::Run;
  }
  // About run_fraction of 200 (0.2 -> 40), well away from none or all.
  EXPECT_GT(runners, 15u);
  EXPECT_LT(runners, 70u);
  options.seed = 8;
  EXPECT_NE(make_random_scenario(options).agents[0].start, a.agents[0].start);
}

TEST(CrowdScenario, SeededWaitIsEveryAgentsAndDrawsNothing) {
  RandomScenarioOptions options;
  options.agents = 50;
  const Scenario still = make_random_scenario(options);
  options.wait_s = 2.5f;
  const Scenario waiting = make_random_scenario(options);
  for (std::size_t i = 0; i < still.agents.size(); ++i) {
    EXPECT_EQ(still.agents[i].wait_s, 0.0f);  // the default
    EXPECT_EQ(waiting.agents[i].wait_s, 2.5f);
    // The same goals and speeds: the wait takes no random draw.
    EXPECT_EQ(waiting.agents[i].goals, still.agents[i].goals);
    EXPECT_EQ(waiting.agents[i].speed.value, still.agents[i].speed.value);
  }
}

TEST(CrowdScenario, WaitAtGoalsFromTheAgentOrTheScenarioDefault) {
  const auto own = parse_scenario_json(
      R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "wait_s": 1.5}, {"start": [0, 0], "goals": [[1, 1]]}]})",
      "crowd.json");
  ASSERT_TRUE(own.ok()) << own.message();
  EXPECT_EQ(own->agents[0].wait_s, 1.5f);
  EXPECT_EQ(own->agents[1].wait_s, 0.0f);  // no wait anywhere: 0, leave at once
  const auto defaulted = parse_scenario_json(
      R"({"wait_s": 2, "agents": [{"start": [0, 0], "goals": [[1, 1]], "wait_s": 0},
                                  {"start": [0, 0], "goals": [[1, 1]]},
                                  {"start": [0, 0], "goals": [[1, 1]], "wait_s": 3600}]})",
      "crowd.json");
  ASSERT_TRUE(defaulted.ok()) << defaulted.message();
  EXPECT_EQ(defaulted->agents[0].wait_s, 0.0f);  // its own overrides the default
  EXPECT_EQ(defaulted->agents[1].wait_s, 2.0f);
  EXPECT_EQ(defaulted->agents[2].wait_s, 3600.0f);  // the limit itself
}

TEST(CrowdScenario, ParsesEveryField) {
  const auto scenario = parse_scenario_json(
      R"({"world_size_m": 30, "agents": [
           {"start": [1, 2], "goals": [[3, 4], [5, -6]], "speed": "run", "require_tags": ["walk"], "exclude_tags": ["idle"]},
           {"start": [0, 0], "goals": [[1, 1]], "speed": 1.25}]})",
      "crowd.json");
  ASSERT_TRUE(scenario.ok()) << scenario.message();
  ASSERT_EQ(scenario->agents.size(), 2u);
  EXPECT_EQ(scenario->world_size_m, 30.0f);
  const AgentPlan& a = scenario->agents[0];
  EXPECT_EQ(a.start, (std::array<float, 2>{1, 2}));
  ASSERT_EQ(a.goals.size(), 2u);
  EXPECT_EQ(a.goals[1], (std::array<float, 2>{5, -6}));
  EXPECT_EQ(a.speed.gait, Gait::Run);
  EXPECT_EQ(a.require_tags, std::vector<std::string>{"walk"});
  EXPECT_EQ(a.exclude_tags, std::vector<std::string>{"idle"});
  EXPECT_EQ(scenario->agents[1].speed.gait, Gait::Metres);
  EXPECT_EQ(scenario->agents[1].speed.value, 1.25f);
}

TEST(CrowdScenario, BadFieldsNameTheFileAndTheField) {
  const struct {
    const char* json;
    const char* expected;
  } cases[] = {
      {"{", "crowd.json: not valid JSON"},
      {R"({"agents": []})", "crowd.json: agents: expected a non-empty array"},
      {R"({"agent": []})", "crowd.json: agent: unknown field"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]]}, {"start": [0], "goals": [[1, 1]]}]})",
       "crowd.json: agents[1].start: expected [x, z] numbers"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1], [2, "x"]]}]})",
       "crowd.json: agents[0].goals[1]: expected [x, z] numbers"},
      {R"({"agents": [{"start": [0, 0]}]})", "crowd.json: agents[0].goals: missing"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "speed": "fly"}]})",
       "crowd.json: agents[0].speed: expected \"walk\", \"run\" or metres/second"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "speed": -1}]})",
       "crowd.json: agents[0].speed: a speed must be > 0"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "require_tags": "walk"}]})",
       "crowd.json: agents[0].require_tags: expected an array of tag names"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "exclude_tags": [""]}]})",
       "crowd.json: agents[0].exclude_tags[0]: expected a tag name"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "colour": "red"}]})",
       "crowd.json: agents[0].colour: unknown field"},
      {R"({"world_size_m": -3, "agents": [{"start": [0, 0], "goals": [[1, 1]]}]})",
       "crowd.json: world_size_m: must be > 0"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]]}, {"start": [0, 0], "goals": [[1, 1]]},
                      {"start": [0, 0], "goals": [[1, 1]], "wait_s": -1}]})",
       "crowd.json: agents[2].wait_s: expected seconds from 0 to 3600, got -1"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "wait_s": true}]})",
       "crowd.json: agents[0].wait_s: expected seconds from 0 to 3600"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "wait_s": 3600.5}]})",
       "crowd.json: agents[0].wait_s: expected seconds from 0 to 3600, got 3600.5"},
      {R"({"agents": [{"start": [0, 0], "goals": [[1, 1]], "wait_s": "2s"}]})",
       "crowd.json: agents[0].wait_s: expected seconds from 0 to 3600"},
      {R"({"wait_s": -0.5, "agents": [{"start": [0, 0], "goals": [[1, 1]]}]})",
       "crowd.json: wait_s: expected seconds from 0 to 3600, got -0.5"},
      {R"({"wait_s": null, "agents": [{"start": [0, 0], "goals": [[1, 1]]}]})",
       "crowd.json: wait_s: expected seconds from 0 to 3600"},
  };
  for (const auto& c : cases) {
    const auto scenario = parse_scenario_json(c.json, "crowd.json");
    ASSERT_FALSE(scenario.ok()) << c.json;
    EXPECT_NE(scenario.message().find(c.expected), std::string::npos)
        << "input: " << c.json << "\nmessage: " << scenario.message() << "\nexpected to contain: " << c.expected;
  }
  const auto missing = load_scenario("/nonexistent/crowd.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("/nonexistent/crowd.json"), std::string::npos);
}

TEST(CrowdGrid, FindsTheSameNeighboursAsBruteForce) {
  Random random(3);
  std::vector<float> x(2000), z(2000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = random.uniform(-40, 40), z[i] = random.uniform(-25, 25);
  x[5] = 1000.0f;  // a stray point far away: cells grow, answers stay right
  const float radius = 1.5f;
  std::vector<glm::vec3> points(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) points[i] = glm::vec3(x[i], 0.0f, z[i]);
  SpatialGrid grid;
  grid.build(points, radius);
  for (std::size_t i = 0; i < x.size(); i += 7) {
    std::set<std::uint32_t> found, expected;
    grid.for_each_near(x[i], z[i], [&](std::uint32_t j) {
      const float dx = x[i] - x[j], dz = z[i] - z[j];
      if (dx * dx + dz * dz < radius * radius) found.insert(j);
    });
    for (std::uint32_t j = 0; j < x.size(); ++j) {
      const float dx = x[i] - x[j], dz = z[i] - z[j];
      if (dx * dx + dz * dz < radius * radius) expected.insert(j);
    }
    ASSERT_EQ(found, expected) << "point " << i;
  }
}

Scenario two_agents(std::array<float, 2> a, std::array<float, 2> b, std::array<float, 2> goal_a,
                    std::array<float, 2> goal_b) {
  Scenario s;
  s.source = "test";
  s.world_size_m = 20.0f;
  s.agents.resize(2);
  s.agents[0].start = a, s.agents[0].goals = {goal_a, {-9, -9}};
  s.agents[1].start = b, s.agents[1].goals = {goal_b};
  return s;
}

TEST(CrowdSteering, SeeksTheGoalAtThePreferredSpeedCappedToTheDatabase) {
  const GaitSpeeds speeds{.walk_mps = 1.2f, .run_mps = 3.5f, .max_mps = 3.0f, .has_run = true};
  Scenario s = two_agents({0, 0}, {10, 10}, {5, 0}, {10, -10});
  s.agents[0].speed = {Gait::Walk, 1.0f};
  s.agents[1].speed = {Gait::Run, 1.0f};
  Steering steering(s, speeds);
  EXPECT_FLOAT_EQ(steering.preferred_speed(0), 1.2f);
  EXPECT_FLOAT_EQ(steering.preferred_speed(1), 3.0f);  // capped to max_mps
  const std::vector<glm::vec3> positions{{0, 0, 0}, {10, 0, 10}};
  std::vector<glm::vec3> v(2);
  steering.update(positions, v, kDt);
  EXPECT_NEAR(v[0].x, 1.2f, 1e-6f);
  EXPECT_NEAR(v[0].z, 0.0f, 1e-6f);
  EXPECT_NEAR(v[1].x, 0.0f, 1e-6f);
  EXPECT_NEAR(v[1].z, -3.0f, 1e-6f);
}

TEST(CrowdSteering, ReachingAGoalMovesOnToTheNext) {
  Scenario s = two_agents({0, 0}, {10, 10}, {0.5f, 0}, {10, -10});
  Steering steering(s, GaitSpeeds{.walk_mps = 1.0f, .run_mps = 1.0f, .max_mps = 1.0f});
  const std::vector<glm::vec3> positions{{0, 0, 0}, {10, 0, 10}};
  std::vector<glm::vec3> v(2);
  steering.update(positions, v, kDt);
  EXPECT_EQ(steering.goal_index(0), 1u);
  EXPECT_EQ(steering.goals_reached(), 1u);
  // Now heading for (-9, -9).
  EXPECT_LT(v[0].x, 0.0f);
  EXPECT_LT(v[0].z, 0.0f);
}

TEST(CrowdSteering, AWaitAtAGoalStandsThenLeavesForTheNext) {
  // Agent 0 walks along +x at 1 m/s to (3, 0), waits 1 s, then heads for
  // (3, 5); agent 1 (no wait) walks on past its goal at once.
  Scenario s = two_agents({0, 0}, {0, 20}, {3, 0}, {3, 20});
  s.agents[0].goals = {{3, 0}, {3, 5}};
  s.agents[0].wait_s = 1.0f;
  s.agents[1].goals = {{3, 20}, {-5, 20}};
  Steering steering(s, GaitSpeeds{.walk_mps = 1.0f, .run_mps = 1.0f, .max_mps = 1.0f});
  std::vector<glm::vec3> positions{{0, 0, 0}, {0, 0, 20}};
  std::vector<glm::vec3> v(2);
  int arrived = -1, left = -1, still_ticks = 0;
  for (int tick = 0; tick < 200 && left < 0; ++tick) {
    steering.update(positions, v, kDt);
    const float speed = std::hypot(v[0].x, v[0].z);
    if (speed == 0.0f) {
      if (arrived < 0) arrived = tick;
      ++still_ticks;
      // At the goal it stands at until the wait's last tick moves it on.
      EXPECT_EQ(steering.goal_index(0), steering.waiting(0) ? 0u : 1u) << tick;
    } else if (arrived >= 0) {
      left = tick;
      // At the walking speed toward (3, 5).
      const float gx = 3.0f - positions[0].x, gz = 5.0f - positions[0].z;
      EXPECT_NEAR(v[0].x, gx / std::hypot(gx, gz), 1e-5f);
      EXPECT_NEAR(v[0].z, gz / std::hypot(gx, gz), 1e-5f);
    }
    // The host moves each character as it is told.
    for (int a = 0; a < 2; ++a) positions[a] += v[a] * kDt;
  }
  // Reached within 1 m of (3, 0): after 2 m at 1 m/s, 60 ticks.
  EXPECT_NEAR(arrived, 60, 1) << "arrived at tick " << arrived;
  // Still for the wait within a tick (30 at 30 Hz), then off at once.
  EXPECT_NEAR(still_ticks, 30, 1);
  EXPECT_EQ(left, arrived + still_ticks);
  EXPECT_FALSE(steering.waiting(0));
  // One arrival each: agent 0's wait counts its goal once, not per tick.
  EXPECT_EQ(steering.goals_reached(), 2u);
  EXPECT_EQ(steering.goal_index(1), 1u);
}

TEST(CrowdSteering, AWaitingCharacterIsNotPushedByItsNeighbours) {
  // Agent 0 stands at its goal (reached at once); agent 1 walks into it.
  Scenario s = two_agents({0, 0}, {0, 0.3f}, {0, 0}, {50, 0.3f});
  s.agents[0].wait_s = 5.0f;
  Steering steering(s, GaitSpeeds{.walk_mps = 1.0f, .run_mps = 1.0f, .max_mps = 1.0f});
  const std::vector<glm::vec3> positions{{0, 0, 0}, {0, 0, 0.3f}};
  std::vector<glm::vec3> v(2);
  steering.update(positions, v, kDt);
  EXPECT_TRUE(steering.waiting(0));
  EXPECT_EQ(v[0], glm::vec3(0.0f));
  EXPECT_GT(v[1].z, 0.1f);  // the walker keeps clear
}

TEST(CrowdSteering, NeighboursPushApartWithoutExceedingThePreferredSpeed) {
  // Two characters 0.4 m apart, both heading the same way along +x.
  Scenario s = two_agents({0, 0}, {0, 0.4f}, {50, 0}, {50, 0.4f});
  Steering steering(s, GaitSpeeds{.walk_mps = 1.0f, .run_mps = 1.0f, .max_mps = 1.0f});
  const std::vector<glm::vec3> positions{{0, 0, 0}, {0, 0, 0.4f}};
  std::vector<glm::vec3> v(2);
  steering.update(positions, v, kDt);
  EXPECT_LT(v[0].z, -0.1f);  // pushed toward -z, away from the other
  EXPECT_GT(v[1].z, 0.1f);
  for (int i = 0; i < 2; ++i) EXPECT_LE(std::hypot(v[i].x, v[i].z), 1.0f + 1e-5f);
  // Far apart: no push at all.
  const std::vector<glm::vec3> far{{0, 0, 0}, {0, 0, 5.0f}};
  steering.update(far, v, kDt);
  EXPECT_NEAR(v[0].z, 0.0f, 1e-5f);
}

}  // namespace
}  // namespace mmvk::crowd
