#include "database/cost_overflow.hpp"

#include <cmath>

#include "database/cost_bound.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk::detail {

Status check_cost_overflow(const Database& database, const std::string& source) {
  const FeatureSchema& schema = database.schema();
  // A query at the far corner of the data's box: (|q_d| + max|row_d|) = 2 max|row_d|.
  const std::span<const float> corner = database.max_abs_features();
  double total = 0.0;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const double channel = channel_distance_bound(database, corner, c);
    if (!(channel <= kMaxCostBound)) {
      return make_error(source + ": schema channel '" + schema.channels[c].name + "': weight " +
                        number_text(schema.channels[c].weight) +
                        " makes its costs overflow float (the weight scales the normalized features); lower it");
    }
    total += channel;
  }
  if (!(total <= kMaxCostBound)) {
    return make_error(source + ": the schema's weights together make the costs overflow float; lower them");
  }
  const std::string overflow =
      " would make costs overflow float (the features' costs reach " + number_text(total) + ")";
  for (const Clip& clip : database.clips()) {
    const std::string where = source + ": clip '" + clip.name + "' (" + clip.source + "): ";
    if (!(std::fabs(double(clip.cost_bias)) <= kMaxCostBound)) {
      return make_error(where + "cost_bias " + number_text(clip.cost_bias) +
                        " would make costs overflow float; lower it");
    }
    if (!(double(clip.cost_multiplier) * total + std::fabs(double(clip.cost_bias)) <= kMaxCostBound)) {
      return make_error(where + "cost_multiplier " + number_text(clip.cost_multiplier) + overflow + "; lower it");
    }
  }
  // Cost ranges multiply the clip's values frame by frame.
  const std::span<const float> multiplier = database.frame_multiplier();
  const std::span<const float> bias = database.frame_bias();
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (double(multiplier[f]) * total + std::fabs(double(bias[f])) <= kMaxCostBound) continue;
    const Clip& clip = database.clips()[database.frame_clip()[f]];
    return make_error(source + ": clip '" + clip.name + "' (" + clip.source + "): cost_ranges: frame " +
                      std::to_string(f - clip.first_frame) + " has cost multiplier " + number_text(multiplier[f]) +
                      " and bias " + number_text(bias[f]) + ", which" + overflow + "; lower them");
  }
  return {};
}

}  // namespace mmvk::detail
