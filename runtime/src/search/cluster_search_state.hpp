// The state ClusterSearch's walks share (cluster_search.cpp) with the
// per-query bound stages (cluster_bounds.cpp): the cluster-ordered layout,
// each thread's scratch, a query as the walks see it, and the stages that
// decide which clusters a query visits.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/search/cluster_search.hpp"
#include "search/half_tile_store.hpp"
#include "search/tile_kernels.hpp"
#include "search/tile_store.hpp"

namespace mmvk {
namespace cluster_walk {

constexpr std::uint32_t kLanes = detail::kLanes;  // rows per tile, boxes per pack

inline std::size_t packs_of(std::size_t boxes) { return (boxes + kLanes - 1) / kLanes; }

constexpr std::uint32_t kNoCluster = 0xffffffffu;

// Exact batched mode: queries whose bounds are held at once per thread (their
// bounds take kSubBatch x clusters floats), and the rounds that take one
// candidate cluster per query before the rest are taken at once.
constexpr std::size_t kSubBatch = 512;
constexpr std::uint32_t kRankedRounds = 1;
// Tiles of one cluster handed to the kernel at once (half_filter: to the
// filter, which holds 8 tiles' sums at once with AVX-512).
constexpr std::uint32_t kTileChunk = 4;
constexpr std::uint32_t kHalfChunk = 8;
// The group level above the clusters: runs of kGroupPacks cluster packs
// (32 clusters) whose centroids lie near each other. Exact mode computes the
// group bounds first and the cluster bounds only of the groups whose bound
// can still pass the k-th best after the seed cluster (about sqrt(K) groups
// for the usual K of 400-1000).
constexpr std::uint32_t kGroupPacks = 2;
constexpr std::uint32_t kGroupClusters = kGroupPacks * kLanes;
// A thread's share of a batch up to this many queries takes the one-query
// walk: the grouped walk's sub-batch bookkeeping buys nothing without other
// queries to share the clusters with.
constexpr std::size_t kOneQueryShare = 1;

// Ordered by (bound, cluster); in nprobe mode `bound` is the centroid
// distance and `lower` the lower bound.
struct ClusterBound {
  float bound;
  std::uint32_t cluster;
  float lower = 0.0f;
  friend bool operator<(const ClusterBound& a, const ClusterBound& b) {
    return a.bound < b.bound || (a.bound == b.bound && a.cluster < b.cluster);
  }
};

// A cluster that query `query` of a sub-batch is to visit, with the
// cluster's lower bound for that query (carried, so that the grouped walk
// does not look it up in a sub-batch's bounds, a cache miss per pair).
struct VisitPair {
  std::uint32_t cluster;
  std::uint32_t query;
  float bound;
};

// Which of a query's cluster bounds are computed: all of them, or those of
// the groups marked done (Partial: complete_bounds() adds the groups that
// pass after the seed; Probed: nprobe's search, final). Bounds outside are
// never read.
enum class BoundState : std::uint8_t { All, Partial, Probed };

// half_filter: a row whose half-precision bound passed the k-th best when
// its tile was filtered; its exact cost is computed at the end of the query
// if the bound still passes then (see cluster_search.cpp).
struct DeferredRow {
  std::uint32_t frame;
  float distance;      // the kernel's half-precision distance
  std::uint32_t block;  // its cluster (HalfTileStore block)
};

struct Scratch {
  std::vector<ClusterBound> order;
  std::vector<float> bound, distance;            // [clusters, padded to 16]
  std::vector<float> group_bound, group_distance;  // [groups, padded to 16]
  std::vector<std::uint8_t> group_done;            // [groups]: its cluster bounds are computed
  std::vector<float> tile_bound;                 // [tiles of the largest cluster, padded to 16]
  std::vector<float> span_bound;                 // [spans of the largest cluster, padded to 16]
  std::vector<std::uint32_t> passing;            // [tiles of the largest cluster]
  std::array<detail::LaneHit, kLanes * kTileChunk> hits{};
  // half_filter: per tile of a chunk, its lanes through the filter and
  // their half-precision distances; per query of a sub-batch (one query:
  // the first), the rows deferred to its exact re-rank.
  std::array<std::uint16_t, kHalfChunk> masks{};
  std::array<float, kLanes * kHalfChunk> distances{};
  std::vector<std::vector<DeferredRow>> deferred;  // [kSubBatch]
  // The grouped walk (batch_by_cluster).
  std::vector<float> batch_bound;                              // [kSubBatch][clusters, padded to 16]
  std::vector<float> batch_group_bound;                        // [kSubBatch][groups, padded to 16]
  std::vector<std::uint8_t> batch_group_done;                 // [kSubBatch][groups]
  std::vector<BoundState> bound_state;                        // [kSubBatch]
  std::vector<std::uint32_t> seed, cursor, candidate_end;     // [kSubBatch]
  std::vector<ClusterBound> candidates;                        // each query's, sorted, one after another
  std::vector<ClusterBound> staging;                           // [clusters]: collect_candidates'
  std::vector<VisitPair> pairs, bucketed;                      // to visit; the same grouped by cluster
  std::vector<std::uint32_t> bucket_start, bucket_fill;
  std::uint64_t rows = 0;
  ClusterSearchCounters counters;
};

}  // namespace cluster_walk

struct ClusterSearch::Layout {
  // The table with its clusters reordered so that each group (a run of
  // kGroupClusters) holds nearby centroids; cluster ids below are these.
  ClusterTable table;
  // [clusters]: the id in the caller's table of each cluster, and back. The
  // nprobe set breaks centroid-distance ties on the caller's id, so the
  // reordering never changes which clusters nprobe searches.
  std::vector<std::uint32_t> table_id, internal_id;
  // [groups]: the box of the candidate members of group g's clusters (min
  // multiplier and bias), and the box of their centroids (multiplier 1,
  // bias 0: its bound is at most the distance to any of them).
  std::uint32_t group_count = 0;
  detail::BoxPacks group_boxes;
  detail::BoxPacks group_centroids;
  std::vector<std::uint8_t> group_has_candidate;  // [groups]
  std::uint32_t dims = 0;
  detail::Kernels kernels{};
  std::vector<std::uint32_t> tile_offsets;   // [clusters + 1]
  // The members of each cluster, in frame order, fill its tiles; the last
  // tile of a cluster is padded (kNoFrame, an invalid lane).
  std::vector<std::uint32_t> frame;          // [tiles x 16]
  // With options.half_filter, `half` holds the tiles at half precision and
  // `rows` only its channel ends (no tiles); else `half` is empty.
  detail::TileStore rows;
  detail::HalfTileStore half;
  // The box of each tile's member rows, with their minimum multiplier and
  // bias. A cluster's tile boxes start a pack of their own, so its bounds
  // are whole packs: tile i of cluster c is box tile_box_pack[c] * 16 + i.
  // Held as halves, rounded outward: the bounds read half the bytes (a lone
  // query waits on them), and a box widened to halves prunes almost the
  // same tiles (0.2% more pass on the Bandai volume set).
  detail::HalfBoxPacks tile_boxes;
  std::vector<std::uint32_t> tile_box_pack;  // [clusters]
  std::vector<std::uint8_t> tile_rows;       // [tiles]: member rows (the rest is padding)
  std::uint32_t max_cluster_tiles = 0;
  // The third level, between clusters and tiles: the box of each span of
  // 16 tiles (one tile-box pack) of a cluster with more than one span,
  // packed like the tile boxes: span j of cluster c is box span_box_pack[c]
  // * 16 + j; kNoCluster for a cluster of one span (its cluster box is it).
  // Halves, as the tile boxes.
  detail::HalfBoxPacks span_boxes;
  std::vector<std::uint32_t> span_box_pack;  // [clusters]
  detail::BoxPacks cluster_boxes;            // box c: the table's box, min_multiplier and min_bias
  // Box c: [centroid, centroid], multiplier 1, bias 0, so its bound is the
  // channel-weighted squared centroid distance.
  detail::BoxPacks centroids;
  // [clusters]: 1 when empty or all members excluded by flags (bytes, not
  // vector<bool>, so the per-query eligibility loop vectorizes).
  std::vector<std::uint8_t> never_candidate;
  std::uint32_t candidate_clusters = 0;      // clusters with never_candidate 0
  std::vector<cluster_walk::Scratch> scratch;              // [pool threads]
};

namespace cluster_walk {

// One query as the walks see it.
struct QueryView {
  const float* q;
  const float* w;
  const QueryParams* params;
  // Sorted, k entries. With half_filter, until the query's end, a row's
  // entry holds an upper bound of its cost (HalfFilterLimits::upper), so the
  // k-th entry is still at least the k-th best cost: every bound compared
  // with it prunes only rows that cannot enter the result.
  std::span<Match> best;
  std::vector<DeferredRow>* deferred = nullptr;  // half_filter: this query's rows to re-rank
};

// What every walk needs besides the query.
struct WalkContext {
  const Database& db;
  const ClusterSearch::Layout& l;
  const ClusterSearchOptions& options;
  detail::TileArrays tiles;
  detail::HalfBoxArrays tile_boxes;
  detail::HalfBoxArrays span_boxes;
  detail::HalfTileArrays half_tiles;
};

// Whether query `params` may take a frame from cluster c (flags and tags).
bool cluster_eligible(const ClusterSearch::Layout& l, const QueryParams& params, std::uint32_t c);

// The group level applies (more than one group, box bounds on).
bool use_groups(const WalkContext& x);
// nprobe finds its probed set through the groups (probe_bounds()).
bool probe_by_group(const WalkContext& x);

// nprobe through the groups: the probed clusters' bounds (cluster_bounds.cpp).
std::uint32_t probe_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, std::uint8_t* done);

// Bounds before the seed, and the seed; see cluster_bounds.cpp.
std::uint32_t exact_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, float* group_bound,
                           std::uint8_t* done, BoundState& state);

// The rest of exact mode's bounds once the seed has tightened the k-th best.
void complete_bounds(const WalkContext& x, const QueryView& v, const float* group_bound, std::uint8_t* done,
                     BoundState state, float* bound);

// The clusters still to visit, sorted by (bound, cluster), appended to `out`.
void collect_candidates(const ClusterSearch::Layout& l, const float* bound, BoundState state,
                        const std::uint8_t* done, std::uint32_t skip, float threshold,
                        std::vector<ClusterBound>& staging, std::vector<ClusterBound>& out);

}  // namespace cluster_walk
}  // namespace mmvk
