// The motion quality figures of a crowd run, accumulated tick by tick with
// memory independent of the run's length (histograms and sums):
//   - trajectory error: at each tick the controller's desired position 1 s
//     ahead is remembered; 1 s later the character's achieved root position
//     is compared with it. Reported as the median distance, metres.
//   - foot sliding: the mean horizontal speed of a foot over the ticks where
//     it is in contact (the database's contact flag) at both ends, cm/s.
//   - transitions: jumps to another frame per character per second.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace mmvk::crowd {

class QualityMeter {
 public:
  // `agents` characters with `feet` feet each, ticks of `dt` seconds; the
  // 1 s horizon is rounded to whole ticks.
  QualityMeter(std::size_t agents, std::size_t feet, double dt);

  // Call once per tick, in this order, after the tick's poses are final.
  // desired_1s_xz: [agents x 2] desired root (x, z) 1 s from now, metres.
  // root_xz: [agents x 2] achieved root (x, z) now, metres.
  void record_trajectory(std::span<const float> desired_1s_xz, std::span<const float> root_xz);
  // foot_xz: [agents x feet x 2] world foot positions (x, z), metres;
  // contact: [agents x feet], nonzero = in contact with the ground.
  void record_feet(std::span<const float> foot_xz, std::span<const std::uint8_t> contact);
  void add_transitions(std::uint64_t count) { transitions_ += count; }
  void end_tick() { ++ticks_; }

  double trajectory_error_m_median() const;  // NaN until 1 s has passed
  double foot_sliding_cm_s() const;          // NaN without any contact
  double transitions_per_agent_s() const;
  std::uint64_t trajectory_samples() const { return error_samples_; }

 private:
  std::size_t agents_, feet_;
  double dt_;
  std::size_t horizon_ticks_;
  std::uint64_t ticks_ = 0;
  std::vector<float> desired_ring_;            // [horizon_ticks x agents x 2]
  std::vector<std::uint64_t> error_histogram_; // 1 mm bins, the last one open-ended
  std::uint64_t error_samples_ = 0;
  std::vector<float> last_foot_xz_;
  std::vector<std::uint8_t> last_contact_;
  bool have_last_feet_ = false;
  double sliding_sum_mps_ = 0.0;
  std::uint64_t sliding_samples_ = 0;
  std::uint64_t transitions_ = 0;
};

// p in [0, 1] of samples (sorted copy; nearest rank). NaN when empty.
double percentile(std::vector<double> samples, double p);

}  // namespace mmvk::crowd
