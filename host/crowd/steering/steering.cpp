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
  wait_s_.resize(n);
  wait_left_s_.assign(n, 0.0);
  for (std::size_t a = 0; a < n; ++a) {
    const AgentPlan& plan = scenario.agents[a];
    float speed = plan.speed.value;
    if (plan.speed.gait == Gait::Walk) speed *= speeds.walk_mps;
    if (plan.speed.gait == Gait::Run) speed *= speeds.run_mps;
    speed_[a] = std::min(speed, speeds.max_mps);
    wait_s_[a] = plan.wait_s;
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

void Steering::update(std::span<const glm::vec3> positions, std::span<glm::vec3> desired_velocity, float dt_s,
                      ThreadPool* pool) {
  const std::size_t n = speed_.size();
  ++updates_;
  grid_.build(positions.first(n), params_.separation_radius_m);
  if (pool == nullptr || pool->thread_count() == 1 || n < kParallelMin) {
    steer(0, n, positions, desired_velocity, dt_s, goals_reached_);
    return;
  }
  // Sized on the first update with this pool: no allocation per tick after it.
  if (reached_by_thread_.size() < pool->thread_count()) reached_by_thread_.resize(pool->thread_count());
  std::fill(reached_by_thread_.begin(), reached_by_thread_.end(), std::uint64_t{0});
  pool->parallel_for(n, [this, positions, desired_velocity, dt_s](std::size_t begin, std::size_t end, unsigned thread) {
    steer(begin, end, positions, desired_velocity, dt_s, reached_by_thread_[thread]);
  });
  for (const std::uint64_t reached : reached_by_thread_) goals_reached_ += reached;
}

void Steering::advance_goal(std::size_t a) {
  const std::uint32_t count = goal_begin_[a + 1] - goal_begin_[a];
  goal_index_[a] = (goal_index_[a] + 1) % count;
}

void Steering::hold(std::size_t a, float dt_s) {
  wait_left_s_[a] -= double(dt_s);
  // Ends on the tick nearest the wait: a 1 s wait at 30 Hz is 30 ticks,
  // not 31 for a rounding error; a wait under half a tick is still one.
  if (wait_left_s_[a] < 0.5 * double(dt_s)) {
    wait_left_s_[a] = 0.0;
    advance_goal(a);
  }
}

std::array<float, 2> Steering::separation(std::size_t a, std::span<const glm::vec3> positions) const {
  const float radius = params_.separation_radius_m;
  const float x = positions[a].x, z = positions[a].z;
  float sx = 0.0f, sz = 0.0f;
  grid_.for_each_near(x, z, [&](std::uint32_t j) {
    if (j == a) return;
    const float dx = x - positions[j].x, dz = z - positions[j].z;
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
  return {sx, sz};
}

void Steering::steer(std::size_t begin, std::size_t end, std::span<const glm::vec3> positions,
                     std::span<glm::vec3> desired_velocity, float dt_s, std::uint64_t& reached) {
  for (std::size_t a = begin; a < end; ++a) {
    // A waiting character stands, unmoved by its neighbours: a push would
    // make it walk in place, and they keep clear of it by their own
    // separation.
    if (wait_left_s_[a] > 0.0) {
      hold(a, dt_s);
      desired_velocity[a] = glm::vec3(0.0f);
      continue;
    }
    std::array<float, 2> target = goal(a);
    float gx = target[0] - positions[a].x, gz = target[1] - positions[a].z;
    float distance = std::sqrt(gx * gx + gz * gz);
    if (distance < params_.goal_radius_m) {
      ++reached;
      if (wait_s_[a] > 0.0f) {
        // The arrival's tick is the wait's first.
        wait_left_s_[a] = double(wait_s_[a]);
        hold(a, dt_s);
        desired_velocity[a] = glm::vec3(0.0f);
        continue;
      }
      advance_goal(a);
      target = goal(a);
      gx = target[0] - positions[a].x, gz = target[1] - positions[a].z;
      distance = std::sqrt(gx * gx + gz * gz);
    }
    const float speed = speed_[a];
    float vx = 0.0f, vz = 0.0f;
    if (distance > 1e-4f) vx = gx / distance * speed, vz = gz / distance * speed;
    const std::array<float, 2> push = separation(a, positions);
    vx += push[0] * params_.separation_gain * speed;
    vz += push[1] * params_.separation_gain * speed;
    // Never faster than the preferred speed: separation turns and slows a
    // character, it does not make it sprint.
    const float len = std::sqrt(vx * vx + vz * vz);
    if (len > speed && len > 0.0f) vx *= speed / len, vz *= speed / len;
    desired_velocity[a] = glm::vec3(vx, 0.0f, vz);
  }
}

}  // namespace mmvk::crowd
