// Internal: building a ClusterTable from trained centroids and a frame
// assignment (shared by training and tests of the table invariants).
#pragma once

#include <functional>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::detail {


// frame_cluster[frame] < centroids.size() / dims. Fills members, offsets,
// boxes, radii, multipliers, biases, tags and flags.
ClusterTable build_cluster_table(const Database& database, std::vector<float> centroids,
                                 const std::vector<std::uint32_t>& frame_cluster);

Result<ClusterTable> train_cluster_table_impl(const Database& database, const KMeansParams& params,
                                              mmvk::ThreadPool* pool, const TrainingProgressFn& progress = {});

// Lloyd iterations on points [count x dims] from the given centroids
// [k x dims] (updated in place); stops early when the assignment is stable.
// An empty cluster is re-seeded at the point farthest from its centroid.
// `on_iteration` (may be empty) gets the number of iterations done after
// each one.
void run_lloyd(const float* points, std::size_t count, std::uint32_t dims, std::vector<float>& centroids,
               std::uint32_t iterations, mmvk::ThreadPool* pool,
               const std::function<void(std::uint32_t)>& on_iteration = {});

// Euclidean distance between a row and a centroid over one channel's dims
// [begin, end), in double, rounded up to a float: a radius that is never
// below the true one.
float channel_distance_up(const float* row, const float* centroid, std::uint32_t begin, std::uint32_t end);

}  // namespace mmvk::detail
