#include "mmvk/search/search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "database/cost_bound.hpp"

namespace mmvk {

namespace {

// An upper bound of |cost| over every frame for one query, in double (which
// cannot overflow here): multiplier * sum_c w_c * sum_d (|q_d| + max|row_d|)^2
// + |bias|, times the continuing multiplier when above 1, + |continuing bias|.
double cost_bound(const Database& database, std::span<const float> query, const QueryParams& params,
                  double max_multiplier, double max_abs_bias) {
  double total = 0.0;
  for (std::size_t c = 0; c < database.schema().channels.size(); ++c) {
    total += double(params.channel_weights[c]) * detail::channel_distance_bound(database, query, c);
  }
  const double base = max_multiplier * total + max_abs_bias;
  return base * std::max(1.0, double(params.continuing_multiplier)) + std::fabs(double(params.continuing_bias));
}

}  // namespace

Status set_channel_weight(const FeatureSchema& schema, QueryParams& params, std::string_view channel, float weight) {
  Result<std::size_t> index = schema.find_channel(channel, "query weight");
  if (!index) return index.status();
  if (!std::isfinite(weight) || weight < 0.0f) {
    return make_error("query weight: channel '" + std::string(channel) + "' weight must be finite and >= 0, got " +
                      std::to_string(weight));
  }
  params.channel_weights[*index] = weight;
  return {};
}

bool params_fit_cost_bound(const Database& database, const QueryParams& params) {
  const double bound = cost_bound(database, database.max_abs_features(), params, database.max_multiplier(),
                                  database.max_abs_bias());
  return bound <= detail::kMaxCostBound;
}

Status validate_queries(const Database& database, const QueryBatch& batch, std::uint32_t k) {
  if (database.frame_count() == 0) return make_error("search: the database is empty");
  if (k < 1 || k > kMaxK) {
    return make_error("search: k = " + std::to_string(k) + " is out of range [1, " + std::to_string(kMaxK) + "]");
  }
  // Before any product of sizes: a huge batch.size would wrap batch.size *
  // dims around and let mismatched spans through.
  if (batch.size > kMaxBatch) {
    return make_error("search: batch of " + std::to_string(batch.size) + " queries is over the limit of " +
                      std::to_string(kMaxBatch) + " (kMaxBatch) per call; split it");
  }
  const std::size_t dims = database.dims();
  if (batch.features.size() != batch.size * dims) {
    return make_error("search: query features have " + std::to_string(batch.features.size()) + " values, expected " +
                      std::to_string(batch.size) + " queries x " + std::to_string(dims) + " dims");
  }
  if (!batch.params.empty() && batch.params.size() != batch.size) {
    return make_error("search: " + std::to_string(batch.params.size()) + " query params for " +
                      std::to_string(batch.size) + " queries");
  }
  for (std::size_t i = 0; i < batch.features.size(); ++i) {
    if (!std::isfinite(batch.features[i])) {
      return make_error("search: query " + std::to_string(i / dims) + " feature " +
                        database.schema().dim_name(static_cast<std::uint32_t>(i % dims)) + " is not finite");
    }
  }
  const std::size_t channels = database.schema().channels.size();
  for (std::size_t q = 0; q < batch.params.size(); ++q) {
    const QueryParams& p = batch.params[q];
    // The message is built only on failure: this loop runs on every query
    // of every crowd tick, which allocates nothing.
    const auto where = [q] { return "search: query " + std::to_string(q) + ": "; };
    if (p.continuing_frame != kNoFrame && p.continuing_frame >= database.frame_count()) {
      return make_error(where() + "continuing_frame " + std::to_string(p.continuing_frame) + " is out of range (" +
                        std::to_string(database.frame_count()) + " frames)");
    }
    if (!std::isfinite(p.continuing_bias)) return make_error(where() + "continuing_bias is not finite");
    if (!std::isfinite(p.continuing_multiplier) || p.continuing_multiplier < 0.0f) {
      return make_error(where() + "continuing_multiplier must be finite and >= 0");
    }
    for (std::size_t c = 0; c < channels; ++c) {
      if (!std::isfinite(p.channel_weights[c]) || p.channel_weights[c] < 0.0f) {
        return make_error(where() + "weight of channel '" + database.schema().channels[c].name +
                          "' must be finite and >= 0");
      }
    }
  }
  // Costs are float sums; a query that is finite but far outside the data
  // (or a huge weight) would turn every cost into +inf and "win" with
  // garbage. Half of FLT_MAX leaves room for the float rounding of the sums.
  const double max_multiplier = database.max_multiplier();
  const double max_abs_bias = database.max_abs_bias();
  const double limit = detail::kMaxCostBound;
  const QueryParams defaults;
  for (std::size_t q = 0; q < batch.size; ++q) {
    const QueryParams& p = batch.params.empty() ? defaults : batch.params[q];
    const double bound = cost_bound(database, batch.features.subspan(q * dims, dims), p, max_multiplier, max_abs_bias);
    if (!(bound <= limit)) {
      return make_error("search: query " + std::to_string(q) +
                        ": its costs could overflow float (features or weights too large for this database; "
                        "normalized features are usually within a few hundred)");
    }
  }
  return {};
}

Status validate_search(const Database& database, const QueryBatch& batch, std::uint32_t k, std::span<const Match> out) {
  MMVK_TRY(validate_queries(database, batch, k));
  if (out.size() != batch.size * k) {
    return make_error("search: result span has " + std::to_string(out.size()) + " slots, expected " +
                      std::to_string(batch.size) + " x k=" + std::to_string(k));
  }
  return {};
}

bool is_candidate(const Database& database, std::uint32_t frame, const QueryParams& params) {
  const std::uint32_t flags = database.frame_flags()[frame];
  if ((flags & (kFrameDoNotUse | kFrameEdgeExcluded)) != 0) return false;
  const bool continuing = frame == params.continuing_frame;
  if ((flags & kFrameBlockTransition) != 0 && !continuing) return false;
  const TagMask tags = database.frame_tags()[frame];
  if ((tags & params.require_all) != params.require_all) return false;
  if ((tags & params.exclude_any) != 0) return false;
  if (params.continuing_frame != kNoFrame && !continuing && params.exclusion_window > 0) {
    const std::uint32_t clip_index = database.frame_clip()[params.continuing_frame];
    if (database.frame_clip()[frame] == clip_index) {
      const Clip& clip = database.clips()[clip_index];
      const std::uint32_t a = frame - clip.first_frame;
      const std::uint32_t b = params.continuing_frame - clip.first_frame;
      std::uint32_t distance = a > b ? a - b : b - a;
      if (clip.loop) distance = std::min(distance, clip.frame_count - distance);
      if (distance <= params.exclusion_window) return false;
    }
  }
  return true;
}

float frame_cost(const Database& database, std::uint32_t frame, std::span<const float> query, const QueryParams& params) {
  const std::span<const float> row = database.row(frame);
  const FeatureSchema& schema = database.schema();
  float total = 0.0f;
  std::uint32_t d = 0;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const std::uint32_t end = d + schema.channels[c].dims();
    float channel_sum = 0.0f;
    for (; d < end; ++d) {
      const float diff = row[d] - query[d];
      channel_sum += diff * diff;
    }
    total += params.channel_weights[c] * channel_sum;
  }
  float cost = database.frame_multiplier()[frame] * total + database.frame_bias()[frame];
  if (frame == params.continuing_frame) {
    cost = cost * params.continuing_multiplier;
    cost += params.continuing_bias;
  }
  return cost;
}

std::string cpu_device_text(unsigned threads) {
  return "cpu, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads");
}

}  // namespace mmvk
