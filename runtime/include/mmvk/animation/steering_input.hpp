// Steering input for a host that moves its agents itself. A crowd simulator
// (social forces, ORCA, a navmesh agent) hands the CrowdController each
// character's desired velocity and, optionally, facing (CrowdInput). One
// that produces positions instead turns them into velocities here.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/common/status.hpp"
#include "mmvk/animation/trajectory.hpp"

namespace mmvk {

// Desired velocities from a host's positions, per tick: where the host has
// each character at the end of the tick (`next`). The velocity is the
// host's own motion (next minus the previous tick's next, over dt: none on
// the first tick or after reset) plus a correction that closes the gap
// between the simulated root and `next` over `horizon` seconds. The
// correction alone, re-aimed every tick at a one-tick horizon, would fight
// the springs' lag and oscillate; a horizon equal to the springs' half-life
// (0.2 s, ControllerParams::spring) follows lines and circles closest
// (bench/RESULTS.md, "Defaults and the measurements that chose them";
// tests/python/test_crowd.py).
class PositionSteering {
 public:
  // `characters` [B]; horizon in seconds, > 0 (else the default).
  explicit PositionSteering(std::size_t characters, float horizon = 0.2f);

  // out[b]: world m/s, y = 0. `simulation` is CrowdController::simulation()
  // before the tick; `next` [B] metres (y ignored); dt the tick's seconds.
  // Errors: sizes, dt not > 0, a non-finite position (naming the character).
  Status velocities(std::span<const SimulationState> simulation, std::span<const glm::vec3> next, float dt,
                    std::span<glm::vec3> out);
  // Forget the previous positions (after teleporting characters: place()).
  void reset();

  float horizon() const { return horizon_; }

 private:
  float horizon_;
  std::vector<glm::vec3> previous_;  // [B] last tick's next
  bool has_previous_ = false;
};

}  // namespace mmvk
