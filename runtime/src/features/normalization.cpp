#include "mmvk/normalization.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mmvk {

std::vector<DimStatistics> compute_statistics(std::span<const float> values, std::uint32_t dims) {
  std::vector<DimStatistics> stats(dims);
  if (dims == 0) return stats;
  const std::size_t frames = values.size() / dims;
  if (frames == 0) return stats;
  std::vector<double> sum(dims, 0.0);
  for (std::uint32_t d = 0; d < dims; ++d) stats[d].min = stats[d].max = values[d];
  for (std::size_t f = 0; f < frames; ++f) {
    const float* row = values.data() + f * dims;
    for (std::uint32_t d = 0; d < dims; ++d) {
      sum[d] += row[d];
      stats[d].min = std::min(stats[d].min, static_cast<double>(row[d]));
      stats[d].max = std::max(stats[d].max, static_cast<double>(row[d]));
    }
  }
  for (std::uint32_t d = 0; d < dims; ++d) stats[d].mean = sum[d] / static_cast<double>(frames);
  // Second pass around the mean: no catastrophic cancellation.
  std::vector<double> squares(dims, 0.0);
  std::vector<double> absolutes(dims, 0.0);
  for (std::size_t f = 0; f < frames; ++f) {
    const float* row = values.data() + f * dims;
    for (std::uint32_t d = 0; d < dims; ++d) {
      const double delta = row[d] - stats[d].mean;
      squares[d] += delta * delta;
      absolutes[d] += std::abs(delta);
    }
  }
  for (std::uint32_t d = 0; d < dims; ++d) {
    stats[d].std = std::sqrt(squares[d] / static_cast<double>(frames));
    stats[d].mean_abs_dev = absolutes[d] / static_cast<double>(frames);
  }
  return stats;
}

Result<std::vector<DimNormalization>> compute_normalization(const FeatureSchema& schema, std::span<const float> raw) {
  MMVK_TRY(schema.validate());
  const std::uint32_t dims = schema.dims();
  if (raw.empty() || raw.size() % dims != 0) {
    return make_error("normalization: " + std::to_string(raw.size()) + " values is not a whole number (>= 1) of " +
                      std::to_string(dims) + "-d frames");
  }
  const std::vector<DimStatistics> stats = compute_statistics(raw, dims);
  std::vector<DimNormalization> result(dims);
  auto too_small = [](double spread, const DimStatistics& s) {
    const double magnitude = std::max({1.0, std::abs(s.min), std::abs(s.max)});
    return !(spread > 1e-6 * magnitude) || !std::isfinite(spread);
  };
  std::uint32_t first = 0;
  for (const FeatureChannel& channel : schema.channels) {
    const std::uint32_t n = channel.dims();
    const double weight = channel.weight;
    if (channel.normalization == Normalization::GroupStd) {
      double spread = 0.0;
      double magnitude = 1.0;
      for (std::uint32_t d = first; d < first + n; ++d) {
        spread += stats[d].std;
        magnitude = std::max({magnitude, std::abs(stats[d].min), std::abs(stats[d].max)});
      }
      spread /= n;
      if (!(spread > 1e-6 * magnitude) || !std::isfinite(spread)) {
        return make_error("normalization: channel '" + channel.name +
                          "' has zero spread (every dimension is constant over the database; group std " +
                          std::to_string(spread) + ")");
      }
      for (std::uint32_t d = first; d < first + n; ++d) {
        result[d] = {static_cast<float>(stats[d].mean), static_cast<float>(spread / weight)};
      }
    } else {
      for (std::uint32_t d = first; d < first + n; ++d) {
        const DimStatistics& s = stats[d];
        double offset = s.mean;
        double spread = s.std;
        const char* what = "standard deviation";
        if (channel.normalization == Normalization::MeanAbsDev) {
          spread = s.mean_abs_dev;
          what = "mean absolute deviation";
        } else if (channel.normalization == Normalization::MinMax) {
          offset = s.min;
          spread = s.max - s.min;
          what = "max - min";
        }
        if (too_small(spread, s)) {
          return make_error("normalization: channel '" + channel.name + "', dimension " + schema.dim_name(d) +
                            " has zero spread (" + what + " " + std::to_string(spread) + ")");
        }
        result[d] = {static_cast<float>(offset), static_cast<float>(spread / weight)};
      }
    }
    for (std::uint32_t d = first; d < first + n; ++d) {
      if (!(result[d].scale > 0.0f) || !std::isfinite(result[d].scale) || !std::isfinite(result[d].offset)) {
        return make_error("normalization: channel '" + channel.name + "', dimension " + schema.dim_name(d) +
                          " has an unusable scale " + std::to_string(result[d].scale));
      }
    }
    first += n;
  }
  return result;
}

void apply_normalization(std::span<const DimNormalization> normalization, std::span<float> values) {
  const std::size_t dims = normalization.size();
  if (dims == 0) return;
  for (std::size_t i = 0; i < values.size(); i += dims) {
    for (std::size_t d = 0; d < dims; ++d) values[i + d] = (values[i + d] - normalization[d].offset) / normalization[d].scale;
  }
}

}  // namespace mmvk
