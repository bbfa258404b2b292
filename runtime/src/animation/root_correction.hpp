// The bounded pull of an animated root toward its simulated root
// (ControllerParams' correction fields, crowd_controller.hpp).
#pragma once

#include <glm/vec3.hpp>

#include "mmvk/animation/crowd_controller.hpp"

namespace mmvk::detail {

// Moves `position` (world, y = 0) and `yaw` toward `simulated` by the
// fraction `fraction` (1 - 2^(-dt / correction_half_life)) of the gap, at
// most correction_speed(params, animated_speed) * dt metres and
// max_correction_yaw_rate * dt radians, then clamps what is left of the gap
// to max_correction_distance and max_correction_yaw.
void correct_root(const ControllerParams& params, float dt, float fraction, float animated_speed,
                  const SimulationState& simulated, glm::vec3& position, float& yaw);

// The correction's speed limit for a root that the animation moves at
// `animated_speed` m/s: correction_speed_ratio times it, at least
// min_correction_speed, at most max_correction_speed.
float correction_speed(const ControllerParams& params, float animated_speed);

}  // namespace mmvk::detail
