// k-means cluster tables over a database's feature rows: the data the exact
// cluster-pruned CPU search walks, and exactly what the Vulkan backend
// uploads into its buffers. Trained on the CPU, never on the GPU.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "mmvk/database.hpp"
#include "mmvk/status.hpp"

namespace mmvk {

// Parameters with documented defaults (nothing is seeded from the clock).
struct KMeansParams {
  // Number of clusters; 0 = round(sqrt(frame_count)), clamped to [1, frames].
  std::uint32_t clusters = 0;
  std::uint32_t iterations = 25;    // Lloyd iterations after k-means++ seeding
  std::uint64_t seed = 1234;        // k-means++ initialization seed
};

struct ClusterTable {
  std::uint64_t database_hash = 0;  // Database::content_hash() of the source
  std::uint32_t dims = 0;
  std::uint32_t cluster_count = 0;
  std::vector<float> centroids;     // [cluster_count x dims]
  // Members of cluster c are members[offsets[c] .. offsets[c+1]), original
  // frame ids in ascending order; offsets has cluster_count + 1 entries.
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> members;   // [frame_count]
  std::vector<float> box_min;           // [cluster_count x dims], per-dim min of the members
  std::vector<float> box_max;           // [cluster_count x dims]
  std::vector<float> min_multiplier;    // [cluster_count], min clip multiplier of the members
  std::vector<float> min_bias;          // [cluster_count], min clip bias of the members
  std::vector<TagMask> tag_union;       // [cluster_count], OR of the members' tags
  // [cluster_count], AND of the members' flags: a cluster whose members are
  // all do-not-use or edge-excluded is skipped without evaluation.
  std::vector<std::uint32_t> flags_intersection;
};

Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params);

// Checks that `table` was built from `database` (hash, dims, sizes) and is
// internally consistent; the error says what does not match.
Status validate_cluster_table(const ClusterTable& table, const Database& database);

// Versioned binary file with a checksum, written atomically.
Status save_cluster_table(const ClusterTable& table, const std::filesystem::path& path);
Result<ClusterTable> load_cluster_table(const std::filesystem::path& path);

}  // namespace mmvk
