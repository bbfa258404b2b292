// The float-overflow bound on costs shared by the search's input checks
// (validate_search), the build's check of the database it made
// (database/cost_overflow.cpp) and the pose query builder, so each can name
// what is too large: a query, a clip's cost multiplier, a schema weight or
// a pose target.
#pragma once

#include <cstddef>
#include <limits>
#include <span>

#include "mmvk/database/database.hpp"

namespace mmvk::detail {

// The largest cost bound a search accepts: half of FLT_MAX leaves room for
// the float rounding of the sums.
inline constexpr double kMaxCostBound = 0.5 * double(std::numeric_limits<float>::max());

// An upper bound, in double (which cannot overflow here), of channel c's
// squared distance between `query` (normalized, [dims]) and any row:
// sum over its dims of (|q_d| + max|row_d|)^2. NaN or inf queries give inf.
double channel_distance_bound(const Database& database, std::span<const float> query, std::size_t channel);

}  // namespace mmvk::detail
