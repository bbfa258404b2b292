// The sorted top-k list every CPU backend fills, and the flags that rule a
// row out before its cost matters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"

namespace mmvk::detail {

// Rows with these flags never enter a result by the tile pass: block-transition
// rows may only be continued into, and the continuing frame is evaluated on
// its own (with its continuing_bias) before any tile.
inline constexpr std::uint32_t kNeverCandidate = kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition;

// Inserts `candidate` into the (cost, frame)-sorted list `best` when it beats
// the k-th entry. Offered in any order, the strict order sends equal costs to
// the lower frame id (the reference's tie rule).
inline void insert_sorted(std::span<Match> best, const Match& candidate) {
  std::size_t slot = best.size() - 1;
  if (!match_less(candidate, best[slot])) return;
  while (slot > 0 && match_less(candidate, best[slot - 1])) {
    best[slot] = best[slot - 1];
    --slot;
  }
  best[slot] = candidate;
}

// Offers a row that a tile kernel reported to one query's list. Tiles know no
// continuing_bias, so the continuing frame (seeded before the tiles) is
// skipped here.
inline void offer_tile_row(const Database& db, const QueryParams& params, std::span<Match> best,
                           const Match& candidate) {
  if (!match_less(candidate, best.back())) return;
  if (candidate.frame == params.continuing_frame || !is_candidate(db, candidate.frame, params)) return;
  insert_sorted(best, candidate);
}

}  // namespace mmvk::detail
