// The pose-targets file of pose-matching queries: parsing, and errors that
// name the file and the field.
#include <gtest/gtest.h>

#include "mmvk/query/pose_query.hpp"

namespace mmvk {
namespace {

TEST(PoseTargets, ParsesPositionsAndVelocities) {
  Result<std::vector<PoseTarget>> targets = parse_pose_targets_json(R"({"targets": [
      {"bone": "@left_foot", "position": [0.1, 0.05, 0.3], "velocity": [0, 0, 1.5]},
      {"bone": "RightHand", "velocity": [0.5, 0, -1]}]})",
                                                                    "t.json");
  ASSERT_TRUE(targets.ok()) << targets.message();
  ASSERT_EQ(targets->size(), 2u);
  EXPECT_EQ((*targets)[0].bone, "@left_foot");
  ASSERT_TRUE((*targets)[0].position.has_value());
  EXPECT_EQ((*targets)[0].position->z, 0.3f);
  EXPECT_EQ((*targets)[0].velocity->z, 1.5f);
  EXPECT_FALSE((*targets)[1].position.has_value());
  EXPECT_EQ((*targets)[1].velocity->x, 0.5f);
}

TEST(PoseTargets, ErrorsNameTheFileAndField) {
  const std::pair<std::string, std::string> cases[] = {
      {"[1, 2]", "t.json: expected a JSON object with \"targets\""},
      {R"({"target": []})", "t.json: target: unknown field"},
      {R"({"targets": []})", "t.json: targets: empty"},
      {R"({"targets": {}})", "t.json: targets: expected an array"},
      {R"({"targets": [{"position": [0, 0, 0]}]})", "t.json: targets[0].bone: missing"},
      {R"({"targets": [{"bone": "", "position": [0, 0, 0]}]})", "t.json: targets[0].bone: expected a bone name"},
      {R"({"targets": [{"bone": "@head"}]})", "t.json: targets[0]: needs a \"position\" or a \"velocity\""},
      {R"({"targets": [{"bone": "@head", "position": [0, 0]}]})", "t.json: targets[0].position: expected [x, y, z]"},
      {R"({"targets": [{"bone": "@head", "position": [0, 0, 0]}, {"bone": "@head", "velocity": [0, "a", 0]}]})",
       "t.json: targets[1].velocity[1]: expected a number"},
      {R"({"targets": [{"bone": "@head", "position": [0, 0, 1e39]}]})", "t.json: targets[0].position[2]: "},
      {R"({"targets": [{"bone": "@head", "rotation": [0, 0, 0, 1]}]})", "t.json: targets[0].rotation: unknown field"},
  };
  for (const auto& [json, expected] : cases) {
    Result<std::vector<PoseTarget>> targets = parse_pose_targets_json(json, "t.json");
    ASSERT_FALSE(targets.ok()) << json;
    EXPECT_EQ(targets.message().rfind(expected, 0), 0u) << targets.message();
  }
}

}  // namespace
}  // namespace mmvk
