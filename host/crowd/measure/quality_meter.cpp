#include "measure/quality_meter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mmvk::crowd {

QualityMeter::QualityMeter(std::size_t agents, double dt, double horizon_s)
    : agents_(agents),
      dt_(dt),
      horizon_ticks_(std::max<std::size_t>(1, std::size_t(std::lround(horizon_s / dt)))),
      desired_ring_(horizon_ticks_ * agents * 2, std::numeric_limits<float>::quiet_NaN()),
      // 1 mm bins up to 20 m; anything further lands in the last bin.
      error_(0.001, 20000) {}

void QualityMeter::record_trajectory(std::span<const float> desired_1s_xz, std::span<const float> root_xz) {
  float* slot = desired_ring_.data() + (ticks_ % horizon_ticks_) * agents_ * 2;
  if (ticks_ >= horizon_ticks_) {
    // The slot still holds what was desired horizon_ticks ago for now.
    for (std::size_t a = 0; a < agents_; ++a) {
      if (std::isnan(slot[2 * a])) continue;
      const double dx = double(root_xz[2 * a]) - slot[2 * a];
      const double dz = double(root_xz[2 * a + 1]) - slot[2 * a + 1];
      error_.add(std::sqrt(dx * dx + dz * dz));
    }
  }
  std::copy(desired_1s_xz.begin(), desired_1s_xz.begin() + std::ptrdiff_t(agents_ * 2), slot);
}

double QualityMeter::trajectory_error_m_median() const { return error_.quantile(0.5); }

double QualityMeter::transitions_per_agent_s() const {
  const double seconds = double(ticks_) * dt_;
  return agents_ == 0 || seconds <= 0.0 ? 0.0 : double(transitions_) / (double(agents_) * seconds);
}

double percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(samples.begin(), samples.end());
  const auto rank = std::size_t(std::ceil(p * double(samples.size())));
  return samples[std::min(samples.size() - 1, rank == 0 ? 0 : rank - 1)];
}

}  // namespace mmvk::crowd
