#include "steering/steering.hpp"

#include <algorithm>
#include <cmath>

namespace mmvk::crowd {

Steering::Steering(const Scenario& scenario, const GaitSpeeds& speeds, const SteeringParams& params)
    : params_(params) {
  const std::size_t n = scenario.agents.size();
  speed_.resize(n);
  goal_begin_.resize(n + 1, 0);
  goal_index_.assign(n, 0);
  for (std::size_t a = 0; a < n; ++a) {
    const AgentPlan& plan = scenario.agents[a];
    float speed = plan.speed.value;
    if (plan.speed.gait == Gait::Walk) speed *= speeds.walk_mps;
    if (plan.speed.gait == Gait::Run) speed *= speeds.run_mps;
    speed_[a] = std::min(speed, speeds.max_mps);
    goal_begin_[a + 1] = goal_begin_[a] + std::uint32_t(plan.goals.size());
    goals_.insert(goals_.end(), plan.goals.begin(), plan.goals.end());
  }
}

std::array<float, 2> Steering::goal(std::size_t agent) const { return goals_[goal_begin_[agent] + goal_index_[agent]]; }

namespace {

// Characters below this count are steered on the calling thread: waking the
// pool costs more than the work.
constexpr std::size_t kParallelMin = 128;

}  // namespace

void Steering::update(std::span<const glm::vec3> positions, std::span<glm::vec3> desired_velocity, ThreadPool* pool) {
  const std::size_t n = speed_.size();
  grid_.build(positions.first(n), params_.separation_radius_m);
  if (pool == nullptr || pool->thread_count() == 1 || n < kParallelMin) {
    steer(0, n, positions, desired_velocity, goals_reached_);
    return;
  }
  // Sized on the first update with this pool: no allocation per tick after it.
  if (reached_by_thread_.size() < pool->thread_count()) reached_by_thread_.resize(pool->thread_count());
  std::fill(reached_by_thread_.begin(), reached_by_thread_.end(), std::uint64_t{0});
  pool->parallel_for(n, [this, positions, desired_velocity](std::size_t begin, std::size_t end, unsigned thread) {
    steer(begin, end, positions, desired_velocity, reached_by_thread_[thread]);
  });
  for (const std::uint64_t reached : reached_by_thread_) goals_reached_ += reached;
}

void Steering::steer(std::size_t begin, std::size_t end, std::span<const glm::vec3> positions,
                     std::span<glm::vec3> desired_velocity, std::uint64_t& reached) {
  const float radius = params_.separation_radius_m;
  const auto x = [positions](std::size_t a) { return positions[a].x; };
  const auto z = [positions](std::size_t a) { return positions[a].z; };
  for (std::size_t a = begin; a < end; ++a) {
    std::array<float, 2> target = goal(a);
    float gx = target[0] - x(a), gz = target[1] - z(a);
    float distance = std::sqrt(gx * gx + gz * gz);
    if (distance < params_.goal_radius_m) {
      const std::uint32_t count = goal_begin_[a + 1] - goal_begin_[a];
      goal_index_[a] = (goal_index_[a] + 1) % count;
      ++reached;
      target = goal(a);
      gx = target[0] - x(a), gz = target[1] - z(a);
      distance = std::sqrt(gx * gx + gz * gz);
    }
    const float speed = speed_[a];
    float vx = 0.0f, vz = 0.0f;
    if (distance > 1e-4f) vx = gx / distance * speed, vz = gz / distance * speed;

    float sx = 0.0f, sz = 0.0f;
    grid_.for_each_near(x(a), z(a), [&](std::uint32_t j) {
      if (j == a) return;
      const float dx = x(a) - x(j), dz = z(a) - z(j);
      const float d2 = dx * dx + dz * dz;
      if (d2 >= radius * radius) return;
      const float d = std::sqrt(d2);
      // Two characters on the same spot push apart along a direction fixed
      // by their ids, so the result does not depend on evaluation order.
      const float ux = d > 1e-5f ? dx / d : (a < j ? 1.0f : -1.0f);
      const float uz = d > 1e-5f ? dz / d : 0.0f;
      const float push = 1.0f - d / radius;
      sx += ux * push, sz += uz * push;
    });
    vx += sx * params_.separation_gain * speed;
    vz += sz * params_.separation_gain * speed;
    // Never faster than the preferred speed: separation turns and slows a
    // character, it does not make it sprint.
    const float len = std::sqrt(vx * vx + vz * vz);
    if (len > speed && len > 0.0f) vx *= speed / len, vz *= speed / len;
    desired_velocity[a] = glm::vec3(vx, 0.0f, vz);
  }
}

}  // namespace mmvk::crowd
