// The manifest's time-ranged modifiers (tag_ranges, cost_ranges) and mirror
// tables (mirror_bones, mirror_map): parsing, and errors that name the
// manifest and the field; the user bone-pair table over the name heuristics.
#include <gtest/gtest.h>

#include "mmvk/import/character.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/import/motion.hpp"

namespace mmvk {
namespace {

constexpr const char* kSidecarSchema =
    R"("schema": {"channels": [{"name": "hipv", "kind": "root_velocity"},
                               {"name": "phase", "kind": "custom", "dims": 5}]})";

Result<Manifest> parse(const std::string& json) { return parse_manifest_json(json, "m.json", "/base"); }

std::string error_of(const std::string& json) {
  Result<Manifest> manifest = parse(json);
  EXPECT_FALSE(manifest.ok()) << json;
  return manifest.ok() ? std::string() : manifest.message();
}

TEST(ManifestModifiers, ParsesTagAndCostRanges) {
  Result<Manifest> manifest = parse(R"({"clips": [
      {"file": "a.bvh", "tag_ranges": {"jump": [[0.5, 1.0], [2, 2.5]], "land": [[1.0, 1.25]]},
       "cost_ranges": [{"range": [0.25, 0.75], "cost_multiplier": 2, "cost_bias": -0.5},
                       {"range": [1, 2]}]}]})");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  const ManifestClip& clip = manifest->clips[0];
  EXPECT_EQ(clip.field, "m.json: clips[0]");
  ASSERT_EQ(clip.tag_ranges.size(), 3u);
  EXPECT_EQ(clip.tag_ranges[0].tag, "jump");
  EXPECT_EQ(clip.tag_ranges[1].range.begin_seconds, 2.0f);
  EXPECT_EQ(clip.tag_ranges[2].tag, "land");
  EXPECT_EQ(clip.tag_ranges[2].range.end_seconds, 1.25f);
  ASSERT_EQ(clip.cost_ranges.size(), 2u);
  EXPECT_EQ(clip.cost_ranges[0].range.begin_seconds, 0.25f);
  EXPECT_EQ(clip.cost_ranges[0].cost_multiplier, 2.0f);
  EXPECT_EQ(clip.cost_ranges[0].cost_bias, -0.5f);
  EXPECT_EQ(clip.cost_ranges[1].cost_multiplier, 1.0f);
  EXPECT_EQ(clip.cost_ranges[1].cost_bias, 0.0f);
}

TEST(ManifestModifiers, RangeErrorsNameTheField) {
  const std::pair<std::string, std::string> cases[] = {
      {R"({"clips": [{"file": "a.bvh", "tag_ranges": [[0, 1]]}]})", "m.json: clips[0].tag_ranges: expected an object"},
      {R"({"clips": [{"file": "a.bvh", "tag_ranges": {"jump": [[1, 0.5]]}}]})",
       "m.json: clips[0].tag_ranges.jump[0]: expected 0 <= begin < end"},
      {R"({"clips": [{"file": "a.bvh", "tag_ranges": {"": [[0, 1]]}}]})", "m.json: clips[0].tag_ranges: empty tag name"},
      {R"({"clips": [{"file": "a.bvh", "cost_ranges": [{"cost_bias": 1}]}]})",
       "m.json: clips[0].cost_ranges[0].range: missing"},
      {R"({"clips": [{"file": "a.bvh", "cost_ranges": [{"range": [0, 1], "cost_multiplier": 0}]}]})",
       "m.json: clips[0].cost_ranges[0].cost_multiplier: must be > 0"},
      {R"({"clips": [{"file": "a.bvh", "cost_ranges": [{"range": [0, 1], "multiplier": 2}]}]})",
       "m.json: clips[0].cost_ranges[0].multiplier: unknown field"},
      {R"({"clips": [{"file": "a.bvh", "cost_ranges": [{"range": [-1, 1]}]}]})",
       "m.json: clips[0].cost_ranges[0].range: expected 0 <= begin < end"},
  };
  for (const auto& [json, expected] : cases) {
    const std::string message = error_of(json);
    EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
  }
}

TEST(ManifestModifiers, ParsesMirrorTables) {
  Result<Manifest> manifest = parse(std::string("{") + kSidecarSchema + R"(,
      "mirror_bones": [["LeftFoot", "RightFoot"], ["@left_hand", "Hand_R"]],
      "mirror_map": {"phase": {"swap": [[0, 2], [1, 3]], "negate": [4, 0]}},
      "clips": ["a.bvh"]})");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  ASSERT_EQ(manifest->mirror_bones.size(), 2u);
  EXPECT_EQ(manifest->mirror_bones[1].first, "@left_hand");
  EXPECT_EQ(manifest->mirror_bones[1].second, "Hand_R");
  ASSERT_EQ(manifest->mirror_map.size(), 1u);
  const SidecarMirror& map = manifest->mirror_map[0];
  EXPECT_EQ(map.channel, "phase");
  EXPECT_EQ(map.source, (std::vector<std::uint32_t>{2, 3, 0, 1, 4}));
  EXPECT_EQ(map.sign, (std::vector<float>{-1, 1, 1, 1, -1}));
}

TEST(ManifestModifiers, MirrorTableErrorsNameTheField) {
  const std::string schema = std::string("{") + kSidecarSchema + ", \"clips\": [\"a.bvh\"], ";
  const std::pair<std::string, std::string> cases[] = {
      {R"("mirror_bones": [["LeftFoot"]]})", "m.json: mirror_bones[0]: expected [left, right]"},
      {R"("mirror_bones": [["LeftFoot", 3]]})", "m.json: mirror_bones[0][1]: expected a string"},
      {R"("mirror_bones": [["", "RightFoot"]]})", "m.json: mirror_bones[0][0]: empty bone name"},
      {R"("mirror_map": {"nope": {}}})", "m.json: mirror_map.nope: the schema has no channel named 'nope'"},
      {R"("mirror_map": {"hipv": {"swap": [[0, 1]]}}})", "m.json: mirror_map.hipv: channel 'hipv' is a root_velocity"},
      {R"("mirror_map": {"phase": {"swap": [[0, 5]]}}})", "m.json: mirror_map.phase.swap[0][1]: expected a dim index in [0, 5)"},
      {R"("mirror_map": {"phase": {"swap": [[0, 1], [1, 2]]}}})",
       "m.json: mirror_map.phase.swap[1]: dim 1 is already in an earlier swap"},
      {R"("mirror_map": {"phase": {"swap": [[3, 3]]}}})", "m.json: mirror_map.phase.swap[0]: a dim cannot swap with itself"},
      {R"("mirror_map": {"phase": {"negate": [1, 1]}}})", "m.json: mirror_map.phase.negate[1]: dim 1 is listed twice"},
      {R"("mirror_map": {"phase": {"flip": [1]}}})", "m.json: mirror_map.phase.flip: unknown field"},
  };
  for (const auto& [tail, expected] : cases) {
    const std::string message = error_of(schema + tail);
    EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
  }
}

// A skeleton whose names defeat the heuristics on one side: "ArmL"/"ArmR"
// pair by the suffix rule only with a separator, so they stay unpaired; the
// legs pair by the "Left"/"Right" rule.
Skeleton odd_skeleton() {
  Skeleton s;
  s.names = {"Hips", "LeftLeg", "RightLeg", "Chest", "ArmL", "ArmR"};
  s.parents = {-1, 0, 0, 0, 3, 3};
  s.rest_offsets = {glm::vec3(0, 1, 0),   glm::vec3(0.1f, 0, 0), glm::vec3(-0.1f, 0, 0),
                    glm::vec3(0, 0.3f, 0), glm::vec3(0.2f, 0, 0), glm::vec3(-0.2f, 0, 0)};
  return s;
}

TEST(MirrorBones, UserPairsOverrideTheNameHeuristics) {
  const Skeleton skeleton = odd_skeleton();
  EXPECT_EQ(mirror_pairs(skeleton), (std::vector<int>{0, 2, 1, 3, 4, 5}));
  const BonePair arms[] = {{"ArmL", "ArmR"}};
  Result<std::vector<int>> pairs = mirror_pairs(skeleton, arms);
  ASSERT_TRUE(pairs.ok()) << pairs.message();
  EXPECT_EQ(*pairs, (std::vector<int>{0, 2, 1, 3, 5, 4}));
  // A joint paired with itself drops its heuristic partner's pair too.
  const BonePair alone[] = {{"ArmL", "ArmR"}, {"LeftLeg", "LeftLeg"}};
  pairs = mirror_pairs(skeleton, alone);
  ASSERT_TRUE(pairs.ok()) << pairs.message();
  EXPECT_EQ(*pairs, (std::vector<int>{0, 1, 2, 3, 5, 4}));
  // Roles resolve like schema bones.
  const BonePair roles[] = {{"@hips", "@hips"}};
  EXPECT_TRUE(mirror_pairs(skeleton, roles).ok());
}

TEST(MirrorBones, ErrorsNameThePair) {
  const Skeleton skeleton = odd_skeleton();
  const BonePair missing[] = {{"ArmL", "ArmR"}, {"LeftLeg", "Tail"}};
  Result<std::vector<int>> pairs = mirror_pairs(skeleton, missing);
  ASSERT_FALSE(pairs.ok());
  EXPECT_EQ(pairs.message().rfind("mirror_bones[1][1]: bone 'Tail' not found", 0), 0u) << pairs.message();
  const BonePair twice[] = {{"ArmL", "ArmR"}, {"ArmR", "Chest"}};
  pairs = mirror_pairs(skeleton, twice);
  ASSERT_FALSE(pairs.ok());
  EXPECT_EQ(pairs.message(), "mirror_bones[1][0]: joint ArmR is already in an earlier pair");
}

TEST(MirrorBones, MirrorWithTheTableSwapsTheArmsAndIsAnInvolution) {
  Motion motion;
  motion.skeleton = odd_skeleton();
  motion.fps = 30.0f;
  motion.frame_count = 3;
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    for (std::size_t j = 0; j < motion.skeleton.size(); ++j) {
      motion.local_positions.push_back(motion.skeleton.rest_offsets[j] + glm::vec3(0.01f * float(f), 0, 0));
      motion.local_rotations.push_back(glm::angleAxis(0.1f * float(f + j), glm::normalize(glm::vec3(1, 2, 3))));
    }
  }
  const BonePair arms[] = {{"ArmL", "ArmR"}};
  Result<Motion> mirrored = mirror(motion, arms);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  // ArmL (4) now moves as ArmR (5) did, reflected.
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    const glm::quat a = mirrored->local_rotations[mirrored->index(f, 4)];
    const glm::quat b = motion.local_rotations[motion.index(f, 5)];
    EXPECT_NEAR(std::abs(a.w), std::abs(b.w), 1e-6f);
  }
  Result<Motion> twice = mirror(*mirrored, arms);
  ASSERT_TRUE(twice.ok());
  EXPECT_EQ(twice->local_rotations, motion.local_rotations);
  EXPECT_EQ(twice->local_positions, motion.local_positions);
}

}  // namespace
}  // namespace mmvk
