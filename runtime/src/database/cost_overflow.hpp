// The build's check that its database can be searched: a schema weight of
// 1e38 or a clip's cost_multiplier of 3e38 builds a valid-looking
// database on which every search then fails ("costs could overflow
// float"), naming neither the clip nor the field. Checked at build time
// instead, for queries inside the data's range (|q_d| <= max|row_d|).
#pragma once

#include <string>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::detail {

// Errors name `source` (the manifest), then the schema channel and its
// weight, or the clip (name and file) and its cost_multiplier, cost_bias or
// cost_ranges.
Status check_cost_overflow(const Database& database, const std::string& source);

}  // namespace mmvk::detail
