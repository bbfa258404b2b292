// The channel kinds of issue 12 on hand-made motions with known answers:
// the past trajectory and its edges, the root's turning rate, foot contacts
// (the animation's own detection), limb vectors (independent of the
// character's size) and phase (frequency, advance, mirroring), with the
// errors each names.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "mmvk/database/database_build.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/query/query_assembly.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk {
namespace {

constexpr float kRate = 30.0f;

struct Gait {
  std::uint32_t frames = 90;
  float speed = 1.2f;       // m/s along the facing
  float turn_rate = 0.0f;   // rad/s, positive = turning left
  float step_hz = 1.5f;     // leg cycles per second
  float swing = 0.4f;       // radians
  bool planted = false;     // each leg swings half the cycle and rests the other half
  float scale = 1.0f;       // every length of the skeleton and of the root path
};

// A biped with Bandai-style joint names (the roles resolve): legs with toes,
// arms hanging from the shoulders.
Motion biped(const Gait& gait) {
  Motion m;
  m.skeleton.names = {"Hips",      "UpperLeg_L", "LowerLeg_L", "Foot_L",    "Toes_L",    "UpperLeg_R", "LowerLeg_R",
                      "Foot_R",    "Toes_R",     "Chest",      "UpperArm_L", "LowerArm_L", "Hand_L",    "UpperArm_R",
                      "LowerArm_R", "Hand_R"};
  m.skeleton.parents = {-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 9, 13, 14};
  const float s = gait.scale;
  m.skeleton.rest_offsets = {
      glm::vec3(0, 1, 0) * s,        glm::vec3(0.1f, -0.05f, 0) * s, glm::vec3(0, -0.45f, 0) * s,
      glm::vec3(0, -0.45f, 0) * s,   glm::vec3(0, -0.04f, 0.12f) * s, glm::vec3(-0.1f, -0.05f, 0) * s,
      glm::vec3(0, -0.45f, 0) * s,   glm::vec3(0, -0.45f, 0) * s,     glm::vec3(0, -0.04f, 0.12f) * s,
      glm::vec3(0, 0.45f, 0) * s,    glm::vec3(0.18f, 0, 0) * s,      glm::vec3(0, -0.3f, 0) * s,
      glm::vec3(0, -0.28f, 0) * s,   glm::vec3(-0.18f, 0, 0) * s,     glm::vec3(0, -0.3f, 0) * s,
      glm::vec3(0, -0.28f, 0) * s};
  m.fps = kRate;
  m.frame_count = gait.frames;
  glm::vec3 position(0.0f, s, 0.0f);
  float yaw = 0.3f;
  const glm::vec3 x_axis(1, 0, 0);
  for (std::uint32_t f = 0; f < gait.frames; ++f) {
    const float cycle = std::sin(2.0f * std::numbers::pi_v<float> * gait.step_hz * float(f) / kRate);
    const float left = gait.planted ? std::max(cycle, 0.0f) : cycle;
    const float right = gait.planted ? std::max(-cycle, 0.0f) : -cycle;
    std::vector<glm::quat> q(m.skeleton.size(), glm::quat(1, 0, 0, 0));
    q[0] = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    q[1] = glm::angleAxis(-gait.swing * left, x_axis);
    q[2] = glm::angleAxis(0.5f * gait.swing * left, x_axis);  // the knee bends while the leg swings
    q[5] = glm::angleAxis(-gait.swing * right, x_axis);
    q[6] = glm::angleAxis(0.5f * gait.swing * right, x_axis);
    q[10] = glm::angleAxis(0.5f * gait.swing * right, x_axis);  // arms swing against the legs
    q[13] = glm::angleAxis(0.5f * gait.swing * left, x_axis);
    for (std::size_t j = 0; j < m.skeleton.size(); ++j) {
      m.local_positions.push_back(j == 0 ? position : m.skeleton.rest_offsets[j]);
      m.local_rotations.push_back(q[j]);
    }
    position += glm::vec3(std::sin(yaw), 0.0f, std::cos(yaw)) * (s * gait.speed / kRate);
    yaw += gait.turn_rate / kRate;
  }
  return m;
}

using test::feature;
using test::root_of;

Result<FeatureSchema> schema_of(const std::string& channels) {
  return parse_schema_json(R"({"channels": [)" + channels + "]}", "test.json");
}

Result<RawFeatures> extract(const Motion& motion, const FeatureSchema& schema, bool loop = false) {
  FeatureExtractionOptions options;
  options.loop = loop;
  options.source = "walk.bvh";
  return extract_features(motion, root_of(motion), schema, options);
}

TEST(PastTrajectory, LooksBackAndFollowsTheEdgeRuleAtTheStart) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "path", "kind": "trajectory_position", "offsets_seconds": [-0.5, -0.2, 0.2]},
         {"name": "dir", "kind": "trajectory_direction", "offsets_seconds": [-0.5]})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Gait gait;
  gait.turn_rate = 0.0f;
  const Motion motion = biped(gait);
  Result<RawFeatures> raw = extract(motion, *schema);
  ASSERT_TRUE(raw.ok()) << raw.message();
  // 15 frames back, 6 back, 6 ahead: 1.2 m/s straight ahead.
  EXPECT_NEAR(feature(*raw, *schema, 40, "path[0].z"), -0.6f, 1e-4f);
  EXPECT_NEAR(feature(*raw, *schema, 40, "path[1].z"), -0.24f, 1e-4f);
  EXPECT_NEAR(feature(*raw, *schema, 40, "path[2].z"), 0.24f, 1e-4f);
  EXPECT_NEAR(feature(*raw, *schema, 40, "path[0].x"), 0.0f, 1e-4f);
  EXPECT_NEAR(feature(*raw, *schema, 40, "dir[0].z"), 1.0f, 1e-5f);
  // Before the start: clamped to frame 0 and flagged, like the end.
  EXPECT_NEAR(feature(*raw, *schema, 5, "path[0].z"), -1.2f * 5.0f / 30.0f, 1e-4f);
  for (std::uint32_t f = 0; f < gait.frames; ++f) {
    EXPECT_EQ(raw->past_end[f], f < 15 || f + 6 > gait.frames - 1 ? 1 : 0) << f;
  }
  // Looping: the path continues before frame 0 and nothing is flagged.
  Result<RawFeatures> looped = extract(motion, *schema, true);
  ASSERT_TRUE(looped.ok()) << looped.message();
  EXPECT_NEAR(feature(*looped, *schema, 5, "path[0].z"), -0.6f, 1e-4f);
  EXPECT_NEAR(feature(*looped, *schema, 5, "path[0].x"), 0.0f, 1e-4f);
  for (std::uint8_t past : looped->past_end) EXPECT_EQ(past, 0);

  // A database flags the start frames too.
  std::vector<MotionClip> clips(1);
  clips[0].motion = motion;
  clips[0].meta.file = "walk.bvh";
  clips[0].meta.name = "walk";
  MotionBuildSettings settings;
  settings.schema.channels = {schema->channels[0]};  // the straight walk's directions are constant
  settings.animation.enabled = false;
  Result<Database> db = build_database_from_motions(clips, settings);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->frame_flags()[14] & kFrameEdgeExcluded, kFrameEdgeExcluded);
  EXPECT_EQ(db->frame_flags()[15] & kFrameEdgeExcluded, 0u);
}

TEST(PastTrajectory, TurningLoopIsContinuousAcrossTheStart) {
  Result<FeatureSchema> schema =
      schema_of(R"({"name": "path", "kind": "trajectory_position", "offsets_seconds": [-1.0]})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Gait gait;
  gait.turn_rate = 0.6f;
  gait.frames = 120;
  Result<RawFeatures> looped = extract(biped(gait), *schema, true);
  ASSERT_TRUE(looped.ok()) << looped.message();
  // A steady turn: the point 1 s back is the same in character space on
  // every frame, whether it lies inside the clip or in the cycle before.
  const float x = feature(*looped, *schema, 100, "path[0].x");
  const float z = feature(*looped, *schema, 100, "path[0].z");
  EXPECT_GT(x, 0.05f) << "on a left turn the whole circle, past included, lies to the left";
  for (std::uint32_t f : {0u, 10u, 29u, 31u, 60u}) {
    EXPECT_NEAR(feature(*looped, *schema, f, "path[0].x"), x, 2e-3f) << f;
    EXPECT_NEAR(feature(*looped, *schema, f, "path[0].z"), z, 2e-3f) << f;
  }
}

TEST(PastTrajectory, AnOffsetBeyondTheEdgesIsAnErrorNamingFileAndField) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "path", "kind": "trajectory_position", "offsets_seconds": [0.5, -2.5]})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Result<RawFeatures> raw = extract(biped(Gait{}), *schema);
  ASSERT_FALSE(raw.ok());
  EXPECT_NE(raw.message().find("walk.bvh"), std::string::npos) << raw.message();
  EXPECT_NE(raw.message().find("channel 'path': offsets_seconds[1]"), std::string::npos) << raw.message();
  // Looping clips wrap, so any reach is fine.
  EXPECT_TRUE(extract(biped(Gait{}), *schema, true).ok());
}

TEST(PastTrajectory, CrowdQueriesCopyThePastFromTheFrame) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "path", "kind": "trajectory_position", "offsets_seconds": [-0.5, 0.2, -0.2, 0.6]},
         {"name": "foot", "kind": "bone_position", "bone": "@left_foot"})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Gait gait;
  gait.turn_rate = 0.5f;
  std::vector<MotionClip> clips(1);
  clips[0].motion = biped(gait);
  clips[0].meta.file = "walk.bvh";
  clips[0].meta.name = "walk";
  MotionBuildSettings settings;
  settings.schema = *schema;
  Result<Database> db = build_database_from_motions(clips, settings);
  ASSERT_TRUE(db.ok()) << db.message();
  Result<QueryAssembler> assembler = QueryAssembler::create(*db);
  ASSERT_TRUE(assembler.ok()) << assembler.message();
  // The predictor fills the future offsets only.
  ASSERT_EQ(assembler->trajectory_offsets().size(), 2u);
  EXPECT_EQ(assembler->trajectory_offsets()[0], 0.2f);
  EXPECT_EQ(assembler->trajectory_offsets()[1], 0.6f);
  const glm::vec3 positions[2] = {{0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 2.0f}};
  const float yaws[2] = {0.0f, 0.0f};
  std::vector<float> query(db->dims());
  assembler->assemble(40, QueryFrame{}, positions, yaws, query);
  for (std::uint32_t d : {0u, 1u, 4u, 5u, 8u, 9u, 10u}) EXPECT_EQ(query[d], db->row(40)[d]) << db->schema().dim_name(d);
  const auto raw = [&](std::uint32_t d) { return query[d] * db->normalization()[d].scale + db->normalization()[d].offset; };
  EXPECT_NEAR(raw(3), 1.0f, 1e-5f);  // path[1].z, predicted
  EXPECT_NEAR(raw(7), 2.0f, 1e-5f);  // path[3].z, predicted
}

TEST(RootAngularVelocity, IsTheTurningRateAndNegatesWhenMirrored) {
  Result<FeatureSchema> schema = schema_of(R"({"name": "turn", "kind": "root_angular_velocity"})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Gait gait;
  gait.turn_rate = 0.8f;
  const Motion motion = biped(gait);
  Result<RawFeatures> raw = extract(motion, *schema);
  ASSERT_TRUE(raw.ok()) << raw.message();
  Result<Motion> mirrored = mirror(motion);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  Result<RawFeatures> flipped = extract(*mirrored, *schema);
  ASSERT_TRUE(flipped.ok()) << flipped.message();
  for (std::uint32_t f = 0; f < gait.frames; ++f) {
    EXPECT_NEAR(raw->values[f], 0.8f, 1e-3f) << f;
    EXPECT_NEAR(flipped->values[f], -raw->values[f], 1e-4f) << f;
  }
}

TEST(FootContact, IsTheAnimationsContactsAndSwapsWhenMirrored) {
  Gait gait;
  gait.speed = 0.0f;
  gait.planted = true;
  gait.frames = 120;
  std::vector<MotionClip> clips(2);
  clips[0].motion = biped(gait);
  clips[0].meta.file = "steps.bvh";
  clips[0].meta.name = "steps";
  Result<Motion> mirrored = mirror(clips[0].motion);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  clips[1] = clips[0];
  clips[1].motion = std::move(*mirrored);
  clips[1].mirrored = true;
  Result<FeatureSchema> schema = schema_of(R"({"name": "contact", "kind": "foot_contact"},
      {"name": "foot", "kind": "bone_position", "bone": "@left_foot"})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  MotionBuildSettings settings;
  settings.schema = *schema;
  Result<Database> db = build_database_from_motions(clips, settings);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_NE(db->animation(), nullptr);
  const auto raw = [&](std::uint32_t f, std::uint32_t d) {
    return db->row(f)[d] * db->normalization()[d].scale + db->normalization()[d].offset;
  };
  std::uint32_t left = 0, right = 0;
  for (std::uint32_t f = 0; f < db->frame_count(); ++f) {
    const std::uint8_t bits = db->animation()->contacts[f];
    EXPECT_NEAR(raw(f, 0), (bits & kContactLeft) ? 1.0f : 0.0f, 1e-5f) << f;
    EXPECT_NEAR(raw(f, 1), (bits & kContactRight) ? 1.0f : 0.0f, 1e-5f) << f;
    if (f < gait.frames) {
      left += (bits & kContactLeft) != 0;
      right += (bits & kContactRight) != 0;
      EXPECT_NEAR(raw(f, 0), raw(gait.frames + f, 1), 1e-5f) << "mirrored: left is the source's right, frame " << f;
      EXPECT_NEAR(raw(f, 1), raw(gait.frames + f, 0), 1e-5f) << "mirrored: right is the source's left, frame " << f;
    }
  }
  EXPECT_GT(left, 20u);
  EXPECT_GT(right, 20u);
  EXPECT_LT(left, gait.frames - 20);
}

TEST(LimbVector, DoesNotChangeWithTheCharactersSize) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "left_leg", "kind": "limb_vector", "limb": "left_leg"},
         {"name": "right_arm", "kind": "limb_vector", "limb": "right_arm"},
         {"name": "hand", "kind": "bone_position", "bone": "@right_hand"})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  EXPECT_EQ(schema->channels[1].bone, "@right_shoulder");
  EXPECT_EQ(schema->channels[1].second_bone, "@right_hand");
  Gait gait;
  gait.turn_rate = 0.4f;
  Result<RawFeatures> base = extract(biped(gait), *schema);
  ASSERT_TRUE(base.ok()) << base.message();
  for (float scale : {0.8f, 1.25f}) {
    SCOPED_TRACE(scale);
    gait.scale = scale;
    Result<RawFeatures> scaled = extract(biped(gait), *schema);
    ASSERT_TRUE(scaled.ok()) << scaled.message();
    float worst = 0.0f;
    for (std::uint32_t f = 0; f < gait.frames; ++f) {
      for (std::uint32_t d = 0; d < 6; ++d) {
        const std::size_t i = std::size_t{f} * base->dims + d;
        worst = std::max(worst, std::abs(scaled->values[i] - base->values[i]));
      }
      for (std::uint32_t d = 6; d < 9; ++d) {  // raw positions scale
        const std::size_t i = std::size_t{f} * base->dims + d;
        EXPECT_NEAR(scaled->values[i], scale * base->values[i], 1e-4f);
      }
    }
    EXPECT_LT(worst, 1e-4f);
    EXPECT_GT(std::abs(feature(*scaled, *schema, 10, "hand.y") - feature(*base, *schema, 10, "hand.y")), 0.05f);
  }
  // A stretched leg points straight down with length 1 (the rest pose at frame 0).
  gait.scale = 1.0f;
  gait.swing = 0.0f;
  Result<RawFeatures> rest = extract(biped(gait), *schema);
  ASSERT_TRUE(rest.ok()) << rest.message();
  const glm::vec3 leg(feature(*rest, *schema, 0, "left_leg.x"), feature(*rest, *schema, 0, "left_leg.y"),
                      feature(*rest, *schema, 0, "left_leg.z"));
  EXPECT_NEAR(leg.y, -(0.05f + 0.9f) / (std::sqrt(0.1f * 0.1f + 0.05f * 0.05f) + 0.9f), 1e-5f);
  EXPECT_NEAR(leg.x, 0.1f / (std::sqrt(0.1f * 0.1f + 0.05f * 0.05f) + 0.9f), 1e-5f);
}

TEST(LimbVector, UnknownLimbsAndRolesAreNamed) {
  Result<FeatureSchema> limb = schema_of(R"({"name": "tail", "kind": "limb_vector", "limb": "tail"})");
  ASSERT_FALSE(limb.ok());
  EXPECT_NE(limb.message().find("test.json: channels[0].limb: unknown limb \"tail\""), std::string::npos)
      << limb.message();
  EXPECT_NE(limb.message().find("\"left_arm\""), std::string::npos) << limb.message();
  Result<FeatureSchema> role =
      schema_of(R"({"name": "arm", "kind": "limb_vector", "bone": "@left_elbow", "second_bone": "@left_hand"})");
  ASSERT_TRUE(role.ok()) << role.message();
  Result<RawFeatures> raw = extract(biped(Gait{}), *role);
  ASSERT_FALSE(raw.ok());
  EXPECT_NE(raw.message().find("walk.bvh: channel 'arm'"), std::string::npos) << raw.message();
  EXPECT_NE(raw.message().find("unknown bone role '@left_elbow'"), std::string::npos) << raw.message();
  EXPECT_NE(raw.message().find("@left_shoulder"), std::string::npos) << "the known roles are listed";
  Result<FeatureSchema> crossed =
      schema_of(R"({"name": "arm", "kind": "limb_vector", "bone": "@left_shoulder", "second_bone": "@right_hand"})");
  ASSERT_TRUE(crossed.ok()) << crossed.message();
  raw = extract(biped(Gait{}), *crossed);
  ASSERT_FALSE(raw.ok());
  EXPECT_NE(raw.message().find("does not hang below bone '@left_shoulder'"), std::string::npos) << raw.message();
}

// The phase of curve c, in cycles, at every frame.
std::vector<double> phases(const RawFeatures& raw, std::uint32_t first) {
  std::vector<double> out;
  for (std::uint32_t f = 0; f < raw.frame_count; ++f) {
    const float* row = raw.values.data() + std::size_t{f} * raw.dims + first;
    out.push_back(std::atan2(row[0], row[1]) / (2.0 * std::numbers::pi));
  }
  return out;
}

// Wrapped phase difference in (-0.5, 0.5] cycles.
double advance(double from, double to) {
  double d = to - from;
  d -= std::round(d);
  return d;
}

TEST(Phase, AdvancesAtTheGaitFrequency) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "foot", "kind": "bone_position", "bone": "@left_foot"},
         {"name": "phase", "kind": "phase", "curves": ["foot.z", "@left_toe.height"], "window_seconds": 1.0})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  ASSERT_EQ(schema->dims(), 7u);
  EXPECT_EQ(schema->dim_name(5), "phase[1].sin");
  Gait gait;
  gait.frames = 150;
  gait.step_hz = 1.25f;
  gait.planted = true;
  Result<RawFeatures> raw = extract(biped(gait), *schema);
  ASSERT_TRUE(raw.ok()) << raw.message();
  for (std::uint32_t curve = 0; curve < 2; ++curve) {
    SCOPED_TRACE(curve);
    const std::vector<double> phi = phases(*raw, 3 + 2 * curve);
    double total = 0.0;
    // Inside the edges (30 frames each side): monotonic, at 1.25 Hz.
    for (std::uint32_t f = 31; f + 30 < gait.frames; ++f) {
      const double step = advance(phi[f - 1], phi[f]);
      EXPECT_GT(step, 0.0) << f;
      total += step;
    }
    const double hz = total / (double(gait.frames - 61) / kRate);
    EXPECT_NEAR(hz, 1.25, 0.05);
    // Amplitude: the sin/cos pair's length is positive and steady.
    const float* row = raw->values.data() + std::size_t{75} * raw->dims + 3 + 2 * curve;
    EXPECT_GT(std::hypot(row[0], row[1]), 1e-3f);
  }
  for (std::uint32_t f = 0; f < gait.frames; ++f) EXPECT_EQ(raw->past_end[f], f < 30 || f + 30 >= gait.frames);
}

TEST(Phase, PureSineGivesItsAmplitudeAndPhase) {
  // A column curve x(t) = 0.3 sin(2 pi 2 t) + 0.1: at frame f, its phase in
  // the convention x = a cos(2 pi (nu t + phi)) is nu t - 1/4.
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "turn", "kind": "root_angular_velocity"},
         {"name": "phase", "kind": "phase", "curves": ["turn.yaw"], "window_seconds": 1.0})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  // The turning rate is the curve: yaw(t) integrates 0.3 sin(4 pi t) + 0.1.
  Gait gait;
  gait.frames = 120;
  Motion motion = biped(gait);
  CharacterRoot root = root_of(motion);
  for (std::uint32_t f = 0; f < gait.frames; ++f) {
    const double t = f / double(kRate);
    const double yaw = 0.1 * t - 0.3 / (4.0 * std::numbers::pi) * std::cos(4.0 * std::numbers::pi * t);
    root.facings[f] = glm::vec3(std::sin(yaw), 0.0, std::cos(yaw));
  }
  Result<RawFeatures> raw = extract_features(motion, root, *schema, {});
  ASSERT_TRUE(raw.ok()) << raw.message();
  for (std::uint32_t f : {40u, 55u, 70u}) {
    const float* row = raw->values.data() + std::size_t{f} * raw->dims + 1;
    const double expected = 2.0 * f / double(kRate) - 0.25;
    EXPECT_NEAR(std::hypot(row[0], row[1]), 0.3, 0.02) << f;
    EXPECT_NEAR(advance(expected, std::atan2(row[0], row[1]) / (2.0 * std::numbers::pi)), 0.0, 0.02) << f;
  }
}

TEST(Phase, MirroredClipsSwapLeftAndRight) {
  Result<FeatureSchema> schema = schema_of(
      R"({"name": "phase", "kind": "phase", "curves": ["@left_foot.height", "@right_foot.height"]})");
  ASSERT_TRUE(schema.ok()) << schema.message();
  Gait gait;
  gait.frames = 120;
  gait.planted = true;
  gait.turn_rate = 0.3f;
  const Motion motion = biped(gait);
  Result<Motion> mirrored = mirror(motion);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  Result<RawFeatures> a = extract(motion, *schema);
  Result<RawFeatures> b = extract(*mirrored, *schema);
  ASSERT_TRUE(a.ok() && b.ok());
  double differ = 0.0;
  for (std::uint32_t f = 0; f < gait.frames; ++f) {
    for (std::uint32_t d = 0; d < 2; ++d) {
      EXPECT_NEAR(b->values[f * 4 + d], a->values[f * 4 + 2 + d], 1e-4f) << f;
      EXPECT_NEAR(b->values[f * 4 + 2 + d], a->values[f * 4 + d], 1e-4f) << f;
      differ += std::abs(a->values[f * 4 + d] - a->values[f * 4 + 2 + d]);
    }
  }
  EXPECT_GT(differ, 1.0) << "the two feet are out of phase, so the swap shows";
}

TEST(Phase, ErrorsNameFileChannelAndField) {
  Result<FeatureSchema> wide =
      schema_of(R"({"name": "phase", "kind": "phase", "curves": ["@left_foot.height"], "window_seconds": 2.0})");
  ASSERT_TRUE(wide.ok()) << wide.message();
  Result<RawFeatures> raw = extract(biped(Gait{}), *wide);
  ASSERT_FALSE(raw.ok());
  EXPECT_NE(raw.message().find("walk.bvh: channel 'phase': window_seconds"), std::string::npos) << raw.message();
  EXPECT_NE(raw.message().find("longer than the clip (90 frames)"), std::string::npos) << raw.message();
  Result<FeatureSchema> curve = schema_of(R"({"name": "phase", "kind": "phase", "curves": ["@left_foot.colour"]})");
  ASSERT_TRUE(curve.ok()) << curve.message();
  raw = extract(biped(Gait{}), *curve);
  ASSERT_FALSE(raw.ok());
  EXPECT_NE(raw.message().find("walk.bvh: channel 'phase': curves[0]: \"@left_foot.colour\""), std::string::npos)
      << raw.message();
  EXPECT_NE(schema_of(R"({"name": "p", "kind": "phase", "curves": []})").message().find("curves is empty"),
            std::string::npos);
  EXPECT_NE(schema_of(R"({"name": "p", "kind": "phase", "curves": ["a.speed"], "window_seconds": 0})")
                .message()
                .find("window_seconds must be finite and > 0"),
            std::string::npos);
  EXPECT_NE(schema_of(R"({"name": "p", "kind": "bone_position", "bone": "Hips", "curves": ["a.speed"]})")
                .message()
                .find("channels[0].curves: a bone_position channel reads no curves"),
            std::string::npos);
}

}  // namespace
}  // namespace mmvk
