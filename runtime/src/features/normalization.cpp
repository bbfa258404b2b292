#include "mmvk/features/normalization.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/name_table.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk {

namespace {

double mean(const DimStatistics& s) { return s.mean; }
double std_dev(const DimStatistics& s) { return s.std; }
double mean_abs_dev(const DimStatistics& s) { return s.mean_abs_dev; }
double min(const DimStatistics& s) { return s.min; }
double range(const DimStatistics& s) { return s.max - s.min; }

// One entry per mode, in Normalization order.
constexpr NormalizationInfo kModes[] = {
    {Normalization::GroupStd, "group_std", "standard deviation", true, mean, std_dev},
    {Normalization::PerDimStd, "per_dim_std", "standard deviation", false, mean, std_dev},
    {Normalization::MeanAbsDev, "mean_abs_dev", "mean absolute deviation", false, mean, mean_abs_dev},
    {Normalization::MinMax, "min_max", "max - min", false, min, range},
};

static_assert(detail::indexed_by(std::span<const NormalizationInfo>(kModes), &NormalizationInfo::mode),
              "kModes is indexed by Normalization");

}  // namespace

std::span<const NormalizationInfo> normalization_modes() { return kModes; }

const NormalizationInfo& normalization_info(Normalization mode) { return detail::entry_for(normalization_modes(), mode); }

const NormalizationInfo* find_normalization(std::string_view name) {
  return detail::find_named(normalization_modes(), &NormalizationInfo::name, name);
}

std::string normalization_list() {
  return detail::name_list(normalization_modes(), &NormalizationInfo::name, '"', true);
}

std::string_view normalization_name(Normalization mode) {
  return detail::name_for(normalization_modes(), &NormalizationInfo::name, mode);
}

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
    const NormalizationInfo& mode = normalization_info(channel.normalization);
    if (mode.one_spread_per_channel) {
      double spread = 0.0;
      double magnitude = 1.0;
      for (std::uint32_t d = first; d < first + n; ++d) {
        spread += mode.spread(stats[d]);
        magnitude = std::max({magnitude, std::abs(stats[d].min), std::abs(stats[d].max)});
      }
      spread /= n;
      if (!(spread > 1e-6 * magnitude) || !std::isfinite(spread)) {
        return make_error("normalization: channel '" + channel.name +
                          "' has zero spread (every dimension is constant over the database; mean " +
                          std::string(mode.spread_name) + " " + std::to_string(spread) + ")");
      }
      for (std::uint32_t d = first; d < first + n; ++d) {
        result[d] = {static_cast<float>(mode.offset(stats[d])), static_cast<float>(spread / weight)};
      }
    } else {
      for (std::uint32_t d = first; d < first + n; ++d) {
        const DimStatistics& s = stats[d];
        const double spread = mode.spread(s);
        if (too_small(spread, s)) {
          return make_error("normalization: channel '" + channel.name + "', dimension " + schema.dim_name(d) +
                            " has zero spread (" + std::string(mode.spread_name) + " " + std::to_string(spread) + ")");
        }
        result[d] = {static_cast<float>(mode.offset(s)), static_cast<float>(spread / weight)};
      }
    }
    for (std::uint32_t d = first; d < first + n; ++d) {
      if (!(result[d].scale > 0.0f) || !std::isfinite(result[d].scale) || !std::isfinite(result[d].offset)) {
        return make_error("normalization: channel '" + channel.name + "', dimension " + schema.dim_name(d) +
                          " has an unusable scale " + std::to_string(result[d].scale));
      }
      // scale = spread / weight: a huge weight makes the normalized features
      // themselves overflow, which the build found later as "feature ... is
      // not finite", naming a frame instead of the weight.
      const double reach = std::max(std::abs(stats[d].max - double(result[d].offset)),
                                    std::abs(stats[d].min - double(result[d].offset)));
      if (!(reach / double(result[d].scale) <= double(std::numeric_limits<float>::max()))) {
        return make_error("normalization: channel '" + channel.name + "': weight " + number_text(channel.weight) +
                          " scales its features beyond float's range (dimension " + schema.dim_name(d) + "); lower it");
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
