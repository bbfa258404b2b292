#include "database/cost_bound.hpp"

#include <cmath>

namespace mmvk::detail {

double channel_distance_bound(const Database& database, std::span<const float> query, std::size_t channel) {
  const FeatureSchema& schema = database.schema();
  const std::span<const float> max_abs = database.max_abs_features();
  const std::uint32_t first = schema.offset(channel);
  const std::uint32_t end = first + schema.channels[channel].dims();
  double sum = 0.0;
  for (std::uint32_t d = first; d < end; ++d) {
    const double diff = std::fabs(double(query[d])) + double(max_abs[d]);
    sum += diff * diff;
  }
  return std::isfinite(sum) ? sum : std::numeric_limits<double>::infinity();
}

}  // namespace mmvk::detail
