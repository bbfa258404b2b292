// FAISS as a peer (Debian libfaiss-dev): the index types a nearest-neighbour
// user would try first, over the database's normalized rows.
//
//   faiss-flat     IndexFlatL2, the whole batch in one search() call. For
//                  20 queries or more FAISS computes ||q||^2 + ||x||^2 - 2 q.x
//                  with a BLAS sgemm, whose rounding differs from mmvk's
//                  sum of (x - q)^2, so two frames whose costs are a few ulp
//                  apart (float near-ties) may come out in the other order.
//   faiss-flat-1q  IndexFlatL2, one search() call per query (what a game
//                  loop asking for one character at a time does); below 20
//                  queries FAISS sums (x - q)^2 directly with its SIMD kernel,
//                  in another order than mmvk's per-channel sums.
//   faiss-ivf<P>   IndexIVFFlat over an IndexFlatL2 quantizer with nlist =
//                  round(4 sqrt(N)) (the low end of FAISS's guideline of
//                  4..16 sqrt(N) lists), trained with FAISS's default
//                  clustering parameters on the database rows, searched with
//                  nprobe = P.
//
// FAISS spreads batched searches over its OpenMP threads (all cores);
// returned costs are FAISS's distances. FAISS exceptions become errors.
#pragma once

#include <filesystem>
#include <memory>

#include "peer.hpp"

namespace mmvk::peers {

Result<std::unique_ptr<PeerBackend>> make_faiss_flat(const Database& database, bool one_query_at_a_time);

// A trained IndexIVFFlat, shared by the faiss-ivf backends of every nprobe.
class FaissIvfIndex;

struct FaissIvfBuild {
  std::shared_ptr<FaissIvfIndex> index;
  // Seconds spent training and adding (read from the cache's sidecar file
  // when the index was loaded from `cache`).
  double build_seconds = 0.0;
};

// Loads the index from `cache` when it exists and matches the database's
// size and dims, else trains it and writes it there (an empty path: no
// cache).
Result<FaissIvfBuild> build_faiss_ivf(const Database& database, const std::filesystem::path& cache);

Result<std::unique_ptr<PeerBackend>> make_faiss_ivf(const Database& database, std::shared_ptr<FaissIvfIndex> index,
                                                    std::uint32_t nprobe);

}  // namespace mmvk::peers
