// A UE-PoseSearch-style approximate search: the rows are projected on their
// first principal components (kPcaComponents dims, from the covariance of
// the database rows), a KD-tree (nanoflann, leaves of 16 rows) over the
// projections returns the C nearest projections of the projected query, and
// those C candidates are re-ranked by the full cost (plain_cost, so the
// returned costs are the reference's). Approximate: the true nearest row may
// not be among the C nearest projections. One query at a time, one thread.
#pragma once

#include <memory>

#include "peer.hpp"

namespace mmvk::peers {

inline constexpr std::uint32_t kPcaComponents = 8;
inline constexpr std::uint32_t kKdTreeLeafRows = 16;

// The projection and the tree, shared by the backends of every C.
class PcaKdTreeIndex;

Result<std::shared_ptr<PcaKdTreeIndex>> build_pca_kdtree(const Database& database);

// Named "pca-kdtree<C>"; C is clamped to the frame count.
Result<std::unique_ptr<PeerBackend>> make_pca_kdtree(const Database& database, std::shared_ptr<PcaKdTreeIndex> index,
                                                     std::uint32_t candidates);

// The principal axes of a symmetric [n x n] matrix (row-major, double):
// eigenvalues in decreasing order with their unit eigenvectors (rows of
// `vectors`, [n x n]), by cyclic Jacobi rotations. Exposed for its test.
void symmetric_eigen(std::vector<double> matrix, std::size_t n, std::vector<double>& values,
                     std::vector<double>& vectors);

}  // namespace mmvk::peers
