// Analytic two-bone IK for a leg (hip - knee - ankle), the solver behind
// foot locking (foot_locker.hpp). Positions in any one space (the locker
// passes world space, metres); the solution is two rotations to apply to the
// chain, so it works on any skeleton convention.
//
// The knee bends in the plane of the animated leg: the pole is the animated
// knee's offset from the animated hip-to-ankle line, so a target in that
// plane keeps the knee in it, and a target off it turns the plane about the
// hip-to-target axis as little as the pole allows (solve_two_bone_ik_toward
// takes the pole from its caller instead: the foot locker keeps each knee's
// direction while the animated leg is nearly straight). Near full extension
// the reach is softened (soft_reach) so the knee never snaps straight.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace mmvk {

// The distance a leg reaches when asked to reach `distance`: the identity up
// to `start`, then an exponential approach to `limit` that is C1 at `start`:
//   start + w (1 - exp(-(distance - start) / w)),  w = limit - start.
// So it is continuous and increasing, below `limit` for every distance, and a
// leg asked beyond its length bends a little instead of locking straight.
// start >= limit (no soft zone) is a hard clamp at limit.
float soft_reach(float distance, float start, float limit);

// The shortest rotation taking direction `from` to direction `to` (any
// lengths). Identity when either is (nearly) zero; a half turn about an axis
// perpendicular to `from` when they are opposite. Never NaN for finite input.
glm::quat rotation_between(const glm::vec3& from, const glm::vec3& to);

struct TwoBoneIkSolution {
  // Rotations in the space of the positions: upper premultiplies the upper
  // leg's global rotation (the hip joint turns), lower premultiplies the
  // lower leg's global rotation after upper was applied. So
  //   knee' = hip + upper * (knee - hip)
  //   ankle' = knee' + lower * upper * (ankle - knee).
  glm::quat upper{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat lower{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 knee{0.0f};   // knee' (the solved knee position)
  glm::vec3 ankle{0.0f};  // ankle' (where the ankle ends up)
  // The ankle was not put on the target (more than 1 mm away): the target
  // was in the soft zone or beyond the leg's length, or nearer the hip than
  // |upper length - lower length|.
  bool clamped = false;
};

// Solves hip-knee-ankle (the animated positions) for the ankle to reach
// `target`.
//   - Reach: d = |target - hip| is softened by soft_reach(d, start, L), L =
//     upper + lower length, start = max(soft_start * L, |ankle - hip|)
//     capped at L: the animated extension always counts as reachable, so a
//     target at the animated ankle returns the animated pose; and at least
//     |upper - lower| (a leg cannot fold closer).
//   - Knee plane: the pole is the animated knee's offset from the animated
//     hip-ankle line. As that offset shrinks below 1% of L (a straight
//     animated leg) `pole_hint` (e.g. the character's forward direction) is
//     blended in, so the bend direction stays defined and continuous.
//   - Degenerate input (zero-length bones, straight legs, a target at the
//     hip, far beyond reach) gives finite rotations and positions: a target
//     at the hip is approached along the animated hip-ankle direction.
// soft_start in (0, 1] (FootIkParams::soft_reach_start).
TwoBoneIkSolution solve_two_bone_ik(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                                    const glm::vec3& target, const glm::vec3& pole_hint, float soft_start);

// As solve_two_bone_ik, with the knee bent toward `pole` (any length; its
// part perpendicular to the hip-to-target line counts) instead of the
// animated knee's plane: for a caller that keeps the bend direction of a
// nearly straight animated leg, whose own plane is noise (FootLocker). A
// pole along the target line, or zero, bends toward the animated knee's
// offset, then any perpendicular.
TwoBoneIkSolution solve_two_bone_ik_toward(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                                           const glm::vec3& target, const glm::vec3& pole, float soft_start);

}  // namespace mmvk
