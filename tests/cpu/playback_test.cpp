// Sub-frame playback and the recorded root path on synthetic clips: the
// interpolated pose equals the stored frames at integer times and is
// continuous between them; the root travels the same path at any tick rate;
// loops wrap, clips end; a huge step stays bounded; the root history answers
// where the root was, whatever the tick rate.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mmvk/animation/playback.hpp"
#include "mmvk/animation/root_history.hpp"
#include "mmvk/animation/spring.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;
constexpr std::uint32_t kFrames = 40;

// Two clips of kFrames frames, a 2-joint skeleton (hips translated, a
// swinging child): clip 0 loops and turns while walking, clip 1 does not.
Database make_database() {
  DatabaseParts parts;
  FeatureChannel channel;
  channel.name = "trajectory_position";
  channel.kind = ChannelKind::TrajectoryPosition;
  channel.offsets_seconds = {0.5f};
  parts.schema.channels = {channel};
  parts.fps = kFps;
  parts.normalization = {{0.0f, 1.0f}, {0.0f, 1.0f}};
  AnimationData a;
  a.skeleton.names = {"Hips", "Spine"};
  a.skeleton.parents = {-1, 0};
  a.skeleton.rest_offsets = {glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 0.5f, 0.0f)};
  a.mirror_pairs = {0, 1};
  a.translated_joints = {0};
  for (std::uint32_t c = 0; c < 2; ++c) {
    Clip clip;
    clip.name = c == 0 ? "loop" : "once";
    clip.source = clip.name + ".bvh";
    clip.loop = c == 0;
    clip.first_frame = c * kFrames;
    clip.frame_count = kFrames;
    parts.clips.push_back(clip);
    for (std::uint32_t f = 0; f < kFrames; ++f) {
      const float t = float(f) / kFps;
      a.local_rotations.push_back(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
      a.local_rotations.push_back(glm::angleAxis(0.6f * std::sin(5.0f * t), glm::vec3(1.0f, 0.0f, 0.0f)));
      a.local_translations.push_back(glm::vec3(0.0f, 1.0f + 0.05f * std::sin(9.0f * t), 0.1f * t));
      // A curve: 1.2 m/s while turning at 0.5 rad/s.
      const float yaw = 0.5f * t;
      a.root_positions.push_back(glm::vec3(2.4f * std::sin(yaw), 0.0f, 2.4f * (1.0f - std::cos(yaw))) +
                                 glm::vec3(float(c) * 10.0f, 0.0f, 0.0f));
      a.root_yaws.push_back(wrap_angle(yaw + 1.0f));
      a.contacts.push_back(0);
    }
  }
  a.frame_count = 2 * kFrames;
  parts.frame_flags.assign(a.frame_count, 0);
  parts.features.assign(std::size_t{a.frame_count} * 2, 0.0f);
  parts.animation = std::move(a);
  Result<Database> db = Database::create(std::move(parts));
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

float angle_between(const glm::quat& a, const glm::quat& b) {
  const glm::quat d = glm::conjugate(a) * b;
  return 2.0f * std::atan2(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::abs(d.w));
}

TEST(Playback, SampledPoseEqualsStoredFramesAtIntegerTimes) {
  const Database db = make_database();
  const AnimationData& a = *db.animation();
  std::vector<glm::quat> r(2), stored_r(2);
  std::vector<glm::vec3> t(2), stored_t(2);
  for (std::uint32_t f = 0; f < db.frame_count(); ++f) {
    sample_pose_at(a, f, next_frame(db, f), 0.0f, r, t);
    sample_pose(a, f, stored_r, stored_t);
    for (int j = 0; j < 2; ++j) {
      EXPECT_EQ(r[j], stored_r[j]) << "frame " << f;
      EXPECT_EQ(t[j], stored_t[j]) << "frame " << f;
    }
    // Approaching the next frame from below gives the next frame.
    const std::uint32_t next = next_frame(db, f);
    sample_pose_at(a, f, next, 0.99999f, r, t);
    sample_pose(a, next, stored_r, stored_t);
    EXPECT_LT(angle_between(r[1], stored_r[1]), 1e-4f) << "frame " << f;
    EXPECT_LT(glm::length(t[0] - stored_t[0]), 1e-5f) << "frame " << f;
  }
}

TEST(Playback, SampledPoseIsContinuousBetweenFrames) {
  const Database db = make_database();
  const AnimationData& a = *db.animation();
  std::vector<glm::quat> r(2), previous_r(2);
  std::vector<glm::vec3> t(2), previous_t(2);
  const int steps = 100;
  for (std::uint32_t f = 0; f + 1 < kFrames; ++f) {
    std::vector<glm::quat> fr(2), nr(2);
    std::vector<glm::vec3> ft(2), nt(2);
    sample_pose(a, f, fr, ft);
    sample_pose(a, f + 1, nr, nt);
    const float frame_angle = angle_between(fr[1], nr[1]);
    const float frame_step = glm::length(nt[0] - ft[0]);
    for (int i = 0; i <= steps; ++i) {
      sample_pose_at(a, f, f + 1, std::min(float(i) / steps, 0.99999f), r, t);
      if (i > 0) {
        // Each hundredth of a frame moves about a hundredth of the frame's change.
        EXPECT_LE(angle_between(r[1], previous_r[1]), frame_angle / steps * 1.5f + 1e-5f);
        EXPECT_LE(glm::length(t[0] - previous_t[0]), frame_step / steps * 1.5f + 1e-6f);
      }
      previous_r = r;
      previous_t = t;
    }
  }
}

// Plays `seconds` of the looping clip at `rate` Hz from frame 3 and returns
// the root's world displacement (integrating each tick's step from the
// start's facing, as the controller does).
glm::vec3 travel(const Database& db, float rate, float seconds, PlayTime& time, float& yaw) {
  glm::vec3 position(0.0f);
  yaw = db.animation()->root_yaws[time.frame];
  const auto ticks = int(std::lround(seconds * rate));
  for (int i = 0; i < ticks; ++i) {
    const PlaybackStep step = advance_playback(db, time, kFps / rate);
    const float c = std::cos(yaw), s = std::sin(yaw);
    position += glm::vec3(step.root_translation.x * c + step.root_translation.z * s, 0.0f,
                          -step.root_translation.x * s + step.root_translation.z * c);
    yaw = wrap_angle(yaw + step.root_yaw);
    time = step.time;
  }
  return position;
}

TEST(Playback, RootTravelsTheSamePathAtAnyTickRate) {
  const Database db = make_database();
  const AnimationData& a = *db.animation();
  // Frame 3 to frame 33 (1 s): the clip's own root path.
  const glm::vec3 expected = a.root_positions[33] - a.root_positions[3];
  for (float rate : {30.0f, 60.0f, 120.0f, 144.0f, 7.0f}) {
    PlayTime time{3, 0.0f};
    float yaw = 0.0f;
    const glm::vec3 moved = travel(db, rate, 1.0f, time, yaw);
    EXPECT_LT(glm::length(moved - expected), 2e-3f) << rate << " Hz";
    EXPECT_NEAR(wrap_angle(yaw - a.root_yaws[33]), 0.0f, 1e-3f) << rate << " Hz";
    EXPECT_NEAR(float(time.frame) + time.fraction, 33.0f, 1e-3f) << rate << " Hz";
  }
}

TEST(Playback, LoopsWrapAndClipsEndHeld) {
  const Database db = make_database();
  // The loop: 45 frames on from frame 30 of 40 lands on frame 35.
  PlaybackStep step = advance_playback(db, {30, 0.25f}, 45.0f);
  EXPECT_EQ(step.time.frame, 35u);
  EXPECT_NEAR(step.time.fraction, 0.25f, 1e-4f);
  EXPECT_FALSE(step.reached_end);
  // The second clip ends at frame 79 and holds it, without root motion after.
  step = advance_playback(db, {kFrames + 37, 0.5f}, 10.0f);
  EXPECT_EQ(step.time.frame, 2 * kFrames - 1);
  EXPECT_EQ(step.time.fraction, 0.0f);
  EXPECT_TRUE(step.reached_end);
  const PlaybackStep held = advance_playback(db, step.time, 3.0f);
  EXPECT_TRUE(held.reached_end);
  EXPECT_EQ(held.root_translation, glm::vec3(0.0f));
  EXPECT_EQ(held.root_yaw, 0.0f);
  EXPECT_EQ(next_frame(db, 2 * kFrames - 1), 2 * kFrames - 1);
  EXPECT_EQ(next_frame(db, kFrames - 1), 0u);
  EXPECT_EQ(nearest_frame(db, {5, 0.49f}), 5u);
  EXPECT_EQ(nearest_frame(db, {5, 0.5f}), 6u);
}

TEST(Playback, HugeStepsAreBoundedAndStayInRange) {
  const Database db = make_database();
  for (float frames : {1e9f, 3.0e38f, 64.5f}) {
    const PlaybackStep step = advance_playback(db, {2, 0.5f}, frames);
    EXPECT_LT(step.time.frame, kFrames);
    EXPECT_GE(step.time.fraction, 0.0f);
    EXPECT_LT(step.time.fraction, 1.0f);
    EXPECT_TRUE(std::isfinite(step.root_translation.x) && std::isfinite(step.root_yaw));
    // At most kMaxPlaybackSegments frame intervals are played.
    EXPECT_LE(glm::length(step.root_translation), 1.3f * float(kMaxPlaybackSegments) / kFps);
  }
}

TEST(RootHistory, AnswersWhereTheRootWasAtAnyTickRate) {
  // A root moving at 1.5 m/s along x while turning at 0.8 rad/s.
  auto position_at = [](double t) { return glm::vec3(float(1.5 * t), 0.0f, 0.0f); };
  auto yaw_at = [](double t) { return wrap_angle(float(0.8 * t)); };
  for (float rate : {30.0f, 60.0f, 144.0f, 10.0f}) {
    RootHistory history(2, 1.0f);
    history.reset(1, position_at(0.0), yaw_at(0.0));
    const float dt = 1.0f / rate;
    const int ticks = int(std::lround(3.0 * rate));
    for (int i = 1; i <= ticks; ++i) history.record(1, dt, position_at(i * double(dt)), yaw_at(i * double(dt)));
    const double now = ticks * double(dt);
    for (float ago : {0.0f, 0.1f, 1.0f / 3.0f, 0.5f, 0.99f}) {
      glm::vec3 p;
      float yaw = 0.0f;
      history.at(1, ago, p, yaw);
      EXPECT_NEAR(p.x, position_at(now - ago).x, 1e-3f) << rate << " Hz, " << ago << " s ago";
      EXPECT_NEAR(wrap_angle(yaw - yaw_at(now - ago)), 0.0f, 1e-3f) << rate << " Hz, " << ago << " s ago";
    }
  }
}

TEST(RootHistory, ResetForgetsThePathAndLongStepsStayBounded) {
  RootHistory history(1, 0.5f);
  history.reset(0, glm::vec3(1.0f, 0.0f, 2.0f), 0.3f);
  glm::vec3 p;
  float yaw = 0.0f;
  history.at(0, 0.4f, p, yaw);
  EXPECT_EQ(p, glm::vec3(1.0f, 0.0f, 2.0f));
  EXPECT_FLOAT_EQ(yaw, 0.3f);
  // A step of a million seconds fills the ring once (bounded work) and
  // still interpolates along it.
  history.record(0, 1.0e6f, glm::vec3(3.0f, 0.0f, 2.0f), 0.3f);
  history.at(0, 0.0f, p, yaw);
  EXPECT_NEAR(p.x, 3.0f, 1e-4f);
  history.at(0, 10.0f, p, yaw);
  EXPECT_TRUE(std::isfinite(p.x) && p.x >= 1.0f && p.x <= 3.0f);
}

}  // namespace
}  // namespace mmvk
