// One tick of the crowd with its observers after it: the part of the loop
// that `mmvk crowd` (crowd_run.cpp) and the stepped crowd (crowd_session.cpp)
// share. Each steers its own way before it.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/search/async_search.hpp"
#include "measure/tick_observers.hpp"

namespace mmvk::crowd {

struct TickObservers {
  TickFigures& figures;
  QualityObserver& quality;
  RecordingObserver* recording;  // none: not recording
};

// Ticks `controller` by `dt` with `input` on the deferred search, records the
// tick's figures (its time counted from `tick_start`, which a caller may take
// before its own steering) and shows the tick to the observers. Returns the
// tick's milliseconds.
Result<double> observed_tick(CrowdController& controller, AsyncSearch& search, ThreadPool& pool, std::uint64_t tick,
                             float dt, const CrowdInput& input, std::chrono::steady_clock::time_point tick_start,
                             const TickObservers& observers);

}  // namespace mmvk::crowd
