// Steering: each character seeks its current goal and keeps apart from its
// neighbours (found on a uniform grid), giving a desired velocity per
// character for the animation controller. A character that reaches a goal
// with a wait (AgentPlan::wait_s) stands there: its desired velocity is 0
// for the wait, rounded to whole ticks (at least one), and it then heads for
// the next goal; the controller's springs bring it to rest and start it
// again. Data-oriented: arrays per field, one pass per stage, no allocation
// per tick after the first.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "steering/gait_speeds.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "steering/scenario.hpp"
#include "steering/spatial_grid.hpp"

namespace mmvk::crowd {

struct SteeringParams {
  float goal_radius_m = 1.0f;        // a goal counts as reached this close
  float separation_radius_m = 1.0f;  // neighbours closer than this push apart
  // Separation velocity at contact, as a share of the preferred speed; it
  // falls linearly to 0 at the separation radius.
  float separation_gain = 1.0f;
};

class Steering {
 public:
  // Resolves each plan's speed preference against the database's gaits
  // (capped to speeds.max_mps).
  Steering(const Scenario& scenario, const GaitSpeeds& speeds, const SteeringParams& params = {});

  std::size_t size() const { return speed_.size(); }
  float preferred_speed(std::size_t agent) const { return speed_[agent]; }
  std::span<const float> preferred_speeds() const { return speed_; }  // [N] m/s
  std::uint32_t goal_index(std::size_t agent) const { return goal_index_[agent]; }
  std::array<float, 2> goal(std::size_t agent) const;
  // Arrivals: a goal counts once when reached, at the start of its wait.
  std::uint64_t goals_reached() const { return goals_reached_; }
  // Whether the character stands at its goal (goal()), waiting to leave.
  bool waiting(std::size_t agent) const { return wait_left_s_[agent] > 0.0; }
  std::uint64_t updates() const { return updates_; }

  // One tick of dt_s seconds from the characters' current positions (world
  // metres, y ignored, [N]): advances the goals of those within
  // goal_radius_m (after their wait) and writes desired velocities (world
  // m/s, y = 0, [N]). With a pool, the characters are split over its threads
  // (each one's velocity depends only on the positions and its own wait, so
  // the result is the same bit for bit); the grid is built on the calling
  // thread.
  void update(std::span<const glm::vec3> positions, std::span<glm::vec3> desired_velocity, float dt_s,
              ThreadPool* pool = nullptr);

 private:
  SteeringParams params_;
  std::vector<float> speed_;                         // [N] preferred, m/s
  std::vector<std::uint32_t> goal_begin_;            // [N + 1] into goals_
  std::vector<std::uint32_t> goal_index_;            // [N] current goal within the agent's list
  std::vector<std::array<float, 2>> goals_;
  std::vector<float> wait_s_;                        // [N] the plan's wait at each goal, seconds
  // [N] left of the wait at goal(), seconds; 0: not waiting. Double: an
  // hour's wait counted down in float ticks of 1/30 s drifts by seconds.
  std::vector<double> wait_left_s_;
  std::uint64_t goals_reached_ = 0;
  std::uint64_t updates_ = 0;
  std::vector<std::uint64_t> reached_by_thread_;  // per pool thread, summed after each update
  SpatialGrid grid_;

  void steer(std::size_t begin, std::size_t end, std::span<const glm::vec3> positions,
             std::span<glm::vec3> desired_velocity, float dt_s, std::uint64_t& reached);
  // The agent's push from neighbours closer than separation_radius_m, each
  // falling linearly from 1 at contact to 0 at the radius (x, z).
  std::array<float, 2> separation(std::size_t agent, std::span<const glm::vec3> positions) const;
  void advance_goal(std::size_t agent);
  // One tick of the agent's wait; the goal advances when it runs out.
  void hold(std::size_t agent, float dt_s);
};

}  // namespace mmvk::crowd
