// The velocities of a stored frame's pose: what a jump blends from and to
// (the controller's inertialization source and destination).
#pragma once

#include <cstdint>
#include <span>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/database/database.hpp"

namespace mmvk::detail {

// The rotation vector (radians) of one frame's rotation step q.
glm::vec3 frame_rotation_vector(const glm::quat& q);

// Local angular velocities (rad/s) and joint velocities (m/s) of the stored
// animation at `frame`, [joints] each, by a finite difference inside its clip
// (forward, backward on its last frame; zero for a one-frame clip); only
// translated joints get a velocity.
void pose_velocity(const Database& database, const AnimationData& animation, std::uint32_t frame,
                   std::span<glm::vec3> angular, std::span<glm::vec3> velocities);

// The same velocities for the frame played at `rate` clip seconds per second.
void scale_pose_velocity(float rate, std::span<glm::vec3> angular, std::span<glm::vec3> velocities);

}  // namespace mmvk::detail
