#include "observed_tick.hpp"

namespace mmvk::crowd {

Result<double> observed_tick(CrowdController& controller, ObservedSearch& observed, ThreadPool& pool,
                             std::uint64_t tick, float dt, const CrowdInput& input,
                             std::chrono::steady_clock::time_point tick_start, std::span<glm::vec3> world,
                             const TickObservers& observers) {
  observed.begin_tick();
  MMVK_TRY(controller.tick(dt, input, observed, pool));
  const double tick_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tick_start).count();
  const auto matches = observed.collected_matches();
  observers.figures.record(tick, tick_ms, observed.blocked_seconds() * 1e3, matches, controller.last_tick().searches);

  controller.world_positions(world, pool);
  const TickView view{tick, input.desired_velocity, input.desired_yaw, matches, world, observed.submitted_batch()};
  observers.quality.observe(controller, view);
  if (observers.recording) observers.recording->observe(controller, view);
  return tick_ms;
}

}  // namespace mmvk::crowd
