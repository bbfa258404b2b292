// The animation section of a Database: the skeleton and, per database frame,
// the pose (local joint rotations and the translations that vary), the
// character root (position and facing on the ground) and foot contacts.
// Optional: a database built with --no-animation, or loaded from a format 1
// file, has features only (Database::animation() is null).
//
// Spaces. The pose is stored in character space (origin = the frame's
// character root position, +Z = its facing, +Y up). Joints above the hips
// (static scene roots such as Bandai's joint_Root) are the identity at the
// character root; every joint whose parent is such a joint, or which has no
// parent (the hips), stores its model-space rotation and translation
// re-expressed in character space; all other joints keep their local
// transforms relative to their parents as imported. Forward kinematics of a
// stored pose therefore gives joint positions relative to the character, and
// placing them at a root position p and yaw a gives world = p + R_y(a) * q.
// The import's model-space positions (of every joint from the hips down) are
// recovered with the frame's own root_positions and root_yaws.
//
// Yaw: radians about +Y; yaw 0 faces +Z, and facing = (sin yaw, 0, cos yaw).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// How rotations are kept in the .mmdb file (always float in memory).
enum class RotationEncoding : std::uint8_t {
  Float32,      // 16 bytes per joint, exact
  Quantized16,  // 4 x int16 per joint (8 bytes); worst-case error measured < 0.1 degree
};

struct AnimationData {
  Skeleton skeleton;                 // names, parents (parents[i] < i), rest offsets (metres)
  std::vector<int> mirror_pairs;     // [joints] each joint's mirror partner (itself when none)
  // Joints whose local translation varies between frames (the hips, stored
  // in character space), ascending. Every other joint uses
  // skeleton.rest_offsets, which hold the effective constant translation.
  std::vector<std::uint32_t> translated_joints;
  // The contact points of each foot (left, right): the toe, and the heel
  // (the ankle joint, "@left_foot"). A skeleton without a toe (DAZ) has its
  // heel in both, and no toe bits in `contacts`. -1 where neither resolved.
  std::array<int, 2> contact_joints{-1, -1};
  std::array<int, 2> heel_joints{-1, -1};
  FootContactParams contact_params;  // the thresholds the contacts were detected with
  // Contacts loaded from a format 2 to 4 file: detected on 3-D speed without
  // hysteresis or minimum durations; rebuilding the database relabels them.
  bool legacy_contacts = false;
  RotationEncoding encoding = RotationEncoding::Float32;

  std::uint32_t frame_count = 0;                 // = Database::frame_count()
  std::vector<glm::quat> local_rotations;        // [frames x joints], unit (hips: character space)
  std::vector<glm::vec3> local_translations;     // [frames x translated_joints.size()], metres
  std::vector<glm::vec3> root_positions;         // [frames], the clip's world space, y = 0, metres
  std::vector<float> root_yaws;                  // [frames], radians
  std::vector<std::uint8_t> contacts;            // [frames], FootContact bits (foot_contacts.hpp)

  std::size_t joint_count() const { return skeleton.size(); }
  // Bytes one frame takes in memory (rotations, translations, root, contacts).
  std::size_t bytes_per_frame_in_memory() const;
  // Bytes one frame takes in the .mmdb file with `encoding`.
  std::size_t bytes_per_frame_in_file() const;
  // Checks sizes, parents, pairs, unit quaternions, finite values, and that
  // the frame count equals `frames`. Errors name the field.
  Status validate(std::uint32_t frames) const;
};

// The clear error for a database without animation. `what` names the
// caller ("crowd controller"); `reason` is the database's own record of why
// (Database::no_animation_reason). Without one (older files) the error lists
// the possible causes rather than blame a flag the user never passed.
Error missing_animation_error(std::string_view what, std::string_view reason);
// The reason alone, for reports: `reason`, or the possible causes.
std::string no_animation_explanation(std::string_view reason);

// The pose of one database frame in character space: local rotations [joints]
// and local translations [joints] (rest offsets, or the frame's translation
// for translated joints). Preconditions: frame < frame_count, spans sized
// joint_count().
void sample_pose(const AnimationData& animation, std::uint32_t frame, std::span<glm::quat> local_rotations,
                 std::span<glm::vec3> local_translations);

// Root motion from database frame `from` to frame `to`, expressed in `from`'s
// character space: the displacement (x, z in metres, y = 0) and the yaw change
// (radians, wrapped to [-pi, pi]).
struct RootDelta {
  glm::vec3 translation{0.0f};
  float yaw = 0.0f;
};
RootDelta root_delta(const AnimationData& animation, std::uint32_t from, std::uint32_t to);

// The motion of one database clip (frames [first, first + count)) back in the
// import's model space: what the build imported after resampling and
// mirroring, up to float rounding. Used by export, tests and tools.
Result<Motion> clip_motion(const AnimationData& animation, float fps, std::uint32_t first_frame,
                           std::uint32_t frame_count);

}  // namespace mmvk
