// Sampling stored poses and root motion, rebuilding a clip's Motion, and
// batched forward kinematics.
#include <cassert>
#include <cmath>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/animation/spring.hpp"
#include "yaw.hpp"

namespace mmvk {

namespace {

using detail::yaw_rotation;

}  // namespace

void sample_pose(const AnimationData& animation, std::uint32_t frame, std::span<glm::quat> local_rotations,
                 std::span<glm::vec3> local_translations) {
  const std::size_t joints = animation.joint_count();
  assert(frame < animation.frame_count && local_rotations.size() >= joints && local_translations.size() >= joints);
  const glm::quat* rotations = animation.local_rotations.data() + std::size_t{frame} * joints;
  for (std::size_t j = 0; j < joints; ++j) {
    local_rotations[j] = rotations[j];
    local_translations[j] = animation.skeleton.rest_offsets[j];
  }
  const std::size_t count = animation.translated_joints.size();
  const glm::vec3* translations = animation.local_translations.data() + std::size_t{frame} * count;
  for (std::size_t t = 0; t < count; ++t) local_translations[animation.translated_joints[t]] = translations[t];
}

RootDelta root_delta(const AnimationData& animation, std::uint32_t from, std::uint32_t to) {
  const float yaw = animation.root_yaws[from];
  const glm::vec3 world = animation.root_positions[to] - animation.root_positions[from];
  // The inverse yaw rotation of the world displacement: character space of `from`.
  RootDelta delta;
  delta.translation = detail::YawTurn(yaw).undo(glm::vec3(world.x, 0.0f, world.z));
  delta.yaw = wrap_angle(animation.root_yaws[to] - yaw);
  return delta;
}

Result<Motion> clip_motion(const AnimationData& animation, float fps, std::uint32_t first_frame,
                           std::uint32_t frame_count) {
  if (std::uint64_t{first_frame} + frame_count > animation.frame_count) {
    return make_error("clip_motion: frames [" + std::to_string(first_frame) + ", " +
                      std::to_string(std::uint64_t{first_frame} + frame_count) + ") are past the animation's " +
                      std::to_string(animation.frame_count) + " frames");
  }
  Motion motion;
  motion.skeleton = animation.skeleton;
  motion.fps = fps;
  motion.frame_count = frame_count;
  const std::size_t joints = animation.joint_count();
  motion.local_rotations.resize(std::size_t{frame_count} * joints);
  motion.local_positions.resize(std::size_t{frame_count} * joints);
  for (std::uint32_t f = 0; f < frame_count; ++f) {
    const std::uint32_t frame = first_frame + f;
    std::span<glm::quat> rotations(motion.local_rotations.data() + std::size_t{f} * joints, joints);
    std::span<glm::vec3> positions(motion.local_positions.data() + std::size_t{f} * joints, joints);
    sample_pose(animation, frame, rotations, positions);
    // Top-level joints back from character space to the clip's world.
    const glm::quat to_world = yaw_rotation(animation.root_yaws[frame]);
    for (std::size_t j = 0; j < joints; ++j) {
      if (animation.skeleton.parents[j] >= 0) continue;
      rotations[j] = to_world * rotations[j];
      positions[j] = animation.root_positions[frame] + to_world * positions[j];
    }
  }
  return motion;
}

void forward_kinematics_batch(const Skeleton& skeleton, std::span<const glm::quat> local_rotations,
                              std::span<const glm::vec3> local_translations,
                              std::span<const glm::vec3> root_positions, std::span<const float> root_yaws,
                              std::span<glm::vec3> world_positions, ThreadPool* pool) {
  const std::size_t joints = skeleton.size();
  const std::size_t characters = root_positions.size();
  assert(root_yaws.size() == characters && local_rotations.size() >= characters * joints &&
         local_translations.size() >= characters * joints && world_positions.size() >= characters * joints);
  const int* parents = skeleton.parents.data();
  auto body = [&](std::size_t begin, std::size_t end, unsigned) {
    // Global rotations of one character at a time, on the stack: 256 joints
    // is far above any mocap skeleton (Bandai 22, CMU 31, LAFAN1 22); deeper
    // indices recompute their parent's global rotation up the chain.
    constexpr std::size_t kMaxStackJoints = 256;
    glm::quat global[kMaxStackJoints];
    for (std::size_t b = begin; b < end; ++b) {
      const glm::quat* rotations = local_rotations.data() + b * joints;
      const glm::vec3* translations = local_translations.data() + b * joints;
      glm::vec3* out = world_positions.data() + b * joints;
      const glm::quat root = yaw_rotation(root_yaws[b]);
      auto global_of = [&](std::size_t j) {
        if (j < kMaxStackJoints) return global[j];
        glm::quat g = rotations[j];
        int p = parents[j];
        for (; p >= 0 && static_cast<std::size_t>(p) >= kMaxStackJoints; p = parents[p]) g = rotations[p] * g;
        return (p >= 0 ? global[p] : root) * g;
      };
      for (std::size_t j = 0; j < joints; ++j) {
        const int parent = parents[j];
        glm::quat g;
        if (parent < 0) {
          g = root * rotations[j];
          out[j] = root_positions[b] + root * translations[j];
        } else {
          const std::size_t p = static_cast<std::size_t>(parent);
          const glm::quat gp = global_of(p);
          out[j] = out[p] + gp * translations[j];
          g = gp * rotations[j];
        }
        if (j < kMaxStackJoints) global[j] = g;
      }
    }
  };
  if (pool != nullptr && characters > 64) {
    pool->parallel_for(characters, body);
  } else {
    body(0, characters, 0);
  }
}

}  // namespace mmvk
