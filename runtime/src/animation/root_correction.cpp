// Root correction (root_correction.hpp).
#include "root_correction.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "mmvk/animation/spring.hpp"

namespace mmvk::detail {

float correction_speed(const ControllerParams& params, float animated_speed) {
  return std::min(params.max_correction_speed,
                  std::max(params.min_correction_speed, params.correction_speed_ratio * animated_speed));
}

void correct_root(const ControllerParams& params, float dt, float fraction, float animated_speed,
                  const SimulationState& simulated, glm::vec3& position, float& yaw) {
  glm::vec3 gap = simulated.position - position;
  gap.y = 0.0f;
  // Only the gap beyond the dead zone is pulled in: a root within it of
  // its simulated one moves by its animation alone.
  const float gap_length = glm::length(gap);
  gap *= gap_length > params.correction_dead_zone ? 1.0f - params.correction_dead_zone / gap_length : 0.0f;
  glm::vec3 step = gap * fraction;
  const float step_length = glm::length(step);
  const float max_step = correction_speed(params, animated_speed) * dt;
  if (step_length > max_step) step *= max_step / step_length;
  position += step;
  gap = simulated.position - position;
  gap.y = 0.0f;
  const float distance = glm::length(gap);
  if (distance > params.max_correction_distance) position += gap * (1.0f - params.max_correction_distance / distance);
  float yaw_gap = wrap_angle(simulated.yaw - yaw);
  const float yaw_step =
      std::clamp(yaw_gap * fraction, -params.max_correction_yaw_rate * dt, params.max_correction_yaw_rate * dt);
  yaw = wrap_angle(yaw + yaw_step);
  yaw_gap = wrap_angle(simulated.yaw - yaw);
  if (std::abs(yaw_gap) > params.max_correction_yaw) {
    yaw = wrap_angle(simulated.yaw - std::copysign(params.max_correction_yaw, yaw_gap));
  }
}

}  // namespace mmvk::detail
