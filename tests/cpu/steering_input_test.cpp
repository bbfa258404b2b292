// PositionSteering: a host's positions as the controller's desired
// velocities (the host's motion plus a correction over the horizon).
#include "mmvk/animation/steering_input.hpp"

#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mmvk {
namespace {

TEST(PositionSteering, FirstTickClosesTheGapOverTheHorizon) {
  PositionSteering steering(2, 0.5f);
  std::vector<SimulationState> sim(2);
  sim[0].position = glm::vec3(1.0f, 0.0f, 2.0f);
  sim[1].position = glm::vec3(-3.0f, 0.0f, 0.5f);
  const std::vector<glm::vec3> next = {{1.5f, 7.0f, 2.0f}, {-3.0f, 0.0f, -0.5f}};
  std::vector<glm::vec3> out(2);
  ASSERT_TRUE(steering.velocities(sim, next, 0.1f, out).ok());
  EXPECT_EQ(out[0], glm::vec3(1.0f, 0.0f, 0.0f));  // y ignored
  EXPECT_EQ(out[1], glm::vec3(0.0f, 0.0f, -2.0f));
}

TEST(PositionSteering, LaterTicksAddTheHostsOwnMotion) {
  PositionSteering steering(1, 0.25f);
  std::vector<SimulationState> sim(1);
  std::vector<glm::vec3> out(1);
  ASSERT_TRUE(steering.velocities(sim, std::vector<glm::vec3>{{0.0f, 0.0f, 0.0f}}, 0.5f, out).ok());
  EXPECT_EQ(out[0], glm::vec3(0.0f));
  // The host moved 1 m in +x in a 0.5 s tick; the root is where it was.
  ASSERT_TRUE(steering.velocities(sim, std::vector<glm::vec3>{{1.0f, 0.0f, 0.0f}}, 0.5f, out).ok());
  EXPECT_EQ(out[0], glm::vec3(2.0f + 4.0f, 0.0f, 0.0f));
  steering.reset();
  ASSERT_TRUE(steering.velocities(sim, std::vector<glm::vec3>{{1.0f, 0.0f, 0.0f}}, 0.5f, out).ok());
  EXPECT_EQ(out[0], glm::vec3(4.0f, 0.0f, 0.0f));
}

TEST(PositionSteering, ErrorsNameTheCause) {
  PositionSteering steering(2);
  std::vector<SimulationState> sim(2);
  std::vector<glm::vec3> next(2), out(2), short_out(1);
  EXPECT_NE(steering.velocities(sim, next, 0.1f, short_out).message().find("for 2 characters"), std::string::npos);
  EXPECT_NE(steering.velocities(sim, next, 0.0f, out).message().find("dt"), std::string::npos);
  next[1].z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(steering.velocities(sim, next, 0.1f, out).message().find("character 1"), std::string::npos);
}

}  // namespace
}  // namespace mmvk
