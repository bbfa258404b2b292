// What queries read of a character's animated pose, measured from its world
// joint positions (the controller's one forward kinematics per tick).
#pragma once

#include <span>

#include <glm/vec3.hpp>

namespace mmvk::detail {

// Velocities (character space, m/s) of `joints` by backward differences of
// their world positions: what the viewer sees, root motion and corrections
// included. world [joints of the skeleton], last_world and velocities
// [joints.size()]; last_world is updated to the positions now. `fresh` (no
// previous positions) or dt <= 0: zero velocities.
void measure_joint_velocities(std::span<const glm::vec3> world, std::span<const int> joints, float root_yaw, float dt,
                              bool fresh, std::span<glm::vec3> last_world, std::span<glm::vec3> velocities);

// World joint positions into character space: R_y(-yaw) * (world - root).
void to_character_space(std::span<const glm::vec3> world, const glm::vec3& root, float root_yaw,
                        std::span<glm::vec3> out);

}  // namespace mmvk::detail
