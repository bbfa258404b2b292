// CommandMeter on made-up ticks: the stillness of characters told to stand
// (after the command has held for 1.2 s), the glide and the steady moving
// ticks.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "measure/command_meter.hpp"

namespace mmvk::crowd {
namespace {

constexpr double kDt = 0.1;

TEST(CrowdCommandMeter, StillWhileToldToStandCountsTheRootAndBothToes) {
  // Three characters told to stand for 3 s: one still, one whose left toe
  // moves at 10 cm/s, one whose root creeps at 2 cm/s (still by the bound).
  CommandMeter meter(3, kDt);
  const std::vector<glm::vec3> desired(3, glm::vec3(0.0f)), corrections(3, glm::vec3(0.0f));
  const std::vector<float> yaws(3, 0.0f);
  std::vector<glm::vec3> roots(3, glm::vec3(0.0f)), toes(6, glm::vec3(0.0f));
  for (int tick = 0; tick < 30; ++tick) {
    toes[2] = glm::vec3(0.1f * kDt * float(tick), 0.0f, 0.0f);  // character 1's left toe
    roots[2] = glm::vec3(0.0f, 0.0f, 0.02f * kDt * float(tick));
    meter.record({desired, {}, roots, yaws, corrections, toes});
  }
  const CommandFigures f = meter.figures();
  // Steady once the command to stand has held for more than 1.2 s (12
  // ticks): 18 of each character's 30 ticks.
  EXPECT_NEAR(f.steady_standing_fraction, 18.0 / 30.0, 1e-9);
  EXPECT_NEAR(f.standing_still_share, 2.0 / 3.0, 1e-9);
  EXPECT_EQ(f.steady_moving_fraction, 0.0);
}

TEST(CrowdCommandMeter, NoStandNoToesNoStillness) {
  CommandMeter walking(1, kDt), blind(1, kDt);
  const std::vector<glm::vec3> corrections(1, glm::vec3(0.0f)), stand(1, glm::vec3(0.0f));
  const std::vector<glm::vec3> walk(1, glm::vec3(0.0f, 0.0f, 1.0f));
  const std::vector<float> yaws(1, 0.0f);
  for (int tick = 0; tick < 30; ++tick) {
    const std::vector<glm::vec3> roots(1, glm::vec3(0.0f, 0.0f, float(kDt) * float(tick)));
    const std::vector<glm::vec3> toes(2, roots[0]);
    walking.record({walk, {}, roots, yaws, corrections, toes});
    blind.record({stand, {}, std::vector<glm::vec3>(1, glm::vec3(0.0f)), yaws, corrections, {}});
  }
  EXPECT_TRUE(std::isnan(walking.figures().standing_still_share));
  EXPECT_GT(walking.figures().steady_moving_fraction, 0.5);
  EXPECT_TRUE(std::isnan(blind.figures().standing_still_share)) << "no toes given: not measured";
}

}  // namespace
}  // namespace mmvk::crowd
