// Normalization statistics: per-dimension offsets and scales computed from a
// raw feature matrix, one channel (group) at a time, with the channel weight
// folded into the scale (scale = spread / weight). Normalized features are
// (raw - offset) / scale, so the search cost is a plain squared distance and
// a channel's normalized spread equals its weight.
//
// Per channel, by FeatureChannel::normalization:
//   GroupStd:   offset = per-dim mean; spread = the mean over the channel's
//               dims of each dim's standard deviation (one spread per channel).
//   PerDimStd:  offset = per-dim mean; spread = per-dim standard deviation.
//   MeanAbsDev: offset = per-dim mean; spread = per-dim mean |x - mean|.
//   MinMax:     offset = per-dim min;  spread = per-dim max - min (normalized
//               values then lie in [0, weight]).
// Standard deviations are population ones (divide by N). Statistics are
// accumulated in double.
//
// A spread that is zero (or below 1e-6 x max(1, largest |value| of the
// dimension), i.e. float noise around a constant) is an error naming the
// channel and dimension: dividing by it would blow the dimension up.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database.hpp"
#include "mmvk/feature_schema.hpp"
#include "mmvk/status.hpp"

namespace mmvk {

// Per-dimension statistics of a [frames x dims] matrix (used by
// compute_normalization and by `mmvk inspect`).
struct DimStatistics {
  double mean = 0.0;
  double std = 0.0;           // population standard deviation
  double mean_abs_dev = 0.0;  // mean |x - mean|
  double min = 0.0;
  double max = 0.0;
};

// Preconditions: values.size() == frames * dims.
std::vector<DimStatistics> compute_statistics(std::span<const float> values, std::uint32_t dims);

// Offsets and scales for `raw` ([frames x schema.dims()], frames >= 1).
Result<std::vector<DimNormalization>> compute_normalization(const FeatureSchema& schema, std::span<const float> raw);

// In place: values[f * dims + d] = (values[f * dims + d] - offset[d]) / scale[d].
void apply_normalization(std::span<const DimNormalization> normalization, std::span<float> values);

}  // namespace mmvk
