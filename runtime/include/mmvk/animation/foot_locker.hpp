// Foot locking for B characters: planted feet held where they touched the
// ground, through two-bone IK (foot_ik.hpp), with the hips lowered when a
// held foot is out of reach. A post-process on the displayed pose, after
// playback and inertialization; docs/animation.md describes it in prose.
//
// Per foot (index b * 2 + side, side 0 left, 1 right) the state is a
// horizontal correction c (world metres) and a yaw correction psi (radians
// about +Y) added to the animated foot:
//   - contact point P: the toe joint when the frame's toe bit is set (or
//     neither point bit is: data without them), else the heel (the ankle);
//     the ankle where the skeleton has no toe;
//   - target: the ankle is aimed at P + c + R_y(psi) * (ankle - P) at its
//     animated height, and the foot keeps its animated global rotation
//     turned by R_y(psi), so the toe keeps its animated attitude to the
//     ground; with clamp_to_floor the target rises so neither the ankle nor
//     the toe is below the floor;
//   - lock: while the foot is planted (kContactLeft / kContactRight) and not
//     locked, it locks at its displayed contact point (P + c) and displayed
//     heading; while locked, c = anchor - P and psi = anchor yaw - animated
//     yaw, so the displayed contact point stays on the anchor. |psi| is held
//     to max_yaw_correction: an animated foot that turns further pivots
//     about its contact point with the animation. A switch of contact point
//     (heel to toe) re-anchors at the new point's displayed position, so c
//     stays continuous;
//   - release: when the contact ends, or c grows beyond unlock_distance.
//     Then c and psi decay to zero with a critically damped spring
//     (release_half_life), starting from their last rate of change, so the
//     displayed foot is continuous in position and velocity. A foot released
//     by drift does not lock again until its contact has ended;
//   - hips: when a target is beyond a leg's comfortable reach (the soft
//     start, or the animated extension where that is longer), the hips are
//     lowered by the least drop that brings it within reach, for the worse
//     of the two legs, at most max_hip_drop, followed by a critically
//     damped spring (hip_half_life) that moves with the wanted drop up to
//     max_hip_goal_rate.
//   - knees: a solved leg bends toward its knee's kept direction: the
//     animated knee's when the animated leg is clearly bent (10% of its
//     length off the hip-ankle line), held while it is nearly straight (under
//     2%), turned toward it in between; so lowering the hips, which bends
//     legs the animation holds straight, never flips a knee to the side its
//     noise points.
// A foot without correction, with the hips not lowered, is left exactly as
// animated (no solve).
//
// Threads: update() and reset() of different characters may run
// concurrently (each touches only its character's state; the scratch is on
// the stack, or per character for skeletons over kStackJoints joints). No
// allocation after create().
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

struct FootIkParams {
  // Off: update() leaves the pose untouched and only copies the world joint
  // positions; the lock state is cleared.
  bool enabled = true;
  // Fraction of a leg's length (upper + lower bone) from which its reach is
  // softened (soft_reach), in (0, 1]; 1 is a hard clamp at full extension.
  float soft_reach_start = 0.95f;
  // Horizontal correction (metres, > 0) beyond which a lock is released.
  // A released foot slides back to its animation, which shows, so the
  // distance is as long as a leg can hold; bench/RESULTS.md "Defaults and
  // the measurements that chose them" has the figures.
  float unlock_distance = 0.5f;
  // Hold the foot's heading while locked (the foot turns about its contact
  // point by psi), by at most max_yaw_correction (radians, > 0): an animated
  // foot that turns further (a pivot in a turn) turns on about its contact
  // point, its position still held.
  bool lock_yaw = true;
  float max_yaw_correction = 0.4f;
  // Half-life (seconds, > 0) of the correction's decay after a release.
  float release_half_life = 0.1f;
  // Largest lowering of the hips (metres, >= 0; 0 disables it) and the
  // half-life (seconds, > 0) of the spring that follows the wanted drop.
  // The spring tracks the wanted drop's own motion up to max_hip_goal_rate
  // (metres per second, >= 0; 0: it chases a goal it treats as still, and
  // lags a deepening one by about a half-life, long enough for a held foot
  // at full stride to slip out of reach). 0.2 m gives most of the sliding
  // gain without a deeper crouch, and a faster hip spring shakes the pose;
  // the figures are in bench/RESULTS.md ("Defaults and the measurements that
  // chose them", and "The default data").
  float max_hip_drop = 0.2f;
  float hip_half_life = 0.1f;
  float max_hip_goal_rate = 1.0f;
  // Keep the ankle and toe joints at or above the floor: floor_height
  // (metres, finite) above the root's y.
  bool clamp_to_floor = true;
  float floor_height = 0.0f;

  // Errors name the field ("foot IK: unlock_distance must be finite and > 0,
  // got 0.000000").
  Status validate() const;
};

class FootLocker {
 public:
  // Skeletons up to this many joints use stack scratch in update(); larger
  // ones a per-character buffer sized at create().
  static constexpr std::size_t kStackJoints = 256;

  // Resolves per side @left_/@right_upper_leg, _lower_leg, _foot (ankle) and
  // optionally _toe (find_bone roles), and @hips. Errors: a role that does
  // not resolve (find_bone's message, which names it), a chain that is not
  // hips > upper leg > lower leg > foot (> toe) in the hierarchy (naming the
  // roles and joints), characters == 0, params.validate().
  static Result<FootLocker> create(const AnimationData& animation, std::uint32_t characters,
                                   const FootIkParams& params = {});

  // One tick of character b (b < size()).
  //   dt: seconds since its last update (>= 0; 0 moves no spring).
  //   contacts: FootContact bits of the pose shown (AnimationData::contacts).
  //   root_position, root_yaw: the character root, world (metres, radians).
  //   animated_world [joints]: the world joint positions of the pose as it
  //     comes in, world = root + R_y(yaw) * fk(pose) (forward_kinematics_batch;
  //     the controller's one FK per tick, which the locker reads rather than
  //     runs again).
  //   local_rotations, local_translations [joints]: in, the animated pose in
  //     character space (as sample_pose writes it, after inertialization);
  //     out, the pose with IK applied (upper leg, lower leg and foot
  //     rotations, and the hips' translation when lowered).
  //   world_positions [joints]: out, the world joint positions of the output
  //     pose (animated_world where IK changed nothing).
  void update(std::uint32_t b, float dt, std::uint8_t contacts, const glm::vec3& root_position, float root_yaw,
              std::span<const glm::vec3> animated_world, std::span<glm::quat> local_rotations,
              std::span<glm::vec3> local_translations, std::span<glm::vec3> world_positions);

  // Forgets character b's locks, corrections and hip drop (a teleport: the
  // controller's place()). Its next update locks planted feet afresh.
  void reset(std::uint32_t b);

  // Character b's foot `side` (0 left, 1 right) steps onto its animated
  // pose: its lock is released, and over the next 0.25 s its correction
  // eases to zero with the foot lifted on an arc (a quarter of the
  // distance, at most 6 cm), whatever the contacts say; then a planted foot
  // locks where it landed. For a standing character with a foot still
  // locked where it planted mid-stride. No effect while that foot steps
  // already.
  void step(std::uint32_t b, std::size_t side);

  std::uint32_t size() const { return characters_; }
  const FootIkParams& params() const { return params_; }
  // New parameters between ticks (not during updates), e.g. IK switched on
  // or off: the locks carry on (switched off, each character's state is
  // cleared at its next update). Errors: params.validate(); nothing changes.
  Status set_params(const FootIkParams& params);

  // Per foot, [B x 2] at b * 2 + side (0 left, 1 right), as of the last update:
  std::span<const std::uint8_t> locked() const { return locked_; }         // 1: held on its anchor
  std::span<const glm::vec3> anchors() const { return anchor_; }          // world; the last lock's (y: its height then)
  std::span<const std::uint8_t> reach_clamped() const { return clamped_; }  // 1: the ankle missed its target this tick
  std::span<const glm::vec3> corrections() const { return offset_; }     // c, world metres (y = 0)
  std::span<const float> yaw_corrections() const { return yaw_offset_; }  // psi, radians
  // True while the foot steps (step()).
  bool stepping(std::uint32_t b, std::size_t side) const { return steps_[std::size_t{b} * 2 + side].time >= 0.0f; }
  // Per character [B]: how far the hips are lowered (metres, >= 0).
  std::span<const float> hip_drops() const { return hip_drop_; }

  // The resolved joints (toe -1 where the skeleton has none).
  struct Leg {
    int upper = -1;
    int lower = -1;
    int foot = -1;
    int toe = -1;
  };
  const std::array<Leg, 2>& legs() const { return legs_; }
  int hips() const { return hips_; }

 private:
  FootLocker() = default;
  void clear(std::uint32_t b);

  // update()'s steps, per foot, defined where update() is (foot_locker.cpp).
  struct Steps;

  std::uint32_t characters_ = 0;
  FootIkParams params_;
  std::vector<int> parents_;
  std::array<Leg, 2> legs_{};
  int hips_ = -1;
  std::array<glm::vec3, 2> heading_{};             // per side: the foot's forward direction in its own frame
  std::vector<std::uint8_t> below_hips_;           // [joints] 1: the hips or under them
  std::array<std::vector<int>, 2> leg_joints_;     // per side: the upper leg and its descendants, ascending
  std::vector<int> rotated_joints_;                // the legs and their ancestors (the hips' too), ascending
  std::vector<glm::quat> wide_scratch_;            // [B x joints], only for skeletons over kStackJoints

  // Per foot [B x 2].
  std::vector<std::uint8_t> locked_, clamped_, point_, drifted_;
  std::vector<glm::vec3> anchor_, offset_, offset_rate_;
  std::vector<glm::vec3> knee_direction_;  // the knee's kept bend direction, character space (zero: none yet)
  std::vector<float> anchor_yaw_, yaw_offset_, yaw_rate_;
  // A foot's step (step()): seconds into it (negative: none), this
  // update's lift (metres), and the corrections it started from.
  struct Step {
    float time = -1.0f;
    float lift = 0.0f;
    float from_yaw = 0.0f;
    glm::vec3 from{0.0f};
  };
  std::vector<Step> steps_;
  // Per character [B].
  std::vector<float> hip_drop_, hip_drop_rate_, hip_goal_;  // hip_goal_: the last tick's wanted drop
};

}  // namespace mmvk
