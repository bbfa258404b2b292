// What watches a crowd run tick by tick without steering it: the ticks' own
// figures (searches, timings, the chosen frames), the quality meters
// (trajectory error, transitions, feet, knees and pose) and the viewer's
// recording. run_crowd (crowd_run.cpp) and CrowdSession (crowd_session.cpp)
// call each after every tick with the same TickView; every buffer is sized at
// construction, so observing a tick allocates nothing (the recording's own
// samples, and TickFigures past its reserve(), aside).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "measure/clip_quality.hpp"
#include "measure/command_meter.hpp"
#include "output/crowd_recorder.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/common/hash.hpp"
#include "measure/motion_meter.hpp"
#include "measure/quality_meter.hpp"
#include "measure/summary.hpp"

namespace mmvk::crowd {

// One finished tick, as every observer sees it.
struct TickView {
  std::uint64_t tick = 0;                 // 0-based; it ended at (tick + 1) * dt
  std::span<const glm::vec3> desired;     // [agents] the steering's desired velocity, m/s
  std::span<const float> desired_yaw;     // [agents] desired facing, radians; empty: facing the velocity
  std::span<const glm::vec3> world;       // [agents x joints] displayed world joint positions, metres
};

// The ticks' own figures: searches, the time each tick took and blocked on
// its search, and a hash of every applied match in order
// (CrowdController::applied_matches).
class TickFigures {
 public:
  void reserve(std::uint64_t ticks);
  // After tick `tick`: it took `tick_ms` (milliseconds), `search_ms` of them
  // blocked on the search, applied `matches` and searched for `searches`
  // characters.
  void record(std::uint64_t tick, double tick_ms, double search_ms, std::span<const Match> matches,
              std::uint64_t searches);
  double last_search_ms() const { return search_ms_.empty() ? 0.0 : search_ms_.back(); }
  // Into `summary` (its ticks and seconds set): the searches, their
  // percentiles, `wall_seconds` and the real-time factor, the frames' hash.
  void summarize(CrowdSummary& summary, double wall_seconds) const;

 private:
  std::vector<double> search_ms_, tick_ms_;
  std::uint64_t searches_ = 0;
  Hasher chosen_;
};

// Trajectory error at 1 s (the controller's own predictions, from each
// search: CrowdController::predicted_positions at its offset nearest 1 s),
// transitions, the motion as displayed against the motion as animated
// (motion_meter.hpp), and the glide and the errors against the command
// (command_meter.hpp).
class QualityObserver {
 public:
  // `clips`: the database's own figures; their planted toe height is the
  // crowd's floor. `params`: the controller's (spring, inertialization).
  // Ticks of `dt` seconds at `rate_hz` over a database of `fps`.
  QualityObserver(const CrowdController& controller, const ControllerParams& params, const ClipQuality& clips,
                  double dt, double rate_hz, double fps);

  // After each tick of the controller.
  void observe(const CrowdController& controller, const TickView& view);
  // The trajectory, transition and motion figures into `summary`.
  void summarize(CrowdSummary& summary) const;

 private:
  std::size_t horizon_index_;  // into the controller's trajectory offsets
  QualityMeter meter_;
  MotionMeter motion_;
  CommandMeter command_;
  // Per tick, sized once: [agents x 2].
  std::vector<float> desired_xz_, root_xz_;
  std::vector<glm::vec3> toes_;  // [agents x 2] the contact joints as displayed; empty without both
};

// The viewer's recording (crowd_recorder.hpp), fed what each tick searched.
class RecordingObserver {
 public:
  // `detail_agents`: the characters kept in detail (CrowdRecorder).
  RecordingObserver(const CrowdController& controller, const Scenario& scenario, std::string title, float dt,
                    std::uint32_t ticks_per_sample, std::vector<std::uint32_t> detail_agents);

  void observe(const CrowdController& controller, const TickView& view);
  Result<Recording> finish(ThreadPool& pool) { return recorder_.finish(pool); }

 private:
  CrowdRecorder recorder_;
  // The tick before's CrowdController::searched() and the frames played
  // then: what the matches applied now were searched with.
  std::vector<std::uint32_t> frames_before_;
  std::vector<SearchKind> kinds_before_;
};

}  // namespace mmvk::crowd
