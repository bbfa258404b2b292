// What watches a crowd run tick by tick without steering it: the quality
// meters (trajectory error, transitions, feet, knees and pose) and the
// viewer's recording. run_crowd (crowd_run.cpp) calls each after every
// tick with the same TickView; every buffer is sized at construction, so
// observing a tick allocates nothing (the recording's own samples aside).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "clip_quality.hpp"
#include "crowd_recorder.hpp"
#include "mmvk/crowd_controller.hpp"
#include "motion_meter.hpp"
#include "quality_meter.hpp"
#include "summary.hpp"

namespace mmvk::crowd {

// One finished tick, as every observer sees it.
struct TickView {
  std::uint64_t tick = 0;                 // 0-based; it ended at (tick + 1) * dt
  std::span<const glm::vec3> desired;     // [agents] the steering's desired velocity, m/s
  std::span<const Match> matches;         // the matches the tick applied, in order
  std::span<const glm::vec3> world;       // [agents x joints] displayed world joint positions, metres
};

// Trajectory error at 1 s, transitions, and the motion as displayed against
// the motion as animated (motion_meter.hpp).
class QualityObserver {
 public:
  // `clips`: the database's own figures; their planted toe height is the
  // crowd's floor. `params`: the controller's (spring, inertialization).
  QualityObserver(const CrowdController& controller, const ControllerParams& params, const ClipQuality& clips,
                  float dt, std::uint32_t acceleration_step);

  void observe(const CrowdController& controller, const TickView& view, ThreadPool& pool);
  // The trajectory, transition and motion figures into `summary`.
  void summarize(CrowdSummary& summary) const;

 private:
  const ControllerParams& params_;
  QualityMeter meter_;
  MotionMeter motion_;
  // Per tick, sized once: [agents x 2] and [agents x joints].
  std::vector<float> desired_xz_, root_xz_;
  std::vector<glm::vec3> animated_;
};

// The viewer's recording (crowd_recorder.hpp), fed what each tick searched.
class RecordingObserver {
 public:
  RecordingObserver(const CrowdController& controller, const Scenario& scenario, std::string title, float dt,
                    std::uint32_t ticks_per_sample);

  void observe(const CrowdController& controller, const TickView& view);
  Recording finish(ThreadPool& pool) { return recorder_.finish(pool); }

 private:
  CrowdRecorder recorder_;
  // The characters that searched in the tick before (ascending), that tick's
  // CrowdController::searched() and the frames they played then.
  std::vector<std::uint32_t> searched_before_, searched_now_, frames_before_;
  std::vector<std::uint8_t> kinds_before_;
};

}  // namespace mmvk::crowd
