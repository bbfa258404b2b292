// The animation runtime on synthetic data: springs, inertialization,
// trajectory prediction, query assembly, format 1 files, and the errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mmvk/common/hash.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/query/query_assembly.hpp"
#include "mmvk/search/reference_search.hpp"
#include "mmvk/animation/spring.hpp"
#include "mmvk/animation/trajectory.hpp"

namespace mmvk {
namespace {

// A small database with an 11-joint animation: one 60-frame looping clip of
// a root walking along +Z at 1 m/s, a spine swinging about X, legs (which the
// default schema's foot channels name) standing straight.
DatabaseParts make_parts(bool animation, FeatureSchema schema = default_schema()) {
  DatabaseParts parts;
  parts.schema = std::move(schema);
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  const std::uint32_t frames = 60;
  for (std::uint32_t d = 0; d < dims; ++d) parts.normalization.push_back({0.1f * float(d), 1.0f + 0.05f * float(d)});
  Clip clip;
  clip.name = "walk";
  clip.source = "walk.bvh";
  clip.loop = true;
  clip.frame_count = frames;
  parts.clips.push_back(clip);
  parts.frame_flags.assign(frames, 0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (std::uint32_t i = 0; i < frames * dims; ++i) parts.features.push_back(uniform(rng));
  if (animation) {
    AnimationData a;
    a.skeleton.names = {"Hips",        "Spine",      "Head",     "LeftUpLeg", "LeftLeg",     "LeftFoot",
                        "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"};
    a.skeleton.parents = {-1, 0, 1, 0, 3, 4, 5, 0, 7, 8, 9};
    a.skeleton.rest_offsets = {glm::vec3(0.0f, 1.0f, 0.0f),   glm::vec3(0.0f, 0.3f, 0.0f),
                               glm::vec3(0.0f, 0.4f, 0.0f),   glm::vec3(0.1f, -0.05f, 0.0f),
                               glm::vec3(0.0f, -0.45f, 0.0f), glm::vec3(0.0f, -0.42f, 0.0f),
                               glm::vec3(0.0f, -0.06f, 0.12f), glm::vec3(-0.1f, -0.05f, 0.0f),
                               glm::vec3(0.0f, -0.45f, 0.0f), glm::vec3(0.0f, -0.42f, 0.0f),
                               glm::vec3(0.0f, -0.06f, 0.12f)};
    a.mirror_pairs = {0, 1, 2, 7, 8, 9, 10, 3, 4, 5, 6};
    a.translated_joints = {0};
    a.frame_count = frames;
    for (std::uint32_t f = 0; f < frames; ++f) {
      const float t = float(f) / parts.fps;
      a.local_rotations.push_back(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
      a.local_rotations.push_back(glm::angleAxis(0.5f * std::sin(6.0f * t), glm::vec3(1.0f, 0.0f, 0.0f)));
      a.local_rotations.push_back(glm::angleAxis(0.2f * t, glm::vec3(0.0f, 1.0f, 0.0f)));
      for (int leg = 0; leg < 8; ++leg) a.local_rotations.push_back(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
      a.local_translations.push_back(glm::vec3(0.0f, 1.0f + 0.05f * std::sin(12.0f * t), 0.0f));
      a.root_positions.push_back(glm::vec3(0.0f, 0.0f, t));
      a.root_yaws.push_back(0.0f);
      a.contacts.push_back(f % 30 < 15 ? kContactLeft : kContactRight);
    }
    parts.animation = std::move(a);
  }
  return parts;
}

Database make_database(bool animation, FeatureSchema schema = default_schema()) {
  Result<Database> db = Database::create(make_parts(animation, std::move(schema)));
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

// From the relative rotation's vector part: accurate for small angles, where
// acos of a dot product near 1 is not.
float angle_between(const glm::quat& a, const glm::quat& b) {
  const glm::quat d = glm::conjugate(a) * b;
  return 2.0f * std::atan2(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::abs(d.w));
}

TEST(Spring, OffsetDecaysToOnePercentWithinFiveHalfLives) {
  const float half_life = 0.1f;
  float x = 1.0f;
  float v = 0.0f;
  float t = 0.0f;
  const float dt = 1.0f / 60.0f;
  float at_one = 0.0f;
  while (t < 5.0f * half_life - 1e-6f) {
    spring_decay(x, v, half_life, dt);
    t += dt;
    if (std::abs(t - half_life) < dt / 2) at_one = x;
    EXPECT_GE(x, 0.0f);  // critically damped: no overshoot
  }
  EXPECT_LT(x, 0.01f);
  EXPECT_NEAR(at_one, (1.0f + 2.0f * kLn2) * std::exp(-2.0f * kLn2), 1e-4f);  // (1 + y h) e^(-y h)
}

TEST(RotationVector, RoundTrips) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const glm::quat q = glm::normalize(glm::quat(uniform(rng), uniform(rng), uniform(rng), uniform(rng)));
    EXPECT_LT(angle_between(rotation_vector_to_quat(quat_to_rotation_vector(q)), q), 1e-5f);
  }
  EXPECT_LT(glm::length(quat_to_rotation_vector(glm::quat(1.0f, 0.0f, 0.0f, 0.0f))), 1e-7f);
  const glm::vec3 tiny(1e-6f, -2e-6f, 0.0f);
  EXPECT_LT(glm::length(quat_to_rotation_vector(rotation_vector_to_quat(tiny)) - tiny), 1e-9f);
}

TEST(Inertializer, ContinuousAtTheJumpAndDecays) {
  const Database db = make_database(true);
  const AnimationData& a = *db.animation();
  Inertializer inertializer(2, a);
  const std::size_t joints = a.joint_count();
  std::vector<glm::quat> src(joints), dst(joints), out(joints);
  std::vector<glm::vec3> src_t(joints), dst_t(joints), out_t(joints), zero(joints, glm::vec3(0.0f));
  sample_pose(a, 23, src, src_t);
  sample_pose(a, 8, dst, dst_t);
  Inertializer::PoseState source{src, zero, src_t, zero, glm::vec3(1.0f, 0.0f, 0.0f), 0.5f};
  Inertializer::PoseState destination{dst, zero, dst_t, zero, glm::vec3(0.0f), 0.0f};
  inertializer.transition(1, source, destination);
  // t = 0: the offset is the pose difference, so the output is the source.
  out = dst;
  out_t = dst_t;
  Inertializer::RootOffset root = inertializer.update(1, 0.1f, 0.0f, out, out_t);
  for (std::size_t j = 0; j < joints; ++j) {
    EXPECT_LT(angle_between(out[j], src[j]), 1e-5f) << j;
    EXPECT_LT(glm::length(out_t[j] - src_t[j]), 1e-6f) << j;
  }
  EXPECT_NEAR(root.velocity.x, 1.0f, 1e-6f);
  EXPECT_NEAR(root.yaw_rate, 0.5f, 1e-6f);
  // Character 0 is untouched.
  EXPECT_EQ(glm::length(inertializer.rotation_offsets(0)[1]), 0.0f);
  // Five half-lives later, under 1% of the difference is left.
  const float initial = glm::length(inertializer.rotation_offsets(1)[1]);
  ASSERT_GT(initial, 0.1f);
  for (int i = 0; i < 30; ++i) {
    out = dst;
    out_t = dst_t;
    root = inertializer.update(1, 0.1f, 0.5f / 30.0f, out, out_t);
  }
  EXPECT_LT(glm::length(inertializer.rotation_offsets(1)[1]), 0.01f * initial);
  EXPECT_LT(glm::length(inertializer.translation_offsets(1)[0]), 0.01f * glm::length(src_t[0] - dst_t[0]) + 1e-7f);
  EXPECT_LT(std::abs(root.velocity.x), 0.01f);
  EXPECT_LT(angle_between(out[1], dst[1]), 0.01f * angle_between(src[1], dst[1]) + 1e-4f);
}

TEST(Trajectory, ConstantDesiredVelocityConvergesToTheStraightLine) {
  SimulationState state;
  state.velocity = glm::vec3(-1.0f, 0.0f, 0.5f);  // starts off the goal
  state.yaw = 2.0f;
  const glm::vec3 desired(1.5f, 0.0f, 0.0f);
  const float desired_yaw = yaw_of_velocity(desired, 0.0f);
  EXPECT_NEAR(desired_yaw, kPi / 2, 1e-6f);
  const SpringParams params;
  const float offsets[] = {0.5f, 1.0f, 2.0f, 3.0f};
  glm::vec3 positions[4];
  float yaws[4];
  predict_trajectory(state, desired, desired_yaw, params, offsets, positions, yaws);
  // The prediction ends on a line of direction `desired`: later points are
  // spaced exactly by desired * dt, and the facing has turned to it.
  EXPECT_LT(glm::length((positions[3] - positions[2]) - desired * 1.0f), 1e-3f);
  EXPECT_NEAR(yaws[3], desired_yaw, 1e-3f);
  // Simulating step by step reaches the same points (closed forms).
  SimulationState s = state;
  for (int i = 0; i < 90; ++i) simulate_step(s, desired, desired_yaw, params, 1.0f / 30.0f);
  EXPECT_LT(glm::length(s.position - positions[3]), 1e-3f);
  // Once settled, the prediction is the straight line itself.
  predict_trajectory(s, desired, desired_yaw, params, offsets, positions, yaws);
  for (int i = 0; i < 4; ++i) EXPECT_LT(glm::length(positions[i] - (s.position + desired * offsets[i])), 1e-3f) << i;
}

TEST(QueryAssembly, TrajectoryInCharacterSpaceAndPoseFromTheFrame) {
  const Database db = make_database(true);
  Result<QueryAssembler> assembler = QueryAssembler::create(db);
  ASSERT_TRUE(assembler.ok()) << assembler.message();
  ASSERT_EQ(assembler->trajectory_offsets().size(), 3u);
  // Root at (2, 0, 3) facing +X (yaw pi/2); future points 1, 2, 3 m ahead.
  const QueryFrame reference{glm::vec3(2.0f, 0.0f, 3.0f), kPi / 2};
  const glm::vec3 positions[3] = {{3.0f, 0.0f, 3.0f}, {4.0f, 0.0f, 3.0f}, {5.0f, 0.0f, 3.0f}};
  const float yaws[3] = {kPi / 2, kPi / 2, kPi};
  std::vector<float> query(db.dims());
  assembler->assemble(7, reference, positions, yaws, query);
  const FeatureSchema& schema = db.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& ch = schema.channels[c];
    const std::uint32_t o = schema.offset(c);
    for (std::uint32_t d = o; d < o + ch.dims(); ++d) {
      const DimNormalization n = db.normalization()[d];
      const float raw = query[d] * n.scale + n.offset;
      const std::uint32_t k = (d - o) / 2;
      if (ch.kind == ChannelKind::TrajectoryPosition) {
        EXPECT_NEAR(raw, (d - o) % 2 == 0 ? 0.0f : float(k + 1), 1e-5f) << schema.dim_name(d);
      } else if (ch.kind == ChannelKind::TrajectoryDirection) {
        const float expected_x = k == 2 ? 1.0f : 0.0f;  // yaw pi relative pi/2: facing +X in character space
        const float expected_z = k == 2 ? 0.0f : 1.0f;
        EXPECT_NEAR(raw, (d - o) % 2 == 0 ? expected_x : expected_z, 1e-5f) << schema.dim_name(d);
      } else {
        EXPECT_EQ(query[d], db.row(7)[d]) << schema.dim_name(d);
      }
    }
  }
}

TEST(QueryAssembly, ShownPoseWritesEveryDimensionPastOffsetsIncluded) {
  FeatureSchema schema = default_schema();
  for (FeatureChannel& channel : schema.channels) {
    // -0.01 s is sampled a whole frame back at 30 fps, as the build does.
    if (channel.kind == ChannelKind::TrajectoryPosition) channel.offsets_seconds = {-0.5f, -0.01f, 0.5f, 1.0f};
  }
  const Database db = make_database(true, schema);
  Result<QueryAssembler> assembler = QueryAssembler::create(db);
  ASSERT_TRUE(assembler.ok()) << assembler.message();
  ASSERT_EQ(assembler->past_offsets().size(), 2u);
  EXPECT_FLOAT_EQ(assembler->past_offsets()[0], 0.5f);
  EXPECT_FLOAT_EQ(assembler->past_offsets()[1], 1.0f / 30.0f);
  const std::size_t joints = db.animation()->joint_count();
  std::vector<glm::vec3> joint_positions(joints, glm::vec3(0.1f));
  std::vector<glm::vec3> velocities(assembler->velocity_joints().size(), glm::vec3(0.5f));
  const glm::vec3 past[2] = {{2.0f, 0.0f, 2.5f}, {2.0f, 0.0f, 3.0f}};
  const float past_yaws[2] = {0.0f, 0.0f};
  // Straight ahead at the predictor's offsets (both channels' future ones).
  std::vector<glm::vec3> future;
  for (float t : assembler->trajectory_offsets()) future.push_back(glm::vec3(2.0f, 0.0f, 3.0f + t));
  const std::vector<float> future_yaws(future.size(), 0.0f);
  ShownPose shown;
  shown.frame = 7;
  shown.joint_positions = joint_positions;
  shown.joint_velocities = velocities;
  shown.past_positions = past;
  shown.past_yaws = past_yaws;
  std::vector<float> query(db.dims(), std::nanf(""));
  assembler->assemble_shown(shown, QueryFrame{glm::vec3(2.0f, 0.0f, 3.0f), 0.0f}, future, future_yaws, query);
  const FeatureSchema& s = db.schema();
  for (std::uint32_t d = 0; d < db.dims(); ++d) EXPECT_TRUE(std::isfinite(query[d])) << s.dim_name(d);
  // The past 0.5 s point lies 0.5 m behind the root (character space -z).
  for (std::size_t c = 0; c < s.channels.size(); ++c) {
    if (s.channels[c].kind != ChannelKind::TrajectoryPosition) continue;
    const std::uint32_t z = s.offset(c) + 1;
    EXPECT_NEAR(query[z] * db.normalization()[z].scale + db.normalization()[z].offset, -0.5f, 1e-5f);
  }
}

TEST(QueryAssembly, NamesTheMissingTrajectoryChannel) {
  FeatureSchema schema = default_schema();
  std::erase_if(schema.channels, [](const FeatureChannel& c) { return c.kind == ChannelKind::TrajectoryPosition; });
  const Database db = make_database(true, schema);
  Result<QueryAssembler> assembler = QueryAssembler::create(db);
  ASSERT_FALSE(assembler.ok());
  EXPECT_NE(assembler.message().find("trajectory_position"), std::string::npos) << assembler.message();
  Result<CrowdController> controller = CrowdController::create(db, 4);
  ASSERT_FALSE(controller.ok());
  EXPECT_NE(controller.message().find("trajectory_position"), std::string::npos) << controller.message();
}

TEST(CrowdController, DatabaseWithoutAnimationNamesBuild) {
  const Database db = make_database(false);
  Result<CrowdController> controller = CrowdController::create(db, 4);
  ASSERT_FALSE(controller.ok());
  EXPECT_NE(controller.message().find("no animation"), std::string::npos) << controller.message();
  EXPECT_NE(controller.message().find("mmvk build"), std::string::npos) << controller.message();
}

TEST(CrowdController, BadParametersAndInputAreNamed) {
  const Database db = make_database(true);
  ControllerParams params;
  params.search_interval = 0.0f;
  Result<CrowdController> bad = CrowdController::create(db, 4, params);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("search_interval"), std::string::npos) << bad.message();
  EXPECT_FALSE(CrowdController::create(db, 0).ok());

  Result<CrowdController> controller = CrowdController::create(db, 4);
  ASSERT_TRUE(controller.ok()) << controller.message();
  ReferenceSearch reference(db);
  ThreadPool pool(1);
  std::vector<glm::vec3> velocities(3, glm::vec3(0.0f));
  Status wrong_size = controller->tick(1.0f / 30.0f, CrowdInput{velocities, {}}, reference, pool);
  ASSERT_FALSE(wrong_size.ok());
  EXPECT_NE(wrong_size.message().find("desired_velocity"), std::string::npos) << wrong_size.message();
  velocities.assign(4, glm::vec3(0.0f));
  velocities[2].x = std::nanf("");
  Status not_finite = controller->tick(1.0f / 30.0f, CrowdInput{velocities, {}}, reference, pool);
  ASSERT_FALSE(not_finite.ok());
  EXPECT_NE(not_finite.message().find("character 2"), std::string::npos) << not_finite.message();
  velocities[2].x = 0.0f;
  EXPECT_FALSE(controller->tick(0.0f, CrowdInput{velocities, {}}, reference, pool).ok());
  EXPECT_FALSE(controller->place(9, glm::vec3(0.0f), 0.0f).ok());
  EXPECT_FALSE(controller->place(0, glm::vec3(0.0f), 0.0f, 600).ok());
}

// Play-rate and stride bounds: not finite, not positive or not ordered is an
// error that names the field.
TEST(CrowdController, PlayRateAndStrideBoundsAreNamed) {
  const Database db = make_database(true);
  const float nan = std::nanf("");
  const struct {
    float ControllerParams::*field;
    float value;
    const char* named;
  } cases[] = {{&ControllerParams::min_play_rate, nan, "min_play_rate"},
               {&ControllerParams::min_play_rate, 0.0f, "min_play_rate"},
               {&ControllerParams::max_play_rate, INFINITY, "max_play_rate"},
               {&ControllerParams::max_play_rate, 0.5f, "max_play_rate"},  // below min_play_rate
               {&ControllerParams::min_stride_scale, -1.0f, "min_stride_scale"},
               {&ControllerParams::max_stride_scale, nan, "max_stride_scale"},
               {&ControllerParams::min_stride_scale, 2.0f, "max_stride_scale"},  // above max_stride_scale
               {&ControllerParams::stride_window, 0.0f, "stride_window"},
               {&ControllerParams::correction_speed_ratio, nan, "correction_speed_ratio"},
               {&ControllerParams::min_correction_speed, -0.1f, "min_correction_speed"},
               {&ControllerParams::correction_dead_zone, -0.01f, "correction_dead_zone"},
               {&ControllerParams::correction_dead_zone, nan, "correction_dead_zone"},
               {&ControllerParams::correction_dead_zone, 0.5f, "correction_dead_zone"}};  // not below the 0.5 m clamp
  for (const auto& c : cases) {
    ControllerParams params;
    params.*c.field = c.value;
    Result<CrowdController> bad = CrowdController::create(db, 2, params);
    ASSERT_FALSE(bad.ok()) << c.named << " = " << c.value;
    EXPECT_NE(bad.message().find(c.named), std::string::npos) << bad.message();
  }
  ControllerParams fixed;
  fixed.min_play_rate = fixed.max_play_rate = 1.3f;  // equal bounds are ordered
  EXPECT_TRUE(CrowdController::create(db, 2, fixed).ok());
}

// The synthetic clip walks at 1 m/s: asked for 0.8 m/s the clip plays
// slower and the root travels near 0.8 m/s by the animation, the
// correction adding little; with the rate and stride held at 1 it plays the
// clip's 1 m/s and the correction supplies the rest.
TEST(CrowdController, PlayRateBringsThePlayedSpeedToTheCommand) {
  const Database db = make_database(true);
  ReferenceSearch reference(db);
  ThreadPool pool(1);
  const auto played_speed = [&](const ControllerParams& params) {
    Result<CrowdController> controller = CrowdController::create(db, 1, params);
    EXPECT_TRUE(controller.ok()) << controller.message();
    std::vector<glm::vec3> velocity(1, glm::vec3(0.0f, 0.0f, 0.8f));
    double played = 0.0;
    const float dt = 1.0f / 30.0f;
    for (int tick = 0; tick < 90; ++tick) {
      const glm::vec3 before = controller->root_positions()[0];
      EXPECT_TRUE(controller->tick(dt, CrowdInput{velocity, {}}, reference, pool).ok());
      if (tick < 30) continue;  // the spring settles
      played += glm::length(controller->root_positions()[0] - before - controller->root_corrections()[0]);
      EXPECT_GE(controller->play_rates()[0], params.min_play_rate);
      EXPECT_LE(controller->play_rates()[0], params.max_play_rate);
    }
    return played / (60.0 * dt);
  };
  ControllerParams off;
  off.min_play_rate = off.max_play_rate = off.min_stride_scale = off.max_stride_scale = 1.0f;
  EXPECT_NEAR(played_speed(off), 1.0, 0.02);
  EXPECT_NEAR(played_speed(ControllerParams{}), 0.8, 0.04);
}

TEST(CrowdController, DeferredAppliesResultsOneTickLater) {
  const Database db = make_database(true);
  ReferenceSearch reference(db);
  DeferredSearch deferred(reference, 16);
  ThreadPool pool(1);
  Result<CrowdController> controller = CrowdController::create(db, 16);
  ASSERT_TRUE(controller.ok());
  std::vector<glm::vec3> velocities(16, glm::vec3(0.0f, 0.0f, 1.0f));
  ASSERT_TRUE(controller->tick(1.0f / 30.0f, CrowdInput{velocities, {}}, deferred, pool).ok());
  EXPECT_EQ(controller->last_tick().searches, 16u);  // all forced on the first tick
  EXPECT_EQ(controller->last_tick().applied, 0u);
  ASSERT_TRUE(controller->tick(1.0f / 30.0f, CrowdInput{velocities, {}}, deferred, pool).ok());
  EXPECT_EQ(controller->last_tick().applied, 16u);
  EXPECT_EQ(controller->last_tick().no_candidate, 0u);
  // A search still in flight cannot be submitted over.
  EXPECT_FALSE(deferred.submit(QueryBatch{}).ok() && deferred.submit(QueryBatch{}).ok());
}

// Answers every query with its continuing frame (or frame 0 without one),
// recording the continuing frames it was asked with.
class ContinuingSearch final : public SearchBackend {
 public:
  explicit ContinuingSearch(const Database& database) : database_(database) {}
  std::string_view name() const override { return "continuing"; }
  std::string device() const override { return cpu_device_text(1); }
  const Database& database() const override { return database_; }
  Status search(const QueryBatch& batch, std::uint32_t, std::span<Match> out) override {
    for (std::size_t i = 0; i < batch.size; ++i) {
      const std::uint32_t continuing = batch.params[i].continuing_frame;
      asked.push_back(continuing);
      out[i] = Match{continuing == kNoFrame ? 0u : continuing, 0.0f};
    }
    return {};
  }
  SearchStats stats() const override { return {}; }
  void reset_stats() override {}
  std::vector<std::uint32_t> asked;

 private:
  const Database& database_;
};

TEST(CrowdController, HeldOnAClipsLastFrameGetsNoContinuingBonus) {
  DatabaseParts parts = make_parts(true);
  parts.clips[0].loop = false;
  Result<Database> db = Database::create(std::move(parts));
  ASSERT_TRUE(db.ok()) << db.message();
  ContinuingSearch search(*db);
  ThreadPool pool(1);
  Result<CrowdController> controller = CrowdController::create(*db, 1);
  ASSERT_TRUE(controller.ok()) << controller.message();
  ASSERT_TRUE(controller->place(0, glm::vec3(0.0f), 0.0f, 57).ok());
  std::vector<glm::vec3> velocity(1, glm::vec3(0.0f, 0.0f, 1.0f));
  // Frame 57 (held on the first tick, until its first search) plays on to
  // 58, then 59, the last, where it is held: that search has no continuing
  // frame, and its answer (frame 0) is jumped to.
  for (int tick = 0; tick < 4 && controller->frames()[0] != 0; ++tick) {
    ASSERT_TRUE(controller->tick(1.0f / 30.0f, CrowdInput{velocity, {}}, search, pool).ok());
  }
  ASSERT_FALSE(search.asked.empty());
  EXPECT_EQ(search.asked.front(), 57u);  // placed: a forced search before it plays on, continuing
  EXPECT_EQ(search.asked.back(), kNoFrame);
  EXPECT_EQ(controller->frames()[0], 0u);
}

TEST(DatabaseFile, FormatOneStillLoadsWithoutAnimation) {
  const Database db = make_database(true);
  std::string bytes = serialize_database(make_database(false));
  // Format 1 = format 2 without the animation presence byte.
  const std::size_t payload_end = bytes.size() - 8;
  ASSERT_EQ(bytes[payload_end - 1], '\0');
  bytes.erase(payload_end - 1, 1);
  auto put = [&](std::size_t at, std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
  };
  put(8, 1, 4);
  put(16, bytes.size() - 8 - kDatabaseHeaderBytes, 8);
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size() - 8);
  put(bytes.size() - 8, hasher.digest(), 8);
  Result<Database> loaded = deserialize_database(bytes, "v1.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->animation(), nullptr);
  EXPECT_EQ(loaded->content_hash(), db.content_hash());

  // And format 2 keeps the synthetic animation exactly.
  Result<Database> round = deserialize_database(serialize_database(db), "v2.mmdb");
  ASSERT_TRUE(round.ok()) << round.message();
  ASSERT_NE(round->animation(), nullptr);
  EXPECT_EQ(round->animation()->local_rotations, db.animation()->local_rotations);
  EXPECT_EQ(round->animation()->contacts, db.animation()->contacts);
}

TEST(DatabaseFile, CorruptAnimationSectionIsNamed) {
  DatabaseParts parts = make_parts(true);
  parts.animation->contacts[3] = 0x80;
  Result<Database> bad = Database::create(std::move(parts));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("contact"), std::string::npos) << bad.message();
  parts = make_parts(true);
  parts.animation->local_rotations[5] = glm::quat(2.0f, 0.0f, 0.0f, 0.0f);
  bad = Database::create(std::move(parts));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("unit quaternion"), std::string::npos) << bad.message();
}

}  // namespace
}  // namespace mmvk
