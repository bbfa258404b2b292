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
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// Normalization of one feature dimension: normalized = (raw - offset) / scale.
// The channel weight is folded into the scale (scale = spread / weight).
struct DimNormalization {
  float offset = 0.0f;
  float scale = 1.0f;   // > 0
};

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

// The table of normalization modes: one entry per mode, with its JSON name
// and its rule. Adding a mode is one enum value and one entry.
struct NormalizationInfo {
  Normalization mode;
  std::string_view name;         // the JSON name, e.g. "group_std"
  std::string_view spread_name;  // for error messages, e.g. "standard deviation"
  bool one_spread_per_channel;   // the channel's spread is the mean of its dims' spreads
  double (*offset)(const DimStatistics&);
  double (*spread)(const DimStatistics&);
};

// Every mode, in Normalization order.
std::span<const NormalizationInfo> normalization_modes();
const NormalizationInfo& normalization_info(Normalization mode);
// The mode with JSON name `name`, or nullptr.
const NormalizationInfo* find_normalization(std::string_view name);
// The JSON names, quoted and comma-separated, for error messages.
std::string normalization_list();

// Offsets and scales for `raw` ([frames x schema.dims()], frames >= 1).
Result<std::vector<DimNormalization>> compute_normalization(const FeatureSchema& schema, std::span<const float> raw);

// In place: values[f * dims + d] = (values[f * dims + d] - offset[d]) / scale[d].
void apply_normalization(std::span<const DimNormalization> normalization, std::span<float> values);

}  // namespace mmvk
