// Trajectory prediction: the "simulation bone" of a motion matching
// controller. A character's simulated root follows its desired velocity and
// facing through critically damped springs (spring.hpp); the same springs,
// run forward without changing the goal, predict where it will be at the
// schema's trajectory offsets. Positions are world space, metres, on the
// ground (y = 0); yaws are radians about +Y (0 faces +Z).
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

namespace mmvk {

struct SpringParams {
  float velocity_half_life = 0.2f;  // seconds for the velocity to cover half its gap to the desired one
  float yaw_half_life = 0.2f;       // seconds for the yaw to cover half its gap to the desired one
};

// One character's simulated root.
struct SimulationState {
  glm::vec3 position{0.0f};      // metres, y = 0
  glm::vec3 velocity{0.0f};      // m/s
  glm::vec3 acceleration{0.0f};  // m/s^2
  float yaw = 0.0f;              // radians
  float yaw_rate = 0.0f;         // rad/s
};

// Advances the state by dt toward `desired_velocity` (y ignored) and
// `desired_yaw`.
void simulate_step(SimulationState& state, const glm::vec3& desired_velocity, float desired_yaw,
                   const SpringParams& params, float dt);

// Future positions and yaws at `offsets_seconds` (> 0, ascending) from
// `state`, the goals held constant: out_positions[i], out_yaws[i] for
// offsets_seconds[i]. Spans sized like offsets_seconds. Allocates nothing.
void predict_trajectory(const SimulationState& state, const glm::vec3& desired_velocity, float desired_yaw,
                        const SpringParams& params, std::span<const float> offsets_seconds,
                        std::span<glm::vec3> out_positions, std::span<float> out_yaws);

// The yaw that faces `velocity` (x, z), or `fallback` when its horizontal
// speed is below `min_speed` m/s.
float yaw_of_velocity(const glm::vec3& velocity, float fallback, float min_speed = 1e-3f);

}  // namespace mmvk
