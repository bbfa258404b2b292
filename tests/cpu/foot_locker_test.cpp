// Foot locking (foot_locker.hpp) on a synthetic walk: a small skeleton whose
// stance feet slide (the animation's feet move back slower than the root
// moves forward), heel strike, flat foot and heel rise flagged by the contact
// bits, the root advancing (and turning). Locked contact points hold within
// 1 mm, release is continuous, reset and the off switch leave the animation,
// and the hips drop for a foot held out of reach.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "mmvk/animation/foot_locker.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {
namespace {

constexpr float kBone = 0.42f;  // thigh and shin
const glm::vec3 kToeOffset(0.0f, -0.06f, 0.13f);
const glm::vec3 kX(1.0f, 0.0f, 0.0f);
constexpr float kToeHeight = 0.02f;  // the toe joint's height on the ground

// Hips, per side UpLeg > Leg > Foot (> ToeBase), Spine.
AnimationData make_skeleton(bool toes = true) {
  AnimationData a;
  Skeleton& s = a.skeleton;
  auto add = [&](const std::string& name, int parent, const glm::vec3& offset) {
    s.names.push_back(name);
    s.parents.push_back(parent);
    s.rest_offsets.push_back(offset);
    return static_cast<int>(s.names.size()) - 1;
  };
  add("Hips", -1, glm::vec3(0.0f, 0.9f, 0.0f));
  for (int side = 0; side < 2; ++side) {
    const std::string prefix = side == 0 ? "Left" : "Right";
    const int upper = add(prefix + "UpLeg", 0, glm::vec3(side == 0 ? 0.1f : -0.1f, -0.05f, 0.0f));
    const int lower = add(prefix + "Leg", upper, glm::vec3(0.0f, -kBone, 0.0f));
    const int foot = add(prefix + "Foot", lower, glm::vec3(0.0f, -kBone, 0.0f));
    if (toes) add(prefix + "ToeBase", foot, kToeOffset);
  }
  add("Spine", 0, glm::vec3(0.0f, 0.1f, 0.0f));
  const std::size_t joints = s.size();
  for (std::size_t j = 0; j < joints; ++j) a.mirror_pairs.push_back(static_cast<int>(j));
  a.translated_joints = {0};
  a.frame_count = 1;
  a.local_rotations.assign(joints, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  a.local_translations = {s.rest_offsets[0]};
  a.root_positions = {glm::vec3(0.0f)};
  a.root_yaws = {0.0f};
  a.contacts = {0};
  return a;
}

struct Pose {
  std::vector<glm::quat> rotations;
  std::vector<glm::vec3> translations;
  std::uint8_t contacts = 0;
};

Pose rest_pose(const AnimationData& a, float hips_height) {
  Pose pose;
  pose.rotations.assign(a.joint_count(), glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  pose.translations = a.skeleton.rest_offsets;
  pose.translations[0] = glm::vec3(0.0f, hips_height, 0.0f);
  return pose;
}

// Sets a leg's rotations (planar IK in its sagittal plane, written
// independently of the solver under test) so its ankle is at `ankle`
// (character space; x is the hip's) with the foot pitched by `pitch` radians
// (positive lifts the heel) and the knee bent forward.
void pose_leg(const AnimationData& a, int side, const glm::vec3& ankle, float pitch, Pose& pose) {
  const std::string prefix = side == 0 ? "Left" : "Right";
  const int upper = a.skeleton.find(prefix + "UpLeg");
  const glm::vec3 hip = pose.translations[0] + a.skeleton.rest_offsets[static_cast<std::size_t>(upper)];
  const glm::vec3 v = ankle - hip;
  const float distance = std::min(std::sqrt(v.y * v.y + v.z * v.z), 0.999f * 2.0f * kBone);
  const float toward = std::atan2(v.z, -v.y);  // from straight down toward +Z
  const float bend = std::acos(distance / (2.0f * kBone));
  const float thigh = toward + bend;
  const float shin = toward - bend;
  pose.rotations[static_cast<std::size_t>(upper)] = glm::angleAxis(-thigh, kX);
  pose.rotations[static_cast<std::size_t>(upper) + 1] = glm::angleAxis(thigh - shin, kX);
  pose.rotations[static_cast<std::size_t>(upper) + 2] = glm::angleAxis(shin + pitch, kX);
}

// The walk: period 1 s, stance 60% (heel only for its first 10%, heel and
// toe until 40%, toe only with the heel rising after), the stance toe moving
// back at kAnimSpeed while the root walks at 1 m/s: planted feet slide
// forward at 0.15 m/s in the world unless held.
constexpr float kPeriod = 1.0f;
constexpr float kStance = 0.6f;
constexpr float kAnimSpeed = 0.85f;
constexpr float kHipsHeight = 0.82f;
constexpr float kMaxPitch = 0.6f;

struct FootState {
  glm::vec3 ankle;
  float pitch;
  std::uint8_t bits;
};

FootState stance_foot(float x, float phase) {
  const float half = kAnimSpeed * kStance * kPeriod / 2.0f;
  const glm::vec3 toe(x, kToeHeight, half - kAnimSpeed * phase * kPeriod);
  const float rise = std::clamp((phase - 0.4f) / 0.2f, 0.0f, 1.0f);
  const float pitch = kMaxPitch * rise * rise * (3.0f - 2.0f * rise);
  return {toe - glm::angleAxis(pitch, kX) * kToeOffset, pitch, 0};
}

FootState walk_foot(int side, float t) {
  const float x = side == 0 ? 0.1f : -0.1f;
  float phase = t / kPeriod + (side == 0 ? 0.0f : 0.5f);
  phase -= std::floor(phase);
  const std::uint8_t planted = side == 0 ? kContactLeft : kContactRight;
  const std::uint8_t heel = side == 0 ? kContactLeftHeel : kContactRightHeel;
  const std::uint8_t toe = side == 0 ? kContactLeftToe : kContactRightToe;
  if (phase < kStance) {
    FootState foot = stance_foot(x, phase);
    foot.bits = static_cast<std::uint8_t>(planted | (phase < 0.4f ? heel : 0) | (phase >= 0.1f ? toe : 0));
    return foot;
  }
  const float u = (phase - kStance) / (1.0f - kStance);
  const float s = 0.5f - 0.5f * std::cos(3.14159265f * u);
  const FootState from = stance_foot(x, kStance);
  const FootState to = stance_foot(x, 0.0f);
  const glm::vec3 ankle = glm::mix(from.ankle, to.ankle, s) + glm::vec3(0.0f, 0.12f * std::sin(3.14159265f * u), 0.0f);
  return {ankle, kMaxPitch * (1.0f - s), 0};
}

Pose walk_pose(const AnimationData& a, float t) {
  Pose pose = rest_pose(a, kHipsHeight);
  for (int side = 0; side < 2; ++side) {
    const FootState foot = walk_foot(side, t);
    pose_leg(a, side, foot.ankle, foot.pitch, pose);
    pose.contacts |= foot.bits;
  }
  return pose;
}

// Both feet flat on the ground, as a fifth into the walk's stance.
Pose standing_pose(const AnimationData& a) {
  Pose pose = rest_pose(a, kHipsHeight);
  for (int side = 0; side < 2; ++side) {
    pose_leg(a, side, stance_foot(side == 0 ? 0.1f : -0.1f, 0.2f).ankle, 0.0f, pose);
  }
  return pose;
}

// The root at time t: 1 m/s along its facing, turning at `turn` rad/s.
void walk_root(float t, float turn, glm::vec3& position, float& yaw) {
  yaw = turn * t;
  position = turn == 0.0f ? glm::vec3(0.0f, 0.0f, t)
                          : glm::vec3((1.0f - std::cos(turn * t)) / turn, 0.0f, std::sin(turn * t) / turn);
}

std::vector<glm::vec3> world_of(const AnimationData& a, const Pose& pose, const glm::vec3& root, float yaw) {
  std::vector<glm::vec3> world(a.joint_count());
  const glm::vec3 roots[] = {root};
  const float yaws[] = {yaw};
  forward_kinematics_batch(a.skeleton, pose.rotations, pose.translations, roots, yaws, world);
  return world;
}

// The joint a foot's lock holds for these contact bits.
int contact_joint(const FootLocker& locker, int side, std::uint8_t contacts) {
  const FootLocker::Leg& leg = locker.legs()[static_cast<std::size_t>(side)];
  const std::uint8_t heel = side == 0 ? kContactLeftHeel : kContactRightHeel;
  const std::uint8_t toe = side == 0 ? kContactLeftToe : kContactRightToe;
  return leg.toe >= 0 && ((contacts & toe) != 0 || (contacts & heel) == 0) ? leg.toe : leg.foot;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Rotation angle between two unit quaternions (radians).
float angle_between(const glm::quat& a, const glm::quat& b) {
  const glm::quat d = glm::conjugate(a) * b;
  return 2.0f * std::atan2(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::abs(d.w));
}

// FootLocker::update on a pose, with the forward kinematics of the pose as it
// comes in, which the locker reads (the controller's one FK per tick).
void update_locker(FootLocker& locker, const AnimationData& a, std::uint32_t b, float dt, std::uint8_t contacts,
                   const glm::vec3& root, float yaw, std::span<glm::quat> rotations,
                   std::span<glm::vec3> translations, std::span<glm::vec3> world) {
  std::vector<glm::vec3> animated(a.joint_count());
  forward_kinematics_batch(a.skeleton, rotations, translations, {&root, 1}, {&yaw, 1}, animated);
  locker.update(b, dt, contacts, root, yaw, animated, rotations, translations, world);
}

glm::quat global_rotation(const AnimationData& a, const Pose& pose, int joint, float yaw) {
  glm::quat g(1.0f, 0.0f, 0.0f, 0.0f);
  for (int j = joint; j >= 0; j = a.skeleton.parents[static_cast<std::size_t>(j)]) {
    g = pose.rotations[static_cast<std::size_t>(j)] * g;
  }
  return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)) * g;
}

struct WalkResult {
  int locked_ticks = 0;
  int planted_ticks = 0;
  float worst_lock_error = 0.0f;        // contact point to anchor while locked (m)
  float worst_lock_error_across = 0.0f;  // the same, horizontally
  float largest_animated_slide = 0.0f;  // the animated contact point's travel over one contact (m)
  float worst_release_step = 0.0f;      // displayed step - animated step on release ticks (m)
  float largest_release_offset = 0.0f;  // the correction being released (m)
  int releases = 0;
  int clamped_ticks = 0;
  float largest_knee_step = 0.0f;           // displayed, per tick (m)
  float largest_animated_knee_step = 0.0f;  // the animation's
};

WalkResult run_walk(float rate, float turn, bool toes = true, const FootIkParams& params = {}) {
  const AnimationData a = make_skeleton(toes);
  Result<FootLocker> created = FootLocker::create(a, 1, params);
  EXPECT_TRUE(created.ok()) << created.message();
  FootLocker& locker = *created;
  const float dt = 1.0f / rate;
  WalkResult result;
  std::vector<glm::vec3> world(a.joint_count());
  std::vector<glm::vec3> previous_world, previous_animated;
  std::uint8_t previous_locked[2] = {0, 0};
  glm::vec3 contact_start[2];
  int start_joint[2] = {-1, -1};
  const int ticks = static_cast<int>(4.0f * rate);
  for (int i = 0; i < ticks; ++i) {
    const float t = float(i) * dt;
    Pose pose = walk_pose(a, t);
    glm::vec3 root;
    float yaw;
    walk_root(t, turn, root, yaw);
    const std::vector<glm::vec3> animated = world_of(a, pose, root, yaw);
    update_locker(locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, yaw, pose.rotations, pose.translations, world);
    for (const glm::vec3& p : world) EXPECT_TRUE(finite(p)) << "tick " << i;
    // The output pose and the world positions agree.
    const std::vector<glm::vec3> refk = world_of(a, pose, root, yaw);
    for (std::size_t j = 0; j < world.size(); ++j) EXPECT_LT(glm::length(refk[j] - world[j]), 1e-5f) << i << " " << j;
    for (int side = 0; side < 2; ++side) {
      const std::size_t f = static_cast<std::size_t>(side);
      const std::uint8_t planted = side == 0 ? kContactLeft : kContactRight;
      const int joint = contact_joint(locker, side, pose.contacts);
      const std::size_t c = static_cast<std::size_t>(joint);
      if ((pose.contacts & planted) != 0) {
        // How far the animation alone moves the contact point in the world
        // while that point is in contact.
        ++result.planted_ticks;
        if (joint != start_joint[f]) contact_start[f] = animated[c];
        start_joint[f] = joint;
        result.largest_animated_slide = std::max(result.largest_animated_slide,
                                                 glm::length(animated[c] - contact_start[f]));
      } else {
        start_joint[f] = -1;
      }
      result.clamped_ticks += locker.reach_clamped()[f];
      if (locker.locked()[f] != 0) {
        ++result.locked_ticks;
        const glm::vec3 error = world[c] - locker.anchors()[f];
        result.worst_lock_error = std::max(result.worst_lock_error, glm::length(error));
        result.worst_lock_error_across = std::max(result.worst_lock_error_across, std::hypot(error.x, error.z));
      }
      if (previous_locked[f] != 0 && locker.locked()[f] == 0 && !previous_world.empty()) {
        // Released this tick: the displayed ankle and toe step no further
        // than the animation's own step, up to 1 mm.
        ++result.releases;
        result.largest_release_offset = std::max(result.largest_release_offset, glm::length(locker.corrections()[f]));
        const FootLocker::Leg& leg = locker.legs()[f];
        for (const int j : {leg.foot, leg.toe}) {
          if (j < 0) continue;
          const std::size_t k = static_cast<std::size_t>(j);
          const float shown = glm::length(world[k] - previous_world[k]);
          const float played = glm::length(animated[k] - previous_animated[k]);
          result.worst_release_step = std::max(result.worst_release_step, shown - played);
        }
      }
      if (!previous_world.empty()) {
        const std::size_t knee = static_cast<std::size_t>(locker.legs()[f].lower);
        result.largest_knee_step = std::max(result.largest_knee_step, glm::length(world[knee] - previous_world[knee]));
        result.largest_animated_knee_step =
            std::max(result.largest_animated_knee_step, glm::length(animated[knee] - previous_animated[knee]));
      }
      previous_locked[f] = locker.locked()[f];
    }
    previous_world = world;
    previous_animated = animated;
  }
  return result;
}

TEST(FootLocker, LockedFootStaysOnItsAnchorOnASlidingWalk) {
  for (const float rate : {30.0f, 60.0f, 144.0f}) {
    for (const float turn : {0.0f, 0.4f}) {
      const WalkResult r = run_walk(rate, turn);
      SCOPED_TRACE("rate " + std::to_string(rate) + " Hz, turn " + std::to_string(turn) + " rad/s");
      // The animation alone slides (the test is not vacuous) ...
      EXPECT_GT(r.largest_animated_slide, 0.05f);
      // ... and the foot is locked through its contacts, on its anchor.
      EXPECT_GT(r.locked_ticks, r.planted_ticks * 9 / 10);
      EXPECT_LT(r.worst_lock_error, 1e-3f);
      EXPECT_EQ(r.clamped_ticks, 0);
      EXPECT_GE(r.releases, 6);
      // Release: the correction (several cm) is not dropped at once; the
      // displayed step exceeds the animation's by no more than the
      // correction's rate (about the 0.15 m/s slide) over one tick.
      EXPECT_GT(r.largest_release_offset, 0.05f);
      EXPECT_LT(r.worst_release_step, 0.15f / rate + 1e-3f);
      // No knee pop: the knee's fastest step stays near the animation's (the
      // decaying correction adds up to about 0.4 m/s to a swinging leg
      // moving 2.5 m/s); a pop would be a step of centimetres at any rate.
      EXPECT_LT(r.largest_knee_step, 1.25f * r.largest_animated_knee_step);
      std::printf("rate %5.1f turn %.1f: locked %d of %d planted ticks, worst lock error %.2g m, animated slide %.3f m, "
                  "worst release step beyond the animation's %.2g m, knee step %.4f m (animated %.4f m)\n",
                  double(rate), double(turn), r.locked_ticks, r.planted_ticks, double(r.worst_lock_error),
                  double(r.largest_animated_slide), double(r.worst_release_step), double(r.largest_knee_step),
                  double(r.largest_animated_knee_step));
    }
  }
}

TEST(FootLocker, AnInstantReleaseWouldJump) {
  // The release check above can fail: with a release half-life of 1 ms the
  // correction vanishes in one tick and the foot jumps by it.
  FootIkParams params;
  params.release_half_life = 1e-3f;
  const WalkResult r = run_walk(60.0f, 0.0f, true, params);
  EXPECT_GT(r.worst_release_step, 0.05f);
}

TEST(FootLocker, SkeletonWithoutToesLocksTheAnkle) {
  // The ankle is held horizontally; its height stays animated (the heel
  // rises before the foot leaves the ground).
  const WalkResult r = run_walk(60.0f, 0.0f, false);
  EXPECT_GT(r.locked_ticks, r.planted_ticks * 9 / 10);
  EXPECT_LT(r.worst_lock_error_across, 1e-3f);
  EXPECT_GT(r.worst_lock_error, 0.02f);
  EXPECT_LT(r.worst_release_step, 0.15f / 60.0f + 1e-3f);
}

TEST(FootLocker, FootKeepsItsAnimatedOrientationTurnedByTheYawCorrection) {
  const AnimationData a = make_skeleton();
  Result<FootLocker> locker = FootLocker::create(a, 1);
  ASSERT_TRUE(locker.ok()) << locker.message();
  const float dt = 1.0f / 60.0f;
  std::vector<glm::vec3> world(a.joint_count());
  float largest_yaw = 0.0f;
  for (int i = 0; i < 240; ++i) {
    const float t = float(i) * dt;
    Pose pose = walk_pose(a, t);
    const Pose animated = pose;
    glm::vec3 root;
    float yaw;
    walk_root(t, 0.4f, root, yaw);
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, yaw, pose.rotations, pose.translations, world);
    for (std::size_t side = 0; side < 2; ++side) {
      const int foot = locker->legs()[side].foot;
      const float psi = locker->yaw_corrections()[side];
      largest_yaw = std::max(largest_yaw, std::abs(psi));
      const glm::quat expected = glm::angleAxis(psi, glm::vec3(0.0f, 1.0f, 0.0f)) * global_rotation(a, animated, foot, yaw);
      EXPECT_LT(angle_between(global_rotation(a, pose, foot, yaw), expected), 1e-4f) << i << " " << side;
      // The toe hangs off the foot unchanged.
      const int toe = locker->legs()[side].toe;
      EXPECT_EQ(pose.rotations[static_cast<std::size_t>(toe)], animated.rotations[static_cast<std::size_t>(toe)]);
    }
  }
  EXPECT_GT(largest_yaw, 0.1f);  // the turning root made the lock turn the feet
}

TEST(FootLocker, YawCorrectionStopsAtItsLimitAndTheFootPivotsInPlace) {
  // The root turns 1.2 rad in place over a still pose with the left toe
  // planted: the foot's heading is held for max_yaw_correction, then the foot
  // turns with the body about its toe, which never leaves its anchor.
  const AnimationData a = make_skeleton();
  FootIkParams params;
  params.max_yaw_correction = 0.4f;
  Result<FootLocker> locker = FootLocker::create(a, 1, params);
  ASSERT_TRUE(locker.ok()) << locker.message();
  const Pose still = standing_pose(a);
  const float dt = 1.0f / 60.0f;
  std::vector<glm::vec3> world(a.joint_count());
  glm::vec3 anchor(0.0f);
  float previous_psi = 0.0f;
  for (int i = 0; i <= 60; ++i) {
    Pose pose = still;
    const float yaw = 1.2f * float(i) / 60.0f;
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, kContactLeft | kContactLeftToe, glm::vec3(0.0f), yaw, pose.rotations,
                   pose.translations, world);
    const glm::vec3 toe = world[static_cast<std::size_t>(locker->legs()[0].toe)];
    if (i == 0) anchor = toe;
    EXPECT_EQ(locker->locked()[0], 1) << i;
    EXPECT_LT(glm::length(toe - anchor), 1e-3f) << i;
    const float psi = locker->yaw_corrections()[0];
    EXPECT_LE(std::abs(psi), 0.4f + 1e-6f) << i;
    EXPECT_LE(std::abs(psi - previous_psi), 1.2f / 60.0f + 1e-5f) << i;  // no faster than the body turns
    previous_psi = psi;
  }
  EXPECT_NEAR(previous_psi, -0.4f, 1e-5f);  // held against the turn, at its limit
}

TEST(FootLocker, AFootPitchedThroughVerticalKeepsItsYawCorrection) {
  // The planted left foot pitches about its toe until it points past
  // straight down and back, while the root turns: the heading's yaw is
  // undefined near vertical (and flips by half a turn past it), but the yaw
  // correction is held meanwhile and carries on, and the toe stays put.
  const AnimationData a = make_skeleton();
  Result<FootLocker> locker = FootLocker::create(a, 1);
  ASSERT_TRUE(locker.ok()) << locker.message();
  const FootState flat = stance_foot(0.1f, 0.2f);
  const glm::vec3 toe_at = flat.ankle + kToeOffset;
  const float dt = 1.0f / 60.0f;
  std::vector<glm::vec3> world(a.joint_count());
  glm::vec3 anchor(0.0f);
  float previous_psi = 0.0f;
  for (int i = 0; i <= 120; ++i) {
    Pose pose = standing_pose(a);
    const float pitch = 1.45f * std::sin(3.14159265f * float(i) / 120.0f);
    pose_leg(a, 0, toe_at - glm::angleAxis(pitch, kX) * kToeOffset, pitch, pose);
    const float yaw = 0.2f * float(i) / 60.0f;
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, kContactLeft | kContactLeftToe, glm::vec3(0.0f), yaw, pose.rotations,
                   pose.translations, world);
    const glm::vec3 toe = world[static_cast<std::size_t>(locker->legs()[0].toe)];
    if (i == 0) anchor = toe;
    ASSERT_TRUE(finite(toe)) << i;
    EXPECT_LT(glm::length(toe - anchor), 1e-3f) << i;
    const float psi = locker->yaw_corrections()[0];
    EXPECT_LE(std::abs(psi - previous_psi), 0.2f / 60.0f + 1e-5f) << i;
    previous_psi = psi;
  }
}

TEST(FootLocker, ReleaseDecaysTheCorrectionWithoutAJump) {
  // Planted (toe) for 0.5 s while the root slides 0.15 m under a still pose,
  // then lifted: the correction decays to nothing, in small steps.
  const AnimationData a = make_skeleton();
  FootIkParams params;
  params.release_half_life = 0.1f;
  Result<FootLocker> locker = FootLocker::create(a, 1, params);
  ASSERT_TRUE(locker.ok()) << locker.message();
  const Pose still = standing_pose(a);
  const float dt = 1.0f / 60.0f;
  std::vector<glm::vec3> world(a.joint_count()), previous;
  float largest_step = 0.0f;
  glm::vec3 anchor(0.0f);
  for (int i = 0; i < 90; ++i) {
    Pose pose = still;
    pose.contacts = i < 30 ? kContactLeft | kContactLeftToe : 0;
    const glm::vec3 root(0.0f, 0.0f, 0.15f * std::min(float(i), 30.0f) / 30.0f);
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, 0.0f, pose.rotations, pose.translations, world);
    const glm::vec3 toe = world[static_cast<std::size_t>(locker->legs()[0].toe)];
    if (i == 0) anchor = toe;
    if (i < 30) {
      EXPECT_EQ(locker->locked()[0], 1);
      EXPECT_LT(glm::length(toe - anchor), 1e-3f) << i;
    } else {
      EXPECT_EQ(locker->locked()[0], 0);
    }
    if (!previous.empty()) largest_step = std::max(largest_step, glm::length(toe - previous[static_cast<std::size_t>(locker->legs()[0].toe)]));
    previous = world;
  }
  // At release the toe is 0.15 m behind its animated place; a pop would
  // cover that in one tick. Critically damped from rest over 0.1 s
  // half-lives the largest step is about 0.15 * 13.9 / e / 60 = 1.3 cm.
  EXPECT_LT(largest_step, 0.016f);
  EXPECT_LT(glm::length(locker->corrections()[0]), 1e-3f);
  EXPECT_EQ(locker->corrections()[1], glm::vec3(0.0f));
}

TEST(FootLocker, AStepCarriesALockedFootOntoItsPoseOffTheGround) {
  // Planted (toe) while the root slides 0.2 m under a still pose, so the
  // lock holds the toe 0.2 m from its pose; then, still planted, the foot
  // steps: within 0.25 s it lands on its pose, lifted on the way (a quarter
  // of the distance, 5 cm), moving in small steps, and locks again there.
  const AnimationData a = make_skeleton();
  Result<FootLocker> locker = FootLocker::create(a, 1);
  ASSERT_TRUE(locker.ok()) << locker.message();
  Pose still = standing_pose(a);
  still.contacts = kContactLeft | kContactLeftToe;
  const float dt = 1.0f / 60.0f;
  const glm::vec3 slid(0.0f, 0.0f, 0.2f);
  const std::size_t toe = static_cast<std::size_t>(locker->legs()[0].toe);
  std::vector<glm::vec3> world(a.joint_count());
  for (int i = 0; i <= 30; ++i) {
    Pose pose = still;
    const glm::vec3 root = slid * (float(i) / 30.0f);
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, 0.0f, pose.rotations, pose.translations, world);
  }
  ASSERT_EQ(locker->locked()[0], 1);
  ASSERT_NEAR(glm::length(locker->corrections()[0]), 0.2f, 1e-3f);
  const glm::vec3 animated_toe = world_of(a, still, slid, 0.0f)[toe];
  locker->step(0, 0);
  EXPECT_TRUE(locker->stepping(0, 0));
  EXPECT_FALSE(locker->stepping(0, 1));
  EXPECT_EQ(locker->locked()[0], 0);
  float highest = 0.0f, largest_step = 0.0f;
  glm::vec3 previous = world[toe];
  int ticks = 0;
  for (; locker->stepping(0, 0) && ticks < 60; ++ticks) {
    Pose pose = still;
    update_locker(*locker, a, 0, dt, pose.contacts, slid, 0.0f, pose.rotations, pose.translations, world);
    highest = std::max(highest, world[toe].y - animated_toe.y);
    largest_step = std::max(largest_step, glm::length(world[toe] - previous));
    previous = world[toe];
  }
  EXPECT_NEAR(ticks, 15, 1) << "0.25 s at 60 Hz";
  EXPECT_NEAR(highest, 0.05f, 0.005f);
  // Smoothstep over 0.25 s: the fastest is 1.5 * 0.2 m / 0.25 s = 1.2 m/s, 2 cm a tick.
  EXPECT_LT(largest_step, 0.025f);
  EXPECT_LT(glm::length(world[toe] - animated_toe), 1e-3f);
  Pose pose = still;
  update_locker(*locker, a, 0, dt, pose.contacts, slid, 0.0f, pose.rotations, pose.translations, world);
  EXPECT_EQ(locker->locked()[0], 1) << "planted, it locks where it landed";
  EXPECT_LT(glm::length(locker->corrections()[0]), 1e-3f);
}

TEST(FootLocker, ResetForgetsTheLocksAndOffLeavesThePose) {
  const AnimationData a = make_skeleton();
  FootIkParams off;
  off.enabled = false;
  Result<FootLocker> locker = FootLocker::create(a, 2);
  Result<FootLocker> disabled = FootLocker::create(a, 2, off);
  ASSERT_TRUE(locker.ok() && disabled.ok());
  const float dt = 1.0f / 30.0f;
  std::vector<glm::vec3> world(a.joint_count());
  for (int i = 0; i < 40; ++i) {
    const float t = float(i) * dt;
    glm::vec3 root;
    float yaw;
    walk_root(t, 0.0f, root, yaw);
    Pose pose = walk_pose(a, t);
    update_locker(*locker, a, 1, dt, pose.contacts, root, yaw, pose.rotations, pose.translations, world);
    // Off: the pose is untouched, the world positions are its FK.
    Pose untouched = walk_pose(a, t);
    update_locker(*disabled, a, 1, dt, untouched.contacts, root, yaw, untouched.rotations, untouched.translations, world);
    const Pose animated = walk_pose(a, t);
    EXPECT_EQ(untouched.rotations, animated.rotations);
    EXPECT_EQ(untouched.translations, animated.translations);
    const std::vector<glm::vec3> fk = world_of(a, animated, root, yaw);
    for (std::size_t j = 0; j < fk.size(); ++j) EXPECT_LT(glm::length(fk[j] - world[j]), 1e-5f);
    EXPECT_EQ(disabled->locked()[2] + disabled->locked()[3], 0);
  }
  // Character 1 walked with locks and corrections; character 0 never moved.
  EXPECT_NE(locker->corrections()[2] + locker->corrections()[3], glm::vec3(0.0f));
  EXPECT_EQ(locker->locked()[0] + locker->locked()[1], 0);
  locker->reset(1);
  EXPECT_EQ(locker->locked()[2] + locker->locked()[3], 0);
  EXPECT_EQ(locker->corrections()[2], glm::vec3(0.0f));
  EXPECT_EQ(locker->hip_drops()[1], 0.0f);
  // After the reset a pose without contacts comes out exactly as animated.
  Pose pose = walk_pose(a, 0.3f);
  pose.contacts = 0;
  const Pose animated = pose;
  update_locker(*locker, a, 1, dt, 0, glm::vec3(5.0f, 0.0f, 5.0f), 1.0f, pose.rotations, pose.translations, world);
  EXPECT_EQ(pose.rotations, animated.rotations);
  EXPECT_EQ(pose.translations, animated.translations);
  // A teleport after the reset: planted feet lock afresh where they are.
  Pose planted = walk_pose(a, 0.3f);
  update_locker(*locker, a, 1, dt, planted.contacts, glm::vec3(50.0f, 0.0f, 0.0f), 0.0f, planted.rotations,
                 planted.translations, world);
  EXPECT_EQ(locker->corrections()[2], glm::vec3(0.0f));
  EXPECT_EQ(locker->locked()[2], 1);
}

// Nearly straight legs (96% extension), both feet planted, and the root
// moving 0.15 m forward under a still pose: the held feet end up behind the
// hips, further than the legs reach.
struct DropResult {
  float drop = 0.0f;
  float largest_drop_step = 0.0f;
  float foot_error = 0.0f;          // the left toe to its anchor, at the end (m)
  float largest_foot_error = 0.0f;  // the same, the largest over the run (m)
  bool clamped = false;
};
DropResult run_hip_drop(float max_hip_drop, float max_hip_goal_rate = FootIkParams{}.max_hip_goal_rate) {
  const AnimationData a = make_skeleton();
  FootIkParams params;
  params.max_hip_drop = max_hip_drop;
  params.max_hip_goal_rate = max_hip_goal_rate;
  Result<FootLocker> locker = FootLocker::create(a, 1, params);
  EXPECT_TRUE(locker.ok()) << locker.message();
  const float extension = 0.96f * 2.0f * kBone;
  const float hips = 0.05f + kToeHeight + 0.06f + extension;  // hip joint to flat-foot ankle, straight down
  Pose still = rest_pose(a, hips);
  for (int side = 0; side < 2; ++side) {
    pose_leg(a, side, glm::vec3(side == 0 ? 0.1f : -0.1f, kToeHeight + 0.06f, 0.0f), 0.0f, still);
  }
  still.contacts = kContactLeft | kContactRight;  // no point bits: the toes
  const float dt = 1.0f / 60.0f;
  std::vector<glm::vec3> world(a.joint_count());
  DropResult result;
  float previous_drop = 0.0f;
  for (int i = 0; i < 120; ++i) {
    Pose pose = still;
    const glm::vec3 root(0.0f, 0.0f, 0.15f * std::min(float(i), 30.0f) / 30.0f);
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, 0.0f, pose.rotations, pose.translations, world);
    const float drop = locker->hip_drops()[0];
    EXPECT_LE(drop, max_hip_drop);
    EXPECT_NEAR(world[0].y, hips - drop, 1e-5f);  // the hips joint moved down by the drop
    result.largest_drop_step = std::max(result.largest_drop_step, std::abs(drop - previous_drop));
    previous_drop = drop;
    const glm::vec3 toe = world[static_cast<std::size_t>(locker->legs()[0].toe)];
    result.largest_foot_error = std::max(result.largest_foot_error, glm::length(toe - locker->anchors()[0]));
  }
  result.drop = previous_drop;
  result.foot_error = glm::length(world[static_cast<std::size_t>(locker->legs()[0].toe)] - locker->anchors()[0]);
  result.clamped = locker->reach_clamped()[0] != 0;
  EXPECT_EQ(locker->locked()[0], 1);
  return result;
}

TEST(FootLocker, HipsLowerForAnOutOfReachTarget) {
  const DropResult lowered = run_hip_drop(0.1f);
  // The least drop that brings a point 0.15 m behind within the animated
  // extension e: e - sqrt(e^2 - 0.15^2) = 0.0141 m for e = 0.806 m.
  EXPECT_NEAR(lowered.drop, 0.0141f, 1e-3f);
  EXPECT_LT(lowered.foot_error, 1e-3f);
  EXPECT_FALSE(lowered.clamped);
  EXPECT_LT(lowered.largest_drop_step, 0.002f);  // springed, no jump
  const DropResult held = run_hip_drop(0.0f);
  EXPECT_EQ(held.drop, 0.0f);
  EXPECT_TRUE(held.clamped);
  EXPECT_GT(held.foot_error, 1e-3f);  // without the drop the soft clamp leaves it short
  std::printf("hip drop %.4f m, foot error %.2g m (without lowering: %.2g m, clamped)\n", double(lowered.drop),
              double(lowered.foot_error), double(held.foot_error));
}

// While the root moves away (the wanted drop deepening every tick), hips
// that only chase the goal lag it and the held foot falls short of its
// anchor; following the goal's motion keeps it there, still without a jump.
TEST(FootLocker, HipsFollowADeepeningDropWithoutLag) {
  const DropResult followed = run_hip_drop(0.1f);
  const DropResult chased = run_hip_drop(0.1f, 0.0f);
  EXPECT_LT(followed.largest_foot_error, 1e-3f);
  EXPECT_GT(chased.largest_foot_error, 2.0f * followed.largest_foot_error);
  EXPECT_LT(followed.largest_drop_step, 0.002f);
  EXPECT_NEAR(followed.drop, chased.drop, 1e-4f);  // the same drop once the root stops
  std::printf("largest foot error while the drop deepens: %.2g m following the goal, %.2g m chasing it\n",
              double(followed.largest_foot_error), double(chased.largest_foot_error));
}

// A nearly straight leg whose animated knee wobbles about the hip-ankle
// line (bent 1.2 degrees forward, then as far back, five times a second:
// motion capture's noise on a straight leg), both feet held while the root
// moves 0.45 m forward, so the hips drop and the IK bends the legs far more
// than the animation does. Where the animated knee's plane set the bend, the
// knee flipped sides as the wobble crossed zero; the kept knee direction
// moves it no faster than the hips and ankle move.
struct WobbleResult {
  float largest_knee_step = 0.0f;   // the left knee relative to its hip, per tick (m)
  float largest_ankle_step = 0.0f;  // the left ankle relative to its hip, per tick (m)
  float largest_hip_step = 0.0f;    // the left hip, per tick (m)
  float drop = 0.0f;
};
WobbleResult run_knee_wobble(float rate) {
  const AnimationData a = make_skeleton();
  FootIkParams params;
  params.max_hip_drop = 0.2f;
  Result<FootLocker> locker = FootLocker::create(a, 1, params);
  EXPECT_TRUE(locker.ok()) << locker.message();
  const FootLocker::Leg leg = locker->legs()[0];
  const float dt = 1.0f / rate;
  std::vector<glm::vec3> world(a.joint_count());
  WobbleResult result;
  glm::vec3 last_knee(0.0f), last_ankle(0.0f), last_hip(0.0f);
  const int ticks = static_cast<int>(2.0f * rate);
  for (int i = 0; i < ticks; ++i) {
    const float t = float(i) * dt;
    // The knee's bend at the hip (radians, positive forward): a pole of at
    // most 1% of the leg's length.
    const float bend = 0.02f * std::cos(2.0f * 3.14159265f * 5.0f * t);
    Pose pose = rest_pose(a, 0.05f + kToeHeight + 0.06f + 2.0f * kBone * std::cos(bend));
    for (int side = 0; side < 2; ++side) {
      const std::size_t upper = static_cast<std::size_t>(locker->legs()[static_cast<std::size_t>(side)].upper);
      pose.rotations[upper] = glm::angleAxis(-bend, kX);
      pose.rotations[upper + 1] = glm::angleAxis(2.0f * bend, kX);
      pose.rotations[upper + 2] = glm::angleAxis(-bend, kX);
    }
    pose.contacts = kContactLeft | kContactRight;
    const float s = std::min(t / 1.5f, 1.0f);  // eased in and out: the hips' spring starts and stops smoothly
    const glm::vec3 root(0.0f, 0.0f, 0.45f * s * s * (3.0f - 2.0f * s));
    update_locker(*locker, a, 0, i == 0 ? 0.0f : dt, pose.contacts, root, 0.0f, pose.rotations, pose.translations, world);
    const glm::vec3 hip = world[static_cast<std::size_t>(leg.upper)];
    const glm::vec3 knee = world[static_cast<std::size_t>(leg.lower)] - hip;
    const glm::vec3 ankle = world[static_cast<std::size_t>(leg.foot)] - hip;
    if (i > 0) {
      result.largest_knee_step = std::max(result.largest_knee_step, glm::length(knee - last_knee));
      result.largest_ankle_step = std::max(result.largest_ankle_step, glm::length(ankle - last_ankle));
      result.largest_hip_step = std::max(result.largest_hip_step, glm::length(hip - last_hip));
    }
    last_knee = knee;
    last_ankle = ankle;
    last_hip = hip;
    EXPECT_EQ(locker->locked()[0], 1) << i;
  }
  result.drop = locker->hip_drops()[0];
  return result;
}

TEST(FootLocker, ANearlyStraightKneeDoesNotFlipAsTheHipsDrop) {
  for (const float rate : {30.0f, 60.0f}) {
    const WobbleResult r = run_knee_wobble(rate);
    EXPECT_GT(r.drop, 0.1f) << rate;  // the legs are bent well beyond the animation's
    // The knee, relative to the hip, moves at most twice as far as the ankle
    // or the hip in any tick (flipping with the wobble it moved 0.064 m a
    // tick, 4 and 8 times the ankle at 30 and 60 Hz; kept, 0.009 and 0.006).
    EXPECT_LT(r.largest_knee_step, 2.0f * std::max(r.largest_ankle_step, r.largest_hip_step)) << rate;
    std::printf("%g Hz: drop %.3f m, largest step per tick: knee %.4f m, ankle %.4f m, hip %.4f m\n", double(rate),
                double(r.drop), double(r.largest_knee_step), double(r.largest_ankle_step), double(r.largest_hip_step));
  }
}

TEST(FootLocker, CharactersUpdateConcurrentlyAsSerially) {
  const AnimationData a = make_skeleton();
  const std::uint32_t characters = 64;
  Result<FootLocker> serial = FootLocker::create(a, characters);
  Result<FootLocker> parallel = FootLocker::create(a, characters);
  ASSERT_TRUE(serial.ok() && parallel.ok());
  const std::size_t joints = a.joint_count();
  std::vector<glm::quat> rotations_a(characters * joints), rotations_b(characters * joints);
  std::vector<glm::vec3> translations_a(characters * joints), translations_b(characters * joints);
  std::vector<glm::vec3> world_a(characters * joints), world_b(characters * joints);
  ThreadPool pool(2);
  const float dt = 1.0f / 30.0f;
  for (int i = 0; i < 60; ++i) {
    auto step = [&](FootLocker& locker, std::vector<glm::quat>& rotations, std::vector<glm::vec3>& translations,
                    std::vector<glm::vec3>& world, std::size_t begin, std::size_t end) {
      for (std::size_t b = begin; b < end; ++b) {
        const float t = float(i) * dt + 0.37f * float(b);
        Pose pose = walk_pose(a, t);
        glm::vec3 root;
        float yaw;
        walk_root(t, 0.1f * float(b % 5), root, yaw);
        std::copy(pose.rotations.begin(), pose.rotations.end(), rotations.begin() + long(b * joints));
        std::copy(pose.translations.begin(), pose.translations.end(), translations.begin() + long(b * joints));
        update_locker(locker, a, static_cast<std::uint32_t>(b), dt, pose.contacts, root, yaw,
                      std::span(rotations).subspan(b * joints, joints), std::span(translations).subspan(b * joints, joints),
                      std::span(world).subspan(b * joints, joints));
      }
    };
    step(*serial, rotations_a, translations_a, world_a, 0, characters);
    pool.parallel_for(characters, [&](std::size_t begin, std::size_t end, unsigned) {
      step(*parallel, rotations_b, translations_b, world_b, begin, end);
    });
    ASSERT_EQ(rotations_a, rotations_b) << i;
    ASSERT_EQ(world_a, world_b) << i;
  }
  EXPECT_EQ(std::vector<std::uint8_t>(serial->locked().begin(), serial->locked().end()),
            std::vector<std::uint8_t>(parallel->locked().begin(), parallel->locked().end()));
}

TEST(FootLocker, ErrorsNameTheRoleOrField) {
  const AnimationData a = make_skeleton();
  EXPECT_FALSE(FootLocker::create(a, 0).ok());
  struct BadParam {
    const char* field;
    void (*set)(FootIkParams&);
  };
  const BadParam bad[] = {
      {"soft_reach_start", [](FootIkParams& p) { p.soft_reach_start = 0.0f; }},
      {"soft_reach_start", [](FootIkParams& p) { p.soft_reach_start = 1.5f; }},
      {"unlock_distance", [](FootIkParams& p) { p.unlock_distance = -1.0f; }},
      {"max_yaw_correction", [](FootIkParams& p) { p.max_yaw_correction = NAN; }},
      {"release_half_life", [](FootIkParams& p) { p.release_half_life = 0.0f; }},
      {"hip_half_life", [](FootIkParams& p) { p.hip_half_life = INFINITY; }},
      {"max_hip_drop", [](FootIkParams& p) { p.max_hip_drop = -0.1f; }},
      {"max_hip_goal_rate", [](FootIkParams& p) { p.max_hip_goal_rate = NAN; }},
      {"floor_height", [](FootIkParams& p) { p.floor_height = NAN; }},
  };
  for (const BadParam& b : bad) {
    FootIkParams params;
    b.set(params);
    Result<FootLocker> locker = FootLocker::create(a, 1, params);
    ASSERT_FALSE(locker.ok()) << b.field;
    EXPECT_NE(locker.message().find(b.field), std::string::npos) << locker.message();
  }
  AnimationData no_knee = make_skeleton();
  no_knee.skeleton.names[2] = "LeftSomething";
  Result<FootLocker> missing = FootLocker::create(no_knee, 1);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("left_lower_leg"), std::string::npos) << missing.message();
  // A foot that is not below its knee.
  AnimationData crossed = make_skeleton();
  crossed.skeleton.parents[3] = 0;
  Result<FootLocker> chain = FootLocker::create(crossed, 1);
  ASSERT_FALSE(chain.ok());
  EXPECT_NE(chain.message().find("@left_foot"), std::string::npos) << chain.message();
  // set_params validates too, and keeps the old parameters on an error.
  Result<FootLocker> locker = FootLocker::create(a, 1);
  ASSERT_TRUE(locker.ok());
  FootIkParams off;
  off.enabled = false;
  EXPECT_TRUE(locker->set_params(off).ok());
  EXPECT_FALSE(locker->params().enabled);
  FootIkParams bad_params;
  bad_params.hip_half_life = -1.0f;
  const Status status = locker->set_params(bad_params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("hip_half_life"), std::string::npos) << status.message();
  EXPECT_FALSE(locker->params().enabled);
}

}  // namespace
}  // namespace mmvk
