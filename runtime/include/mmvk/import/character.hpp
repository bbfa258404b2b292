// Skeleton conventions: named bone roles (so one feature schema works on CMU,
// Bandai and other skeletons) and the character root ("simulation bone").
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// Resolves a bone reference: either an exact joint name ("Foot_L") or a role
// written with a leading '@': "@hips", "@left_upper_leg", "@right_upper_leg",
// "@left_lower_leg", "@right_lower_leg", "@left_foot", "@right_foot" (ankle),
// "@left_toe", "@right_toe" (ball of the foot), "@left_shoulder",
// "@right_shoulder" (the upper arm joint, not the clavicle), "@left_hand",
// "@right_hand" (wrist), "@head". Roles are matched against the naming conventions seen in
// CMU (ASF lfemur/ltibia/lfoot/ltoes, cgspeed max LeftHip/LeftKnee/LeftAnkle,
// mb LeftUpLeg/LeftLeg/LeftFoot/LeftToeBase, DAZ lThigh/lShin/lFoot), Bandai
// Namco (UpperLeg_L/LowerLeg_L/Foot_L/Toes_L) and LAFAN1 skeletons, compared
// lower-case without punctuation. "@hips" is the deepest common ancestor of
// the two upper legs (so Bandai's static joint_Root above Hips is never
// taken), or else a joint named hips/hip/pelvis/root. DAZ skeletons have no
// toe joint: "@left_toe" fails there. The error names the bone and lists the
// skeleton's joints.
Result<int> find_bone(const Skeleton& skeleton, std::string_view bone);

struct CharacterRootOptions {
  // The bone whose ground projection is the character root. "@hips" resolves
  // to the pelvis joint, never to a static scene root such as Bandai's
  // joint_Root.
  std::string source_bone = "@hips";
  // Facing is the horizontal direction perpendicular to the left->right
  // upper-leg axis, smoothed with a centred window of this many seconds.
  float facing_smoothing_seconds = 0.5f;
};

// Per frame: the root position on the ground (y = 0, metres) and its facing
// direction (unit vector in the XZ plane).
//
// The rule: position = the source bone's model-space position with y set to
// 0 (not smoothed). Raw facing = (left upper leg - right upper leg) x up,
// i.e. the horizontal direction perpendicular to the hip-to-hip axis (+Z for
// a character whose left is +X), normalized. The facing is the normalized
// mean of the raw facings over a centred window of facing_smoothing_seconds
// (half a window each side, cut at the clip's ends); a window whose mean
// vanishes keeps the previous facing (+Z on the first frame). Errors: an
// unknown source bone, no upper legs, a negative smoothing window, a motion
// with fps <= 0 or transforms not sized frame_count x joints.
struct CharacterRoot {
  std::vector<glm::vec3> positions;  // [frame_count]
  std::vector<glm::vec3> facings;    // [frame_count]
};

Result<CharacterRoot> compute_character_root(const Motion& motion, const CharacterRootOptions& options);

}  // namespace mmvk
