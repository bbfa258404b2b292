// A fixed-bin histogram of non-negative values: quantiles and the exact mean
// with memory independent of how many values are added, so the crowd's
// figures stay bounded over runs of any length.
#pragma once

#include <cstdint>
#include <vector>

namespace mmvk::crowd {

class Histogram {
 public:
  // Bins [i * bin_width, (i + 1) * bin_width) for i < bins; the last bin also
  // takes everything above (and NaN); a negative value lands in the first.
  Histogram(double bin_width, std::size_t bins);

  void add(double value);
  std::uint64_t count() const { return count_; }
  double mean() const;                // of the values as added; NaN when empty
  // The nearest-rank p-quantile (p in [0, 1]), as its bin's centre: exact to
  // half a bin below the last bin. NaN when empty.
  double quantile(double p) const;
  double bin_width() const { return width_; }

 private:
  double width_;
  std::vector<std::uint64_t> bins_;
  std::uint64_t count_ = 0;
  double sum_ = 0.0;
};

}  // namespace mmvk::crowd
