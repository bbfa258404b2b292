// Forward kinematics: local joint transforms -> model-space transforms.
#include <cassert>

#include "mmvk/import/motion.hpp"

namespace mmvk {

void forward_kinematics(const Motion& motion, std::uint32_t frame, std::span<glm::vec3> global_positions,
                        std::span<glm::quat> global_rotations) {
  const std::size_t joints = motion.joint_count();
  assert(frame < motion.frame_count);
  assert(global_positions.size() >= joints && global_rotations.size() >= joints);
  const glm::vec3* local_positions = motion.local_positions.data() + motion.index(frame, 0);
  const glm::quat* local_rotations = motion.local_rotations.data() + motion.index(frame, 0);
  // Parents precede children, so one pass in joint order suffices.
  for (std::size_t j = 0; j < joints; ++j) {
    const int parent = motion.skeleton.parents[j];
    if (parent < 0) {
      global_positions[j] = local_positions[j];
      global_rotations[j] = local_rotations[j];
    } else {
      const std::size_t p = static_cast<std::size_t>(parent);
      global_positions[j] = global_positions[p] + global_rotations[p] * local_positions[j];
      global_rotations[j] = global_rotations[p] * local_rotations[j];
    }
  }
}

void forward_kinematics_clip(const Motion& motion, std::span<glm::vec3> global_positions,
                             std::span<glm::quat> global_rotations) {
  const std::size_t joints = motion.joint_count();
  assert(global_positions.size() >= motion.frame_count * joints);
  assert(global_rotations.size() >= motion.frame_count * joints);
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    forward_kinematics(motion, f, global_positions.subspan(f * joints, joints),
                       global_rotations.subspan(f * joints, joints));
  }
}

}  // namespace mmvk
