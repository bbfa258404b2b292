// The simulated root and its prediction (trajectory.hpp).
#include "mmvk/animation/trajectory.hpp"

#include <cassert>
#include <cmath>

#include "mmvk/animation/spring.hpp"

namespace mmvk {

namespace {

glm::vec3 horizontal(const glm::vec3& v) { return {v.x, 0.0f, v.z}; }

}  // namespace

void simulate_step(SimulationState& state, const glm::vec3& desired_velocity, float desired_yaw,
                   const SpringParams& params, float dt) {
  spring_velocity_step(state.position, state.velocity, state.acceleration, horizontal(desired_velocity),
                       params.velocity_half_life, dt);
  spring_angle_step(state.yaw, state.yaw_rate, desired_yaw, params.yaw_half_life, dt);
  state.yaw = wrap_angle(state.yaw);
}

void predict_trajectory(const SimulationState& state, const glm::vec3& desired_velocity, float desired_yaw,
                        const SpringParams& params, std::span<const float> offsets_seconds,
                        std::span<glm::vec3> out_positions, std::span<float> out_yaws) {
  assert(out_positions.size() >= offsets_seconds.size() && out_yaws.size() >= offsets_seconds.size());
  // The closed forms are exact for any step, so each offset is reached from
  // the current state in one step (no accumulation of rounding over steps).
  const glm::vec3 goal = horizontal(desired_velocity);
  for (std::size_t i = 0; i < offsets_seconds.size(); ++i) {
    SimulationState s = state;
    spring_velocity_step(s.position, s.velocity, s.acceleration, goal, params.velocity_half_life, offsets_seconds[i]);
    spring_angle_step(s.yaw, s.yaw_rate, desired_yaw, params.yaw_half_life, offsets_seconds[i]);
    out_positions[i] = s.position;
    out_yaws[i] = wrap_angle(s.yaw);
  }
}

float yaw_of_velocity(const glm::vec3& velocity, float fallback, float min_speed) {
  const float speed2 = velocity.x * velocity.x + velocity.z * velocity.z;
  if (speed2 < min_speed * min_speed) return fallback;
  return std::atan2(velocity.x, velocity.z);
}

}  // namespace mmvk
