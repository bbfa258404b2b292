#include "mmvk/animation/steering_input.hpp"

#include <cmath>
#include <string>

namespace mmvk {

PositionSteering::PositionSteering(std::size_t characters, float horizon)
    : horizon_(horizon > 0.0f && std::isfinite(horizon) ? horizon : 0.2f), previous_(characters) {}

void PositionSteering::reset() { has_previous_ = false; }

Status PositionSteering::velocities(std::span<const SimulationState> simulation, std::span<const glm::vec3> next,
                                    float dt, std::span<glm::vec3> out) {
  const std::size_t count = previous_.size();
  if (simulation.size() != count || next.size() != count || out.size() != count) {
    return make_error("position steering: " + std::to_string(next.size()) + " positions, " +
                      std::to_string(simulation.size()) + " simulated roots and " + std::to_string(out.size()) +
                      " outputs for " + std::to_string(count) + " characters");
  }
  if (!(dt > 0.0f) || !std::isfinite(dt)) return make_error("position steering: dt must be a positive number");
  for (std::size_t b = 0; b < count; ++b) {
    if (!std::isfinite(next[b].x) || !std::isfinite(next[b].z)) {
      return make_error("position steering: the position of character " + std::to_string(b) + " is not finite");
    }
  }
  for (std::size_t b = 0; b < count; ++b) {
    const glm::vec3 host = has_previous_ ? (next[b] - previous_[b]) / dt : glm::vec3(0.0f);
    const glm::vec3 gap = next[b] - simulation[b].position;
    out[b] = glm::vec3(host.x + gap.x / horizon_, 0.0f, host.z + gap.z / horizon_);
    previous_[b] = next[b];
  }
  has_previous_ = true;
  return {};
}

}  // namespace mmvk
