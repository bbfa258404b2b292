// k-means cluster tables over a database's feature rows: the data the exact
// cluster-pruned CPU search walks, and exactly what the Vulkan backend
// uploads into its buffers. Trained on the CPU, never on the GPU.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

class ThreadPool;

// Parameters with documented defaults (nothing is seeded from the clock).
struct KMeansParams {
  // Number of clusters; 0 = round(sqrt(frame_count)), clamped to [1, frames].
  // sqrt(N) was kept after trying 2*sqrt(N) and 4*sqrt(N) on the 417k-frame
  // Bandai volume set: they evaluate fewer rows per exact query (0.83%,
  // 0.63% vs 1.04%) but every query bounds every cluster first, and that
  // cost grows with the count; exact search measured no faster, and nprobe
  // needed more probes for the same recall.
  std::uint32_t clusters = 0;
  std::uint32_t iterations = 25;    // Lloyd iterations after k-means++ seeding (stops early when stable)
  std::uint64_t seed = 1234;        // k-means++ initialization seed (std::mt19937_64)
  // k-means++ and Lloyd run on at most this many frames, drawn uniformly
  // without replacement from the seed (all frames when fewer); every frame
  // is then assigned to its nearest trained centroid. 0 = all frames.
  // 65536 keeps training at N = 417k, D = 27, 650 clusters to seconds while
  // giving each cluster ~100 training points.
  std::uint32_t max_training_frames = 65536;
};

// Arrays are row-major; "dims" is the database's feature dimension count and
// "channel_count" its schema's channel count. Units are those of the
// normalized features.
struct ClusterTable {
  std::uint64_t database_hash = 0;  // Database::content_hash() of the source
  std::uint32_t dims = 0;
  std::uint32_t cluster_count = 0;
  std::vector<float> centroids;     // [cluster_count x dims]
  // Members of cluster c are members[offsets[c] .. offsets[c+1]), original
  // frame ids in ascending order; offsets has cluster_count + 1 entries.
  // A cluster may be empty (offsets[c] == offsets[c+1]); its box is its
  // centroid, min_multiplier 1, min_bias 0, tags 0, flags all ones.
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

  // Added after the first layout (the Vulkan backend may ignore them):
  // [cluster_count], AND of the members' tags: a cluster is skipped when
  // every member carries a tag of the query's exclude_any mask.
  std::vector<TagMask> tag_intersection;
  std::uint32_t channel_count = 0;      // schema channels of the database
  // [cluster_count x channel_count]: max over members of the Euclidean
  // distance between the member's and the centroid's values of that channel
  // (rounded up to the next float), for the per-channel triangle bound
  // cost >= min_mult * sum_c w_c * max(0, |q_c - centroid_c| - radius_c)^2 + min_bias.
  // No backend uses that bound (it never beat the box bound); the field is
  // kept so that tables on disk keep their layout.
  std::vector<float> channel_radius;
};

// Where training is, for a progress bar. Stages in order: "seeding"
// (k-means++, step = centroids chosen), "lloyd" (step = iterations done;
// it may stop early when stable), "assigning" (every frame to its nearest
// centroid: step 0 of 1, then 1 of 1). `fraction` in [0, 1] weighs the
// stages by their distance evaluations and never decreases.
struct TrainingProgress {
  const char* stage = "";
  std::uint32_t step = 0;
  std::uint32_t steps = 0;
  double fraction = 0.0;
};
// Called on the training thread, between steps (never from the pool's
// workers); it should return quickly.
using TrainingProgressFn = std::function<void(const TrainingProgress&)>;

// Trains k-means (k-means++ seeding, then Lloyd) and builds the table.
// Deterministic for given params and database: the same table on every
// machine and thread count. The pool overload spreads the distance work;
// `progress` (may be empty) reports each step.
Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params);
Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params, ThreadPool& pool);
Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params, ThreadPool& pool,
                                         const TrainingProgressFn& progress);

// Checks that `table` was built from `database` (hash, dims, sizes) and is
// internally consistent (members a partition of the frames, ascending within
// each cluster; boxes, radii, multipliers, biases, tags and flags cover every
// member, so the pruning bounds hold); the error says what does not match.
Status validate_cluster_table(const ClusterTable& table, const Database& database);

// Versioned binary file with a checksum, written atomically.
Status save_cluster_table(const ClusterTable& table, const std::filesystem::path& path);
Result<ClusterTable> load_cluster_table(const std::filesystem::path& path);

}  // namespace mmvk
