// Turns about +Y, the one axis a character's root turns about: the home of
// the yaw maths that playback, poses, the controller and the foot locker
// share. Inline: they run per joint per character per tick.
#pragma once

#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace mmvk::detail {

// R_y(yaw) with its sine and cosine taken once, for the many vectors of one
// character.
struct YawTurn {
  float c = 1.0f;
  float s = 0.0f;
  explicit YawTurn(float yaw) : c(std::cos(yaw)), s(std::sin(yaw)) {}
  // Character space to world: R_y(yaw) * v.
  glm::vec3 apply(const glm::vec3& v) const { return {v.x * c + v.z * s, v.y, -v.x * s + v.z * c}; }
  // World to character space: R_y(-yaw) * v.
  glm::vec3 undo(const glm::vec3& v) const { return {v.x * c - v.z * s, v.y, v.x * s + v.z * c}; }
};

// R_y(yaw) * v.
inline glm::vec3 yaw_rotate(const glm::vec3& v, float yaw) { return YawTurn(yaw).apply(v); }

// R_y(yaw) as a quaternion.
inline glm::quat yaw_rotation(float yaw) { return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)); }

}  // namespace mmvk::detail
