// Finite-difference velocities of stored poses (pose_velocity.hpp).
#include "pose_velocity.hpp"

#include <utility>

#include "mmvk/animation/pose_batch.hpp"

namespace mmvk::detail {

namespace {

// The frames a finite difference at `frame` uses: forward inside its clip,
// backward on its last frame; {frame, frame} for a one-frame clip.
std::pair<std::uint32_t, std::uint32_t> difference_frames(const Database& database, std::uint32_t frame) {
  const Clip& clip = database.clips()[database.frame_clip()[frame]];
  if (frame + 1 < clip.first_frame + clip.frame_count) return {frame, frame + 1};
  if (frame > clip.first_frame) return {frame - 1, frame};
  return {frame, frame};
}

}  // namespace

// Steps are small (under 0.2 rad at 30 fps for human motion), where 2 v / w
// (the tangent of the half angle) is within 0.4% of the angle and needs no
// atan; larger steps take the exact map.
glm::vec3 frame_rotation_vector(const glm::quat& q_in) {
  const glm::quat q = q_in.w < 0.0f ? -q_in : q_in;
  const float s2 = q.x * q.x + q.y * q.y + q.z * q.z;
  if (s2 < 0.01f) return glm::vec3(q.x, q.y, q.z) * (2.0f / q.w);
  return quat_to_rotation_vector(q);
}

void pose_velocity(const Database& database, const AnimationData& animation, std::uint32_t frame,
                   std::span<glm::vec3> angular, std::span<glm::vec3> velocities) {
  const auto [a, b] = difference_frames(database, frame);
  const std::size_t joints = animation.joint_count();
  const float fps = database.fps();
  const glm::quat* qa = animation.local_rotations.data() + std::size_t{a} * joints;
  const glm::quat* qb = animation.local_rotations.data() + std::size_t{b} * joints;
  for (std::size_t j = 0; j < joints; ++j) {
    angular[j] = a == b ? glm::vec3(0.0f) : frame_rotation_vector(qb[j] * glm::inverse(qa[j])) * fps;
    velocities[j] = glm::vec3(0.0f);
  }
  const std::size_t count = animation.translated_joints.size();
  if (a == b) return;
  for (std::size_t t = 0; t < count; ++t) {
    velocities[animation.translated_joints[t]] =
        (animation.local_translations[std::size_t{b} * count + t] - animation.local_translations[std::size_t{a} * count + t]) *
        fps;
  }
}

void scale_pose_velocity(float rate, std::span<glm::vec3> angular, std::span<glm::vec3> velocities) {
  if (rate == 1.0f) return;
  for (glm::vec3& w : angular) w *= rate;
  for (glm::vec3& v : velocities) v *= rate;
}

}  // namespace mmvk::detail
