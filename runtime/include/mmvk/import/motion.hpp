// A clip of motion as local joint transforms in metres, Y-up, right-handed,
// plus the operations that produce one: import from BVH (units, axes),
// resampling and left/right mirroring; and forward kinematics.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/import/bvh.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

struct Skeleton {
  std::vector<std::string> names;
  std::vector<int> parents;           // -1 for the root; parents[i] < i
  std::vector<glm::vec3> rest_offsets;  // metres, in the parent's frame

  std::size_t size() const { return names.size(); }
  // Index of the joint named `name` (exact match), or -1.
  int find(std::string_view name) const;
};

// Local transforms per frame, in metres, Y-up. Position channels of the BVH
// replace the OFFSET (they do not add to it), so local_positions holds the
// effective translation of each joint relative to its parent.
struct Motion {
  Skeleton skeleton;
  float fps = 0.0f;
  std::uint32_t frame_count = 0;
  std::vector<glm::vec3> local_positions;  // [frame_count x joints], metres
  std::vector<glm::quat> local_rotations;  // [frame_count x joints]

  std::size_t joint_count() const { return skeleton.size(); }
  std::size_t index(std::uint32_t frame, std::size_t joint) const { return frame * joint_count() + joint; }
};

// Frame rates mmvk accepts, from a BVH's Frame Time, a manifest's fps or
// --fps: outside them a value is a typo or a corrupt file (a Frame Time of
// 1e-30 would otherwise surface later as a baffling normalization error).
inline constexpr float kMinFps = 1.0f;
inline constexpr float kMaxFps = 10000.0f;

enum class UpAxis : std::uint8_t { Y, Z };

struct ImportOptions {
  // Metres per file unit. 0 = guess with guess_metres_per_unit(); CMU
  // ASF-derived BVH (amc2bvh, cgspeed max/mb) is 0.05644, Bandai, LAFAN1 and
  // cgspeed DAZ are 0.01.
  float metres_per_unit = 0.0f;
  // The file's up axis; Z-up files are rotated into mmvk's Y-up frame.
  UpAxis up_axis = UpAxis::Y;
  // Whether up_axis was given (a manifest's "up_axis"): BVH files are Y-up
  // unless told, while FBX and COLLADA files say their axes themselves and
  // keep them unless this is set (scene_import.hpp).
  bool up_axis_given = false;
  // The build's plausibility check of the imported motion (import_check.hpp)
  // reports instead of stopping the build when this is set (a manifest's
  // "import": {"accept_implausible": true}: a child, a giant, a crawl).
  bool accept_implausible = false;
};

// Rotation channels compose in the file's channel order as intrinsic
// rotations ("Zrotation Xrotation Yrotation" -> Rz * Rx * Ry); position
// channels replace the OFFSET's components. fps = 1 / frame_time, snapped to
// the nearest integer when within 0.01% (".0083333" -> 120). For a Z-up file
// the root's rest offset, translation and rotation are turned to Y-up by a
// -90 degree rotation about X ((x, y, z) -> (x, z, -y)); other joints stay in
// their parents' frames. Errors name the file (an inconsistent BvhFile, a bad
// option).
Result<Motion> motion_from_bvh(const BvhFile& file, const ImportOptions& options);

// The unit guess used when metres_per_unit is 0. Rule: take the skeleton's
// tree diameter in file units (the longest leaf-to-leaf path through the
// hierarchy, End Sites included, each bone counting the length of its OFFSET,
// the root's own OFFSET excluded): for a human about toe tip to finger tip,
// ~2.2 m. Return the candidate among cm (0.01), inches (0.0254), CMU ASF units
// (0.05644) and metres (1.0) whose diameter in metres is closest to 2.2 m on a
// log scale. Skeletons without bones give 1.0.
float guess_metres_per_unit(const BvhFile& file);

// Global (model-space) joint positions and rotations of one frame.
// Preconditions: frame < motion.frame_count, spans sized joint_count().
void forward_kinematics(const Motion& motion, std::uint32_t frame, std::span<glm::vec3> global_positions,
                        std::span<glm::quat> global_rotations);

// Forward kinematics of every frame. Preconditions: spans sized
// frame_count x joint_count(), row-major by frame ([frame][joint]).
void forward_kinematics_clip(const Motion& motion, std::span<glm::vec3> global_positions,
                             std::span<glm::quat> global_rotations);

// Resamples to `fps` (> 0, any rate): positions are interpolated linearly and
// rotations with slerp (shorter arc); the clip's duration is kept. A clip of
// n frames (duration (n - 1) / motion.fps) becomes round(duration * fps) + 1
// frames; output frame k samples source time k / fps, clamped to the last
// frame. Output frames that fall on source frames copy them exactly. 0 and 1
// frame clips stay 0 and 1 frames.
Result<Motion> resample(const Motion& motion, float fps);

// Swaps left and right and reflects across the world YZ plane (x -> -x): in
// the result, joint j's model-space position is its partner's original one
// with x negated (exactly so for symmetric skeletons). Joints are paired by
// mirror_pairs(); the skeleton (names, parents, rest offsets) is unchanged.
// Skeletons whose local frames are not world aligned (Bandai) are handled by
// a per-joint local reflection chosen from the rest offsets (see mirror.cpp).
// mirror(mirror(m)) == m bit for bit. Errors: partners whose parents are not
// partners, inconsistent sizes.
Result<Motion> mirror(const Motion& motion);

// A user's left/right pair (manifest "mirror_bones"): joint names or bone
// roles ("@left_foot", find_bone()). A pair of one joint with itself says
// the joint has no partner.
struct BonePair {
  std::string first;
  std::string second;
};

// mirror() with a user pair table that overrides the name heuristics: each
// joint the table names gets the table's partner; a heuristic pair that
// involves a named joint is dropped; the other joints keep the heuristics.
// Errors name the pair: "mirror_bones[1][0]: bone 'X' not found ...", a
// joint named twice.
Result<Motion> mirror(const Motion& motion, std::span<const BonePair> pairs);
Result<std::vector<int>> mirror_pairs(const Skeleton& skeleton, std::span<const BonePair> pairs);

// Index of each joint's mirror partner (itself when it has none). Names are
// paired when swapping a side marker gives another joint's name: "Left" <->
// "Right" (any case, anywhere: LeftUpLeg, leftEye, mixamorig:LeftFoot), a
// suffix "_L"/".L"/"-L"/" L" (Foot_L), an infix " L "/"_L_" (Bip01 L Thigh),
// or a leading L/l/R/r (LHipJoint, lThigh, lCollar, lfemur; "lowerback" stays
// unpaired as no "rowerback" exists). Only mutual pairs are kept.
std::vector<int> mirror_pairs(const Skeleton& skeleton);

}  // namespace mmvk
