// The database build's animation step: each clip's motion turned into
// character-space poses, root motion and foot contacts, then the clips
// concatenated into one AnimationData (animation_data.hpp).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::detail {

// One clip's animation before concatenation. To keep the build's memory low,
// joint translations are kept per frame only for joints whose translation
// varies within the clip; the others keep one constant value.
struct ClipAnimation {
  Skeleton skeleton;
  std::string source;                         // names the clip in errors
  std::uint32_t frame_count = 0;
  std::array<int, 2> contact_joints{-1, -1};  // AnimationData::contact_joints
  std::array<int, 2> heel_joints{-1, -1};
  std::vector<glm::quat> rotations;           // [frames x joints]
  std::vector<glm::vec3> constant;            // [joints]: the translation of non-varying joints
  std::vector<std::uint32_t> varying;         // joints whose translation varies, ascending
  std::vector<glm::vec3> translations;        // [frames x varying]
  std::vector<glm::vec3> root_positions;      // [frames]
  std::vector<float> root_yaws;               // [frames]
  std::vector<std::uint8_t> contacts;         // [frames]
};

// `hips_bone` (the character root's source bone) decides which joints are
// re-expressed in character space (animation_build.cpp).
Result<ClipAnimation> extract_clip_animation(const Motion& motion, const CharacterRoot& root,
                                             const std::string& hips_bone, const FootContactParams& contacts,
                                             std::string source);

// Concatenates the clips in order. Errors: clips with different skeletons
// (names or parents), naming both files (the build then leaves the section
// out and passes the message on as a warning).
Result<AnimationData> assemble_animation(std::span<const ClipAnimation> clips, const FootContactParams& contacts,
                                         RotationEncoding encoding,
                                         std::span<const BonePair> mirror_bones = {});

}  // namespace mmvk::detail
