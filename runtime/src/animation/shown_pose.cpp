// Measurements of the animated pose for queries (shown_pose.hpp).
#include "shown_pose.hpp"

#include <cstddef>

#include "yaw.hpp"

namespace mmvk::detail {

void measure_joint_velocities(std::span<const glm::vec3> world, std::span<const int> joints, float root_yaw, float dt,
                              bool fresh, std::span<glm::vec3> last_world, std::span<glm::vec3> velocities) {
  const YawTurn turn(root_yaw);
  const bool differences = !fresh && dt > 0.0f;
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const glm::vec3 now = world[static_cast<std::size_t>(joints[k])];
    velocities[k] = differences ? turn.undo((now - last_world[k]) / dt) : glm::vec3(0.0f);
    last_world[k] = now;
  }
}

void to_character_space(std::span<const glm::vec3> world, const glm::vec3& root, float root_yaw,
                        std::span<glm::vec3> out) {
  const YawTurn turn(root_yaw);
  for (std::size_t j = 0; j < world.size(); ++j) out[j] = turn.undo(world[j] - root);
}

}  // namespace mmvk::detail
