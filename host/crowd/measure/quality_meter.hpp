// The motion quality figures of a crowd run, accumulated tick by tick with
// memory independent of the run's length (histograms and sums):
//   - trajectory error: at each tick the controller's desired position 1 s
//     ahead (of the characters it has one for) is remembered; 1 s later the
//     character's achieved root position is compared with it. Reported as
//     the median distance, metres.
//   - transitions: jumps to another frame per character per second.
// The feet, knees and pose are measured by MotionMeter (motion_meter.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "measure/histogram.hpp"

namespace mmvk::crowd {

class QualityMeter {
 public:
  // `agents` characters, ticks of `dt` seconds; the horizon (seconds, 1 s
  // unless given) is rounded to whole ticks.
  QualityMeter(std::size_t agents, double dt, double horizon_s = 1.0);

  // Call once per tick, in this order, after the tick's poses are final.
  // desired_1s_xz: [agents x 2] desired root (x, z) a horizon from now,
  // metres; NaN for a character without a prediction this tick (it is not
  // measured a horizon later).
  // root_xz: [agents x 2] achieved root (x, z) now, metres.
  void record_trajectory(std::span<const float> desired_1s_xz, std::span<const float> root_xz);
  void add_transitions(std::uint64_t count) { transitions_ += count; }
  void end_tick() { ++ticks_; }

  double trajectory_error_m_median() const;  // NaN until 1 s has passed
  double transitions_per_agent_s() const;
  std::uint64_t trajectory_samples() const { return error_.count(); }

 private:
  std::size_t agents_;
  double dt_;
  std::size_t horizon_ticks_;
  std::uint64_t ticks_ = 0;
  std::vector<float> desired_ring_;            // [horizon_ticks x agents x 2]
  Histogram error_;                            // metres
  std::uint64_t transitions_ = 0;
};

// p in [0, 1] of samples (sorted copy; nearest rank). NaN when empty.
double percentile(std::vector<double> samples, double p);

}  // namespace mmvk::crowd
