// Skeleton conventions: named bone roles (so one feature schema works on CMU,
// Bandai and other skeletons) and the character root ("simulation bone").
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/motion.hpp"
#include "mmvk/status.hpp"

namespace mmvk {

// Resolves a bone reference: either an exact joint name ("Foot_L") or a role
// written with a leading '@': "@hips", "@left_upper_leg", "@right_upper_leg",
// "@left_foot", "@right_foot", "@left_toe", "@right_toe". Roles are matched
// against the naming conventions seen in CMU (ASF, cgspeed max/mb/daz),
// Bandai Namco and LAFAN1 skeletons. The error names the bone and lists the
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
struct CharacterRoot {
  std::vector<glm::vec3> positions;  // [frame_count]
  std::vector<glm::vec3> facings;    // [frame_count]
};

Result<CharacterRoot> compute_character_root(const Motion& motion, const CharacterRootOptions& options);

}  // namespace mmvk
