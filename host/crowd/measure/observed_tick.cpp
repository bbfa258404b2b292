#include "measure/observed_tick.hpp"

namespace mmvk::crowd {

Result<double> observed_tick(CrowdController& controller, AsyncSearch& search, ThreadPool& pool, std::uint64_t tick,
                             float dt, const CrowdInput& input, std::chrono::steady_clock::time_point tick_start,
                             const TickObservers& observers) {
  MMVK_TRY(controller.tick(dt, input, search, pool));
  const double tick_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tick_start).count();
  const TickStats& stats = controller.last_tick();
  observers.figures.record(tick, tick_ms, stats.search_seconds * 1e3, controller.applied_matches(), stats.searches);
  const TickView view{tick, input.desired_velocity, input.desired_yaw, controller.world_positions()};
  observers.quality.observe(controller, view);
  if (observers.recording) observers.recording->observe(controller, view);
  return tick_ms;
}

}  // namespace mmvk::crowd
