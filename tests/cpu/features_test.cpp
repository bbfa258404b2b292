// Raw features of hand-made motions with known answers: character-space
// conventions, trajectory offsets, finite-difference velocities, the edge
// rule, looping, custom channels; then a database from in-memory motions.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "mmvk/database/database_build.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/features/normalization.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;

using test::walker;
using test::feature;
using test::root_of;

TEST(Features, StraightWalkInCharacterSpace) {
  const FeatureSchema schema = default_schema();
  for (float heading : {0.0f, 1.0f, -2.5f}) {
    SCOPED_TRACE(heading);
    const Motion motion = walker(60, 1.5f, heading);
    const CharacterRoot root = root_of(motion);
    Result<RawFeatures> raw = extract_features(motion, root, schema, {});
    ASSERT_TRUE(raw.ok()) << raw.message();
    ASSERT_EQ(raw->dims, 27u);
    const std::uint32_t f = 20;
    // Feet: the left foot is on the character's left (+X), 5 cm above ground.
    EXPECT_NEAR(feature(*raw, schema, f, "left_foot_position.x"), 0.1f, 1e-5f);
    EXPECT_NEAR(feature(*raw, schema, f, "left_foot_position.y"), 0.05f, 1e-5f);
    EXPECT_NEAR(feature(*raw, schema, f, "right_foot_position.x"), -0.1f, 1e-5f);
    EXPECT_NEAR(feature(*raw, schema, f, "left_foot_velocity.z"), 1.5f, 1e-3f);
    EXPECT_NEAR(feature(*raw, schema, f, "left_foot_velocity.x"), 0.0f, 1e-3f);
    EXPECT_NEAR(feature(*raw, schema, f, "hip_velocity.z"), 1.5f, 1e-3f);
    // Trajectory: straight ahead, 10, 20 and 30 frames on.
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_position[0].z"), 0.5f, 1e-4f);
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_position[1].z"), 1.0f, 1e-4f);
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_position[2].z"), 1.5f, 1e-4f);
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_position[2].x"), 0.0f, 1e-4f);
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_direction[2].z"), 1.0f, 1e-5f);
    EXPECT_NEAR(feature(*raw, schema, f, "trajectory_direction[2].x"), 0.0f, 1e-5f);
    // Non-looping: the last 30 frames run past the end and clamp.
    for (std::uint32_t g = 0; g < 60; ++g) EXPECT_EQ(raw->past_end[g], g + 30 > 59 ? 1 : 0) << g;
    EXPECT_NEAR(feature(*raw, schema, 40, "trajectory_position[2].z"), 1.5f * 19.0f / 30.0f, 1e-4f);
    // Looping: the trajectory wraps and keeps going.
    FeatureExtractionOptions loop;
    loop.loop = true;
    Result<RawFeatures> looped = extract_features(motion, root, schema, loop);
    ASSERT_TRUE(looped.ok()) << looped.message();
    EXPECT_NEAR(feature(*looped, schema, 40, "trajectory_position[2].z"), 1.5f, 1e-4f);
    EXPECT_NEAR(feature(*looped, schema, 59, "trajectory_position[2].z"), 1.5f, 1e-4f);
    for (std::uint8_t past : looped->past_end) EXPECT_EQ(past, 0);
  }
}

TEST(Features, TurningWalkIsTheSameFromAnyStartingHeading) {
  const FeatureSchema schema = default_schema();
  const Motion a = walker(90, 1.2f, 0.0f, 0.8f, 0.4f);
  const Motion b = walker(90, 1.2f, 2.0f, 0.8f, 0.4f);
  Result<RawFeatures> fa = extract_features(a, root_of(a), schema, {});
  Result<RawFeatures> fb = extract_features(b, root_of(b), schema, {});
  ASSERT_TRUE(fa.ok() && fb.ok());
  for (std::size_t i = 0; i < fa->values.size(); ++i) {
    ASSERT_NEAR(fa->values[i], fb->values[i], 2e-4f) << schema.dim_name(std::uint32_t(i % 27)) << " frame " << i / 27;
  }
  // Turning left (positive yaw rate, towards +X = the character's left).
  EXPECT_GT(feature(*fa, schema, 30, "trajectory_position[2].x"), 0.1f);
  EXPECT_GT(feature(*fa, schema, 30, "trajectory_direction[2].x"), 0.5f);
}

TEST(Features, ExtrapolateContinuesTheClipsSpeedAndTurningRate) {
  // A walk turning at a constant rate, and its first 60 frames: the cut
  // clip's extrapolated trajectory is where the full walk really went.
  const FeatureSchema schema = default_schema();
  const Motion full = walker(90, 1.2f, 0.3f, 0.8f, 0.4f);
  const Motion cut = walker(60, 1.2f, 0.3f, 0.8f, 0.4f);
  Result<RawFeatures> truth = extract_features(full, root_of(full), schema, {});
  FeatureExtractionOptions options;
  options.extrapolate_seconds = 0.1f;
  Result<RawFeatures> guess = extract_features(cut, root_of(cut), schema, options);
  ASSERT_TRUE(truth.ok() && guess.ok());
  for (std::uint32_t f = 30; f < 60; ++f) {
    for (const char* name : {"trajectory_position[2].x", "trajectory_position[2].z", "trajectory_direction[2].x",
                             "trajectory_direction[1].z"}) {
      EXPECT_NEAR(feature(*guess, schema, f, name), feature(*truth, schema, f, name), 1e-4f) << name << " " << f;
    }
  }
  EXPECT_GT(feature(*guess, schema, 59, "trajectory_position[2].x"), 0.3f) << "still turning left past the end";
  for (std::uint8_t past : guess->past_end) EXPECT_EQ(past, 0) << "extrapolated frames are not past the end";

  // Straight on past the end and back before the start, with past offsets.
  Result<FeatureSchema> past = parse_schema_json(
      R"({"channels": [{"name": "path", "kind": "trajectory_position", "offsets_seconds": [-0.5, 1.0]}]})", "s");
  ASSERT_TRUE(past.ok()) << past.message();
  const Motion straight = walker(40, 1.5f, 1.0f);
  Result<RawFeatures> line = extract_features(straight, root_of(straight), *past, options);
  ASSERT_TRUE(line.ok()) << line.message();
  EXPECT_NEAR(feature(*line, *past, 39, "path[1].z"), 1.5f, 1e-4f);
  EXPECT_NEAR(feature(*line, *past, 0, "path[0].z"), -0.75f, 1e-4f);
  EXPECT_NEAR(feature(*line, *past, 0, "path[0].x"), 0.0f, 1e-4f);

  // Phase windows still clamp at the edges and count as past the end.
  Result<FeatureSchema> phase = parse_schema_json(
      R"({"channels": [{"name": "path", "kind": "trajectory_position", "offsets_seconds": [1.0]},
                       {"name": "p", "kind": "phase", "curves": ["Foot_L.height"], "window_seconds": 0.2}]})",
      "s");
  ASSERT_TRUE(phase.ok()) << phase.message();
  const Motion swinging = walker(40, 1.5f, 0.0f, 0.0f, 0.4f);
  Result<RawFeatures> windows = extract_features(swinging, root_of(swinging), *phase, options);
  ASSERT_TRUE(windows.ok()) << windows.message();
  for (std::uint32_t f = 0; f < 40; ++f) EXPECT_EQ(windows->past_end[f], f < 6 || f + 6 > 39 ? 1 : 0) << f;

  // A looping clip wraps whatever the option says.
  options.loop = true;
  Result<RawFeatures> looped = extract_features(straight, root_of(straight), *past, options);
  FeatureExtractionOptions loop_only;
  loop_only.loop = true;
  Result<RawFeatures> wrapped = extract_features(straight, root_of(straight), *past, loop_only);
  ASSERT_TRUE(looped.ok() && wrapped.ok());
  EXPECT_EQ(looped->values, wrapped->values);
}

TEST(Features, CustomChannelsAndErrors) {
  FeatureSchema schema;
  FeatureChannel custom;
  custom.name = "phase";
  custom.kind = ChannelKind::Custom;
  custom.custom_dims = 2;
  FeatureChannel foot;
  foot.name = "foot";
  foot.kind = ChannelKind::BonePosition;
  foot.bone = "@left_foot";
  schema.channels = {custom, foot};
  const Motion motion = walker(10, 1.0f, 0.0f);
  const CharacterRoot root = root_of(motion);
  std::vector<std::vector<float>> values(1);
  for (int i = 0; i < 20; ++i) values[0].push_back(float(i) * 0.5f);
  FeatureExtractionOptions options;
  options.custom = values;
  options.source = "walk.bvh";
  Result<RawFeatures> raw = extract_features(motion, root, schema, options);
  ASSERT_TRUE(raw.ok()) << raw.message();
  EXPECT_EQ(raw->values[5 * 5 + 1], 5.5f);
  EXPECT_EQ(raw->past_end[9], 0) << "no trajectory channel, nothing runs past the end";

  values[0].pop_back();
  Result<RawFeatures> short_values = extract_features(motion, root, schema, options);
  ASSERT_FALSE(short_values.ok());
  EXPECT_NE(short_values.message().find("walk.bvh: channel 'phase': custom values hold 19 floats"), std::string::npos)
      << short_values.message();
  options.custom = {};
  EXPECT_FALSE(extract_features(motion, root, schema, options).ok());

  schema.channels = {foot};
  schema.channels[0].bone = "Tail";
  Result<RawFeatures> missing = extract_features(motion, root, schema, {.loop = false, .source = "walk.bvh", .custom = {}, .contacts = {}});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("walk.bvh: channel 'foot'"), std::string::npos) << missing.message();
  EXPECT_NE(missing.message().find("Tail"), std::string::npos) << missing.message();
}

TEST(Features, ResampleValuesInterpolatesLinearly) {
  const std::vector<float> values = {0.0f, 10.0f, 2.0f, 20.0f, 4.0f, 40.0f};  // 3 frames x 2 at 30 fps
  const std::vector<float> out = resample_values(values, 2, 3, 30.0f, 5, 60.0f);
  ASSERT_EQ(out.size(), 10u);
  EXPECT_FLOAT_EQ(out[2], 1.0f);
  EXPECT_FLOAT_EQ(out[3], 15.0f);
  EXPECT_FLOAT_EQ(out[8], 4.0f);
  EXPECT_EQ(offset_frames(1.0f / 3.0f, 30.0f), 10u);
  EXPECT_EQ(offset_frames(0.001f, 30.0f), 1u);
  EXPECT_EQ(max_offset_frames(default_schema(), 120.0f), 120u);
}

TEST(DatabaseFromMotions, FlagsTagsMirrorsAndNormalization) {
  std::vector<MotionClip> clips(3);
  clips[0].motion = walker(90, 1.2f, 0.0f, 0.5f, 0.4f);
  clips[0].meta.file = "a.bvh";
  clips[0].meta.name = "a";
  clips[0].meta.tags = {"walk"};
  clips[0].meta.do_not_use = {{0.0f, 0.5f}};            // frames 0..14
  clips[0].meta.block_transition = {{2.0f, 2.1f}};      // frames 60..62
  clips[1].motion = walker(60, 3.0f, 1.0f, -0.7f, 0.6f);
  clips[1].meta.file = "b.bvh";
  clips[1].meta.name = "b";
  clips[1].meta.tags = {"run", "walk"};
  clips[1].meta.loop = true;
  clips[1].meta.cost_multiplier = 2.0f;
  clips[1].meta.cost_bias = 0.5f;
  Result<Motion> mirrored = mirror(clips[0].motion);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  clips[2] = clips[0];
  clips[2].motion = std::move(*mirrored);
  clips[2].mirrored = true;

  MotionBuildSettings settings;
  settings.schema.channels[0].weight = 2.0f;
  settings.schema.channels[5].normalization = Normalization::PerDimStd;
  Result<Database> db = build_database_from_motions(clips, settings);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->frame_count(), 240u);
  ASSERT_EQ(db->clips().size(), 3u);
  EXPECT_EQ(db->clips()[2].name, "a_mirrored");
  EXPECT_TRUE(db->clips()[2].mirrored);
  EXPECT_EQ(db->clips()[1].first_frame, 90u);
  EXPECT_EQ(db->clips()[1].cost_multiplier, 2.0f);
  ASSERT_EQ(db->tag_names().size(), 2u + kGaitTagNames.size());  // the manifest's, then the measured gait tags
  EXPECT_EQ(db->tag_names()[0], "walk");
  EXPECT_EQ(db->tag_names()[2], kGaitTagNames[0]);
  EXPECT_EQ(db->clips()[1].tags, TagMask{3});
  std::uint32_t do_not_use = 0, block = 0, edge = 0;
  for (std::uint32_t f = 0; f < 240; ++f) {
    const std::uint32_t flags = db->frame_flags()[f];
    do_not_use += (flags & kFrameDoNotUse) != 0;
    block += (flags & kFrameBlockTransition) != 0;
    edge += (flags & kFrameEdgeExcluded) != 0;
    if (f >= 90 && f < 150) {
      EXPECT_EQ(flags & kFrameEdgeExcluded, 0u) << "looping clip, frame " << f;
    }
  }
  EXPECT_EQ(do_not_use, 2u * 15u);
  EXPECT_EQ(block, 2u * 3u);
  EXPECT_EQ(edge, 2u * 30u);
  EXPECT_EQ(db->frame_flags()[14] & kFrameDoNotUse, kFrameDoNotUse);
  EXPECT_EQ(db->frame_flags()[15] & kFrameDoNotUse, 0u);

  // Mirroring flips the sideways features of the turning walk.
  const std::uint32_t x = db->schema().offset(5) + 4;  // trajectory_position[2].x
  const auto raw = [&](std::uint32_t f, std::uint32_t d) {
    return db->row(f)[d] * db->normalization()[d].scale + db->normalization()[d].offset;
  };
  EXPECT_NEAR(raw(40, x), -raw(150 + 40, x), 1e-3f);

  // Normalized channels: mean 0, spread = weight.
  const std::vector<DimStatistics> stats = compute_statistics(db->features(), db->dims());
  double group = 0.0;
  for (std::uint32_t d = 0; d < 3; ++d) {
    EXPECT_NEAR(stats[d].mean, 0.0, 1e-4);
    group += stats[d].std / 3.0;
  }
  EXPECT_NEAR(group, 2.0, 1e-4);
  for (std::uint32_t d = db->schema().offset(5); d < db->schema().offset(6); ++d) EXPECT_NEAR(stats[d].std, 1.0, 1e-4);

  // Clamp keeps the edge frames.
  settings.edge_rule = EdgeRule::Clamp;
  Result<Database> clamped = build_database_from_motions(clips, settings);
  ASSERT_TRUE(clamped.ok()) << clamped.message();
  for (std::uint32_t flags : clamped->frame_flags()) EXPECT_EQ(flags & kFrameEdgeExcluded, 0u);

  // Extrapolate keeps them too, with the trajectory continued instead of
  // clamped (the turning walk's last frame still looks 1 s ahead), all but
  // the last kExtrapolateEndSeconds (6 frames) of the non-looping clips.
  settings.edge_rule = EdgeRule::Extrapolate;
  Result<Database> extrapolated = build_database_from_motions(clips, settings);
  ASSERT_TRUE(extrapolated.ok()) << extrapolated.message();
  for (std::uint32_t f = 0; f < 240; ++f) {
    const bool end = (f >= 84 && f < 90) || f >= 234;  // clips 0 and 2 end at 90 and 240; clip 1 loops
    EXPECT_EQ(extrapolated->frame_flags()[f] & kFrameEdgeExcluded, end ? kFrameEdgeExcluded : 0u) << f;
  }
  const std::uint32_t z = db->schema().offset(5) + 5;  // trajectory_position[2].z
  const auto raw_of = [&](const Database& d, std::uint32_t f) {
    return d.row(f)[z] * d.normalization()[z].scale + d.normalization()[z].offset;
  };
  EXPECT_LT(raw_of(*clamped, 89), 0.01f);
  EXPECT_GT(raw_of(*extrapolated, 89), 0.9f);

  // Mixed rates name the files.
  clips[1].motion.fps = 60.0f;
  Result<Database> mixed = build_database_from_motions(clips, settings);
  ASSERT_FALSE(mixed.ok());
  EXPECT_NE(mixed.message().find("b.bvh"), std::string::npos) << mixed.message();
}

// 64 tags in all: the measured gait tags (gait_bands.hpp) count, 58 of the
// manifest's with them, 64 without.
TEST(DatabaseFromMotions, AtMost64Tags) {
  std::vector<MotionClip> clips(2);
  for (MotionClip& clip : clips) {
    clip.motion = walker(40, 1.0f + float(&clip - clips.data()), 0.0f, 0.5f, 0.3f);
    clip.meta.file = "c.bvh";
    clip.meta.name = "c";
  }
  // Appending rather than "t" + std::to_string(t): GCC 12 at -O3 warns
  // (-Wrestrict, a known false positive) on the latter here.
  auto tag = [](int t) { return std::string("t").append(std::to_string(t)); };
  for (int t = 0; t < 40; ++t) clips[0].meta.tags.push_back(tag(t));
  for (int t = 30; t < 58; ++t) clips[1].meta.tags.push_back(tag(t));
  Result<Database> full = build_database_from_motions(clips, {});
  ASSERT_TRUE(full.ok()) << full.message();
  EXPECT_EQ(full->tag_names().size(), 64u);
  EXPECT_EQ(full->clips()[1].tags, (~TagMask{0} << 30) & ~(~TagMask{0} << 58));
  clips[1].meta.tags.push_back("t58");
  Result<Database> no_room = build_database_from_motions(clips, {});
  ASSERT_FALSE(no_room.ok());
  EXPECT_NE(no_room.message().find("59 tags and the 6 measured gait tags are more than 64"), std::string::npos)
      << no_room.message();
  MotionBuildSettings unmeasured;
  unmeasured.gait_bands.enabled = false;
  for (int t = 59; t < 64; ++t) clips[1].meta.tags.push_back(tag(t));
  Result<Database> own = build_database_from_motions(clips, unmeasured);
  ASSERT_TRUE(own.ok()) << own.message();
  EXPECT_EQ(own->tag_names().size(), 64u);
  EXPECT_EQ(own->clips()[1].tags, ~TagMask{0} << 30);
  clips[1].meta.tags.push_back("one_too_many");
  Result<Database> over = build_database_from_motions(clips, unmeasured);
  ASSERT_FALSE(over.ok());
  EXPECT_NE(over.message().find("more than 64 distinct tags"), std::string::npos) << over.message();
  EXPECT_NE(over.message().find("one_too_many"), std::string::npos) << over.message();
}

}  // namespace
}  // namespace mmvk
