// The cluster-pruned CPU backend over a k-means ClusterTable.
//
// Exact mode (nprobe = 0): per query, a lower bound of every cluster's best
// possible cost is computed, clusters are visited in order of that bound,
// and the walk stops when the next bound is strictly above the current k-th
// best cost (equal costs may still win on the lower frame id). Returns the
// reference's frames with bit-identical costs: rows are evaluated in the
// reference's accumulation order (see search.hpp).
//
// The lower bound of cluster c is its box bound, a true lower bound of
// multiplier_i * total_i for every member i, to which min_bias is added
// (float addition is monotone, so the bias step keeps it a bound):
// min_multiplier * sum_ch w_ch * sum_d gap_d^2, gap_d = distance of q_d to
// [box_min_d, box_max_d], accumulated in the reference's order in float;
// every rounding step is monotone, so it never exceeds the cost of a member
// computed the same way.
// The continuing frame (whose cost may carry a negative continuing_bias) is
// evaluated first as a seed and skipped during the cluster walk, so the
// cluster bounds never need to account for continuing_bias.
// Within a visited cluster, the members (in frame order, so mostly runs of
// neighbouring frames) are evaluated in tiles of 16 rows, and a tile whose
// own box bound is above the k-th best is skipped (same box-bound argument;
// the tile boxes, and the boxes of spans of 16 tiles, are held as halves
// rounded outward, so each still holds its rows).
// Clusters are skipped without evaluation when their tag union misses the
// query's require_all mask, their tag intersection hits exclude_any, or all
// their members are do-not-use, edge-excluded or block-transition.
//
// Exact mode first visits the cluster whose centroid is nearest to the query
// (option seed_nearest), so the k-th best is tight before the bound-ordered
// walk starts; that never changes the results, only the work.
// With seed_nearest and box_bound, a level above the clusters spares most
// cluster bounds: the backend orders the clusters (internally; the caller's
// ids are kept for nprobe's ties) so that each run of 32 holds nearby
// centroids, a group with the box of its members and the box of its
// centroids. The seed is found group by group in order of the centroid
// box's bound, and after the seed only the groups whose own bound is at most
// the k-th best get their cluster bounds computed.
//
// Approximate mode (nprobe > 0): only the nprobe eligible clusters whose
// centroids are nearest to the query (channel-weighted squared distance) are
// searched (plus the continuing frame), nearest first, each with the exact
// mode's cluster and tile bounds against the current k-th best (a probed
// cluster whose bound is above it is skipped); nprobe >= cluster_count gives
// the exact results. Batches visit the probed clusters grouped by cluster,
// like exact mode (see batch_by_cluster), with the same results. Up to 32
// probes (with box_bound), the probed set is found through the group level
// (the groups in order of their centroid box's bound, until that bound is
// above the nprobe-th nearest distance found) rather than by ranking every
// centroid; the set is the same.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

struct ClusterSearchOptions {
  std::uint32_t nprobe = 0;  // 0 = exact; else clusters searched per query
  bool box_bound = true;     // use the per-dimension box bound
  // Within a visited cluster, skip 16-row tiles whose own box bound (the
  // same box bound over the tile's members) is above the k-th best.
  bool tile_bound = true;
  // With tile_bound, in a cluster of more than 16 tiles: first bound each
  // span of 16 tiles (a third level of boxes) and compute the tile bounds of
  // the spans whose bound is at most the k-th best only.
  bool span_bound = true;
  // Exact mode: visit the cluster of the nearest centroid first, then the
  // rest in lower-bound order (the seed tightens the k-th best early).
  bool seed_nearest = true;
  // Each thread takes its queries in sub-batches and visits their clusters
  // (in nprobe mode, the probed ones) grouped by cluster, so the rows of a
  // cluster are loaded once for all the sub-batch's queries that visit it
  // (see cluster_search.cpp). Off: the one-query walk, query by query. A
  // thread's share of one query takes the one-query walk either way.
  bool batch_by_cluster = true;
  // Visited tiles are read from a 16-bit (IEEE half) copy of the rows: a
  // row whose lower bound from its half row passes the k-th best enters the
  // list with an upper bound of its cost, and at the query's end the rows
  // that can still be in the result get their exact cost (from the
  // database's rows). Results and costs stay the reference's, bit for bit.
  // The half copy replaces the backend's float copy of the rows: 2 bytes a
  // value instead of 4 (27 dims: 54 bytes a row instead of 120 with the
  // float copy's multiplier, bias and lane flag). Off: every visited row is
  // evaluated from the float copy.
  bool half_filter = true;
  // As FastSearchOptions::kernels.
  CpuKernels kernels = CpuKernels::Widest;
};

// Work counters beyond SearchStats (benchmarks report them).
struct ClusterSearchCounters {
  std::uint64_t clusters_visited = 0;  // clusters whose tiles were walked
  std::uint64_t tiles_checked = 0;     // tiles whose bound was computed
  // half_filter: tiles filtered at half precision, rows that passed the
  // filter (deferred to the query's end), and rows evaluated exactly there.
  std::uint64_t tiles_filtered = 0;
  std::uint64_t rows_rechecked = 0;
  std::uint64_t rows_exact = 0;
};

class ClusterSearch final : public SearchBackend {
 public:
  // Validates `table` against `database` (validate_cluster_table) and copies
  // the rows into cluster order. `database` and `pool` must outlive the
  // backend; the pool serves one search() at a time.
  static Result<std::unique_ptr<ClusterSearch>> create(const Database& database, const ClusterTable& table,
                                                       ThreadPool& pool, ClusterSearchOptions options = {});
  ~ClusterSearch() override;

  std::string_view name() const override { return options_.nprobe == 0 ? "clusters" : "clusters-nprobe"; }
  std::string device() const override { return cpu_device_text(pool_->thread_count()); }
  const Database& database() const override { return *database_; }
  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  SearchStats stats() const override { return stats_; }
  void reset_stats() override {
    stats_ = {};
    counters_ = {};
  }
  const ClusterSearchCounters& counters() const { return counters_; }

  const ClusterSearchOptions& options() const { return options_; }
  std::uint32_t cluster_count() const;
  // The instruction set the kernels use: "avx512f", "avx2" or "generic".
  std::string_view kernel_name() const;

  struct Layout;  // the cluster-ordered tiles (cluster_search.cpp)

 private:
  ClusterSearch(const Database& database, ThreadPool& pool, ClusterSearchOptions options, std::unique_ptr<Layout> layout);

  const Database* database_;
  ThreadPool* pool_;
  ClusterSearchOptions options_;
  std::unique_ptr<Layout> layout_;
  SearchStats stats_;
  ClusterSearchCounters counters_;
};

}  // namespace mmvk
