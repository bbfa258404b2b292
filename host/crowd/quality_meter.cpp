#include "quality_meter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mmvk::crowd {

namespace {
constexpr double kBinMetres = 0.001;
constexpr std::size_t kBins = 20000;  // 20 m; anything further lands in the last bin
}  // namespace

QualityMeter::QualityMeter(std::size_t agents, std::size_t feet, double dt)
    : agents_(agents),
      feet_(feet),
      dt_(dt),
      horizon_ticks_(std::max<std::size_t>(1, std::size_t(std::lround(1.0 / dt)))),
      desired_ring_(horizon_ticks_ * agents * 2, 0.0f),
      error_histogram_(kBins, 0),
      last_foot_xz_(agents * feet * 2, 0.0f),
      last_contact_(agents * feet, 0) {}

void QualityMeter::record_trajectory(std::span<const float> desired_1s_xz, std::span<const float> root_xz) {
  float* slot = desired_ring_.data() + (ticks_ % horizon_ticks_) * agents_ * 2;
  if (ticks_ >= horizon_ticks_) {
    // The slot still holds what was desired horizon_ticks ago for now.
    for (std::size_t a = 0; a < agents_; ++a) {
      const double dx = double(root_xz[2 * a]) - slot[2 * a];
      const double dz = double(root_xz[2 * a + 1]) - slot[2 * a + 1];
      const auto bin = std::size_t(std::sqrt(dx * dx + dz * dz) / kBinMetres);
      ++error_histogram_[std::min(bin, kBins - 1)];
      ++error_samples_;
    }
  }
  std::copy(desired_1s_xz.begin(), desired_1s_xz.begin() + std::ptrdiff_t(agents_ * 2), slot);
}

void QualityMeter::record_feet(std::span<const float> foot_xz, std::span<const std::uint8_t> contact) {
  const std::size_t count = agents_ * feet_;
  if (have_last_feet_) {
    for (std::size_t i = 0; i < count; ++i) {
      if (!contact[i] || !last_contact_[i]) continue;
      const double dx = double(foot_xz[2 * i]) - last_foot_xz_[2 * i];
      const double dz = double(foot_xz[2 * i + 1]) - last_foot_xz_[2 * i + 1];
      sliding_sum_mps_ += std::sqrt(dx * dx + dz * dz) / dt_;
      ++sliding_samples_;
    }
  }
  std::copy(foot_xz.begin(), foot_xz.begin() + std::ptrdiff_t(count * 2), last_foot_xz_.begin());
  std::copy(contact.begin(), contact.begin() + std::ptrdiff_t(count), last_contact_.begin());
  have_last_feet_ = true;
}

double QualityMeter::trajectory_error_m_median() const {
  if (error_samples_ == 0) return std::numeric_limits<double>::quiet_NaN();
  const std::uint64_t half = (error_samples_ + 1) / 2;
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < kBins; ++b) {
    seen += error_histogram_[b];
    if (seen >= half) return (double(b) + 0.5) * kBinMetres;
  }
  return double(kBins) * kBinMetres;
}

double QualityMeter::foot_sliding_cm_s() const {
  if (sliding_samples_ == 0) return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * sliding_sum_mps_ / double(sliding_samples_);
}

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
