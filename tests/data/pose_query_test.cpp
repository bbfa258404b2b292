// Pose-matching queries on real motion (Bandai locomotion): end-effector
// targets taken from frames of a clip held out of the database recover a
// frame whose end effectors lie within a stated distance; errors name the
// targets and the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <glm/geometric.hpp>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/query/pose_query.hpp"
#include "mmvk/search/reference_search.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

const char* const kEffectors[] = {"@left_foot", "@right_foot", "@left_hand", "@right_hand"};

// The default schema plus hand positions, so hands can be targets.
FeatureSchema pose_schema() {
  FeatureSchema schema = default_schema();
  for (const char* hand : {"@left_hand", "@right_hand"}) {
    FeatureChannel channel;
    channel.name = std::string(hand + 1) + "_position";
    channel.kind = ChannelKind::BonePosition;
    channel.bone = hand;
    schema.channels.push_back(channel);
  }
  return schema;
}

std::filesystem::path clip(const std::filesystem::path& data, const std::string& stem) {
  return data / "bandai-namco-nc/locomotion-normal" / ("dataset-2_" + stem + ".bvh");
}

// Raw features of one clip (what the database would hold before normalizing).
RawFeatures raw_features(const std::filesystem::path& file, const FeatureSchema& schema) {
  Result<BvhFile> bvh = load_bvh(file);
  EXPECT_TRUE(bvh.ok()) << bvh.message();
  Result<Motion> motion = motion_from_bvh(*bvh, {});
  EXPECT_TRUE(motion.ok()) << motion.message();
  Result<Motion> resampled = resample(*motion, 30.0f);
  Result<CharacterRoot> root = compute_character_root(*resampled, {});
  EXPECT_TRUE(root.ok()) << root.message();
  Result<RawFeatures> raw = extract_features(*resampled, *root, schema, {});
  EXPECT_TRUE(raw.ok()) << raw.message();
  return std::move(*raw);
}

class PoseQueryData : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto data = test::find_data_dir();
    if (!data) return;
    data_ = new std::filesystem::path(*data);
    Manifest manifest;
    manifest.source = "pose test";
    manifest.fps = 30.0f;
    manifest.schema = pose_schema();
    std::vector<std::string> stems = {"walk-turn-left_normal_001", "walk-turn-right_normal_001", "run_normal_001"};
    for (int i = 1; i <= 12; ++i) {
      char stem[40];
      std::snprintf(stem, sizeof(stem), "walk_normal_%03d", i);
      stems.push_back(stem);
    }
    for (const std::string& stem : stems) {
      ManifestClip meta;
      meta.file = clip(*data, stem);
      meta.name = stem;
      manifest.clips.push_back(std::move(meta));
    }
    Result<Database> db = build_database(manifest);
    EXPECT_TRUE(db.ok()) << db.message();
    if (db.ok()) db_ = new Database(std::move(*db));
  }
  static void TearDownTestSuite() {
    delete db_;
    delete data_;
    db_ = nullptr;
    data_ = nullptr;
  }
  void SetUp() override {
    if (!data_) GTEST_SKIP() << "motion data not found (set MMVK_DATA)";
    ASSERT_NE(db_, nullptr);
  }
  static inline Database* db_ = nullptr;
  static inline std::filesystem::path* data_ = nullptr;
};

float value(const RawFeatures& raw, const FeatureSchema& schema, std::uint32_t frame, std::size_t channel, int axis) {
  return raw.values[std::size_t{frame} * raw.dims + schema.offset(channel) + static_cast<std::uint32_t>(axis)];
}

// Held-out walk frames (walk_normal_020 is not in the database): the four
// end effectors' positions as targets. The stated distance: every matched
// effector within 12 cm of its target, and on average within 5 cm, far
// closer than an arbitrary frame of the database.
TEST_F(PoseQueryData, HeldOutTargetsRecoverAFrameWithNearbyEndEffectors) {
  const FeatureSchema schema = pose_schema();
  const RawFeatures held_out = raw_features(clip(*data_, "walk_normal_020"), schema);
  ReferenceSearch reference(*db_);
  std::mt19937 rng(3);
  double sum = 0.0;
  double worst = 0.0;
  double random_sum = 0.0;
  int count = 0;
  for (std::uint32_t f = 20; f + 20 < held_out.frame_count; f += 13) {
    std::vector<PoseTarget> targets;
    for (const char* bone : kEffectors) {
      std::size_t c = 0;
      while (schema.channels[c].kind != ChannelKind::BonePosition || schema.channels[c].bone != bone) ++c;
      targets.push_back({bone, glm::vec3(value(held_out, schema, f, c, 0), value(held_out, schema, f, c, 1),
                                         value(held_out, schema, f, c, 2)),
                         std::nullopt});
    }
    Result<PoseQuery> query = build_pose_query(*db_, targets);
    ASSERT_TRUE(query.ok()) << query.message();
    ASSERT_EQ(query->channels.size(), 4u);
    Match match;
    ASSERT_TRUE(reference.search({query->features, {&query->params, 1}, 1}, 1, {&match, 1}).ok());
    ASSERT_NE(match.frame, kNoFrame);
    const std::vector<PoseTargetError> errors = pose_target_errors(*db_, match.frame, targets);
    const std::uint32_t random_frame = std::uniform_int_distribution<std::uint32_t>(0, db_->frame_count() - 1)(rng);
    const std::vector<PoseTargetError> random_errors = pose_target_errors(*db_, random_frame, targets);
    for (std::size_t t = 0; t < targets.size(); ++t) {
      EXPECT_LT(errors[t].position_metres, 0.12f) << "held-out frame " << f << ", " << targets[t].bone;
      EXPECT_EQ(errors[t].velocity_metres_per_second, -1.0f);
      sum += errors[t].position_metres;
      worst = std::max(worst, double(errors[t].position_metres));
      random_sum += random_errors[t].position_metres;
      ++count;
    }
  }
  ASSERT_GT(count, 40);
  const double mean = sum / count;
  std::printf("pose matching, %d effector targets from held-out frames: mean %.4f m, worst %.4f m "
              "(a random database frame: mean %.4f m)\n", count, mean, worst, random_sum / count);
  EXPECT_LT(mean, 0.05);
  EXPECT_LT(mean * 3.0, random_sum / count);
}

TEST_F(PoseQueryData, QueryWeighsOnlyTheTargetedChannels) {
  const PoseTarget targets[] = {{"@left_foot", glm::vec3(0.1f, 0.1f, 0.2f), glm::vec3(0.0f, 0.0f, 1.0f)},
                                {"Hand_R", glm::vec3(-0.2f, 0.9f, 0.0f), std::nullopt}};
  Result<PoseQuery> query = build_pose_query(*db_, targets);
  ASSERT_TRUE(query.ok()) << query.message();
  const FeatureSchema& schema = db_->schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const bool targeted = schema.channels[c].name == "left_foot_position" ||
                          schema.channels[c].name == "left_foot_velocity" ||
                          schema.channels[c].name == "right_hand_position";  // Hand_R is @right_hand's joint
    EXPECT_EQ(query->params.channel_weights[c], targeted ? 1.0f : 0.0f) << schema.channels[c].name;
  }
  // Raw values round-trip through the normalization.
  const std::size_t c = 0;
  const std::uint32_t first = schema.offset(c);
  const DimNormalization& n = db_->normalization()[first];
  EXPECT_NEAR(query->features[first] * n.scale + n.offset, 0.1f, 1e-5f);
}

TEST_F(PoseQueryData, ErrorsNameTheTargetAndField) {
  const PoseTarget head[] = {{"@left_foot", glm::vec3(0.0f), std::nullopt}, {"@head", glm::vec3(0.0f), std::nullopt}};
  Result<PoseQuery> query = build_pose_query(*db_, head, "t.json");
  ASSERT_FALSE(query.ok());
  EXPECT_EQ(query.message().rfind("t.json: targets[1].position: the database has no bone_position channel for bone '@head' "
                                  "(it has: left_foot_position (@left_foot)", 0), 0u) << query.message();
  const PoseTarget twice[] = {{"@left_foot", glm::vec3(0.0f), std::nullopt}, {"Foot_L", glm::vec3(0.0f), std::nullopt}};
  query = build_pose_query(*db_, twice, "t.json");
  ASSERT_FALSE(query.ok());
  EXPECT_EQ(query.message(), "t.json: targets[1].position: channel 'left_foot_position' is already set by an earlier target");
  const PoseTarget velocity[] = {{"@left_hand", std::nullopt, glm::vec3(0.0f)}};
  query = build_pose_query(*db_, velocity, "t.json");
  ASSERT_FALSE(query.ok());
  EXPECT_NE(query.message().find("t.json: targets[0].velocity: the database has no bone_velocity or root_velocity"),
            std::string::npos) << query.message();
}

}  // namespace
}  // namespace mmvk
