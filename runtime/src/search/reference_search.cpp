#include "mmvk/search/reference_search.hpp"

#include <algorithm>

#include "search/top_k.hpp"

namespace mmvk {

Status ReferenceSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  const Database& db = *database_;
  const QueryParams default_params;
  for (std::size_t q = 0; q < batch.size; ++q) {
    const QueryParams& params = batch.params.empty() ? default_params : batch.params[q];
    const std::span<const float> query = batch.features.subspan(q * db.dims(), db.dims());
    const std::span<Match> best = out.subspan(q * k, k);
    std::fill(best.begin(), best.end(), Match{});
    // Ties go to the lower frame id (insert_sorted's strict order).
    for (std::uint32_t frame = 0; frame < db.frame_count(); ++frame) {
      if (!is_candidate(db, frame, params)) continue;
      const Match candidate{frame, frame_cost(db, frame, query, params)};
      ++stats_.rows_evaluated;
      detail::insert_sorted(best, candidate);
    }
  }
  stats_.queries += batch.size;
  return {};
}

}  // namespace mmvk
