#include "measure/histogram.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mmvk::crowd {

Histogram::Histogram(double bin_width, std::size_t bins) : width_(bin_width), bins_(std::max<std::size_t>(1, bins), 0) {}

void Histogram::add(double value) {
  const double position = value / width_;
  std::size_t bin = bins_.size() - 1;
  if (!(position >= 0.0)) {
    bin = std::isnan(position) ? bins_.size() - 1 : 0;
  } else if (position < double(bins_.size() - 1)) {
    bin = std::size_t(position);
  }
  ++bins_[bin];
  ++count_;
  if (std::isfinite(value)) sum_ += value;
}

double Histogram::mean() const {
  return count_ ? sum_ / double(count_) : std::numeric_limits<double>::quiet_NaN();
}

double Histogram::quantile(double p) const {
  if (count_ == 0) return std::numeric_limits<double>::quiet_NaN();
  const auto rank = std::max<std::uint64_t>(1, std::uint64_t(std::ceil(std::clamp(p, 0.0, 1.0) * double(count_))));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen >= rank) return (double(b) + 0.5) * width_;
  }
  return (double(bins_.size()) - 0.5) * width_;
}

}  // namespace mmvk::crowd
