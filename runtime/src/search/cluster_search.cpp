#include "mmvk/cluster_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "search/cluster_groups.hpp"
#include "search/tile_store.hpp"
#include "search/top_k.hpp"

namespace mmvk {

namespace {

constexpr std::uint32_t kLanes = detail::kLanes;  // rows per tile, boxes per pack

std::size_t packs_of(std::size_t boxes) { return (boxes + kLanes - 1) / kLanes; }

constexpr std::uint32_t kNoCluster = 0xffffffffu;

// Exact batched mode: queries whose bounds are held at once per thread (their
// bounds take kSubBatch x clusters floats), and the rounds that take one
// candidate cluster per query before the rest are taken at once.
constexpr std::size_t kSubBatch = 512;
constexpr std::uint32_t kRankedRounds = 1;
// Tiles of one cluster handed to the kernel at once.
constexpr std::uint32_t kTileChunk = 4;
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

struct Scratch {
  std::vector<ClusterBound> order;
  std::vector<float> bound, distance;            // [clusters, padded to 16]
  std::vector<float> group_bound, group_distance;  // [groups, padded to 16]
  std::vector<std::uint8_t> group_done;            // [groups]: its cluster bounds are computed
  std::vector<float> tile_bound;                 // [tiles of the largest cluster, padded to 16]
  std::vector<float> span_bound;                 // [spans of the largest cluster, padded to 16]
  std::vector<std::uint32_t> passing;            // [tiles of the largest cluster]
  std::array<detail::LaneHit, kLanes * kTileChunk> hits{};
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

}  // namespace

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
  detail::TileStore rows;
  // The box of each tile's member rows, with their minimum multiplier and
  // bias. A cluster's tile boxes start a pack of their own, so its bounds
  // are whole packs: tile i of cluster c is box tile_box_pack[c] * 16 + i.
  detail::BoxPacks tile_boxes;
  std::vector<std::uint32_t> tile_box_pack;  // [clusters]
  std::vector<std::uint8_t> tile_rows;       // [tiles]: member rows (the rest is padding)
  std::uint32_t max_cluster_tiles = 0;
  // The third level, between clusters and tiles: the box of each span of
  // 16 tiles (one tile-box pack) of a cluster with more than one span,
  // packed like the tile boxes: span j of cluster c is box span_box_pack[c]
  // * 16 + j; kNoCluster for a cluster of one span (its cluster box is it).
  detail::BoxPacks span_boxes;
  std::vector<std::uint32_t> span_box_pack;  // [clusters]
  detail::BoxPacks cluster_boxes;            // box c: the table's box, min_multiplier and min_bias
  // Box c: [centroid, centroid], multiplier 1, bias 0, so its bound is the
  // channel-weighted squared centroid distance.
  detail::BoxPacks centroids;
  // [clusters]: 1 when empty or all members excluded by flags (bytes, not
  // vector<bool>, so the per-query eligibility loop vectorizes).
  std::vector<std::uint8_t> never_candidate;
  std::uint32_t candidate_clusters = 0;      // clusters with never_candidate 0
  std::vector<Scratch> scratch;              // [pool threads]
};

Result<std::unique_ptr<ClusterSearch>> ClusterSearch::create(const Database& database, const ClusterTable& table,
                                                            ThreadPool& pool, ClusterSearchOptions options) {
  MMVK_TRY(validate_cluster_table(table, database));
  auto layout = std::make_unique<Layout>();
  Layout& l = *layout;
  l.table_id = detail::group_order(table, kGroupClusters);
  l.internal_id.resize(table.cluster_count);
  for (std::uint32_t c = 0; c < table.cluster_count; ++c) l.internal_id[l.table_id[c]] = c;
  l.table = detail::reorder_clusters(table, l.table_id);
  l.dims = database.dims();
  const ClusterTable& t = l.table;
  if (!detail::select_kernels(options.kernels, l.kernels)) {
    return make_error("cluster search: this CPU cannot run the requested kernels (ClusterSearchOptions::kernels)");
  }
  const std::uint32_t k = t.cluster_count;
  l.tile_offsets.assign(k + 1, 0);
  l.tile_box_pack.assign(k, 0);
  l.never_candidate.resize(k);
  std::uint32_t tile_packs = 0;
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::uint32_t size = t.offsets[c + 1] - t.offsets[c];
    const std::uint32_t tiles_c = (size + kLanes - 1) / kLanes;
    l.never_candidate[c] = size == 0 || (t.flags_intersection[c] & detail::kNeverCandidate) != 0;
    l.candidate_clusters += l.never_candidate[c] == 0 ? 1u : 0u;
    l.tile_offsets[c + 1] = l.tile_offsets[c] + tiles_c;
    l.tile_box_pack[c] = tile_packs;
    tile_packs += static_cast<std::uint32_t>(packs_of(tiles_c));
    l.max_cluster_tiles = std::max(l.max_cluster_tiles, tiles_c);
  }
  const std::size_t tiles = l.tile_offsets[k];
  l.frame.assign(tiles * kLanes, kNoFrame);
  for (std::uint32_t c = 0; c < k; ++c) {
    std::copy(t.members.begin() + t.offsets[c], t.members.begin() + t.offsets[c + 1],
              l.frame.begin() + std::ptrdiff_t{l.tile_offsets[c]} * kLanes);
  }
  l.rows = detail::TileStore::build(database, l.frame);
  l.tile_boxes = detail::BoxPacks(tile_packs, l.dims);
  l.tile_rows.assign(tiles, 0);
  for (std::uint32_t c = 0; c < k; ++c) {
    for (std::uint32_t tile = l.tile_offsets[c]; tile < l.tile_offsets[c + 1]; ++tile) {
      detail::BoxAccumulator box(l.dims);
      for (std::size_t slot = std::size_t{tile} * kLanes; slot < (std::size_t{tile} + 1) * kLanes; ++slot) {
        const std::uint32_t f = l.frame[slot];
        if (f == kNoFrame) continue;
        box.add_row(database.row(f), database.frame_multiplier()[f], database.frame_bias()[f]);
        ++l.tile_rows[tile];
      }
      l.tile_boxes.set(std::size_t{l.tile_box_pack[c]} * kLanes + (tile - l.tile_offsets[c]), box);
    }
  }
  l.span_box_pack.assign(k, kNoCluster);
  std::uint32_t span_packs = 0;
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::size_t spans = packs_of(l.tile_offsets[c + 1] - l.tile_offsets[c]);
    if (spans < 2) continue;
    l.span_box_pack[c] = span_packs;
    span_packs += static_cast<std::uint32_t>(packs_of(spans));
  }
  l.span_boxes = detail::BoxPacks(span_packs, l.dims);
  for (std::uint32_t c = 0; c < k; ++c) {
    if (l.span_box_pack[c] == kNoCluster) continue;
    const std::size_t first_slot = std::size_t{l.tile_offsets[c]} * kLanes;
    const std::size_t end_slot = std::size_t{l.tile_offsets[c + 1]} * kLanes;
    for (std::size_t span = 0; first_slot + span * kLanes * kLanes < end_slot; ++span) {
      detail::BoxAccumulator box(l.dims);
      const std::size_t span_end = std::min(end_slot, first_slot + (span + 1) * kLanes * kLanes);
      for (std::size_t slot = first_slot + span * kLanes * kLanes; slot < span_end; ++slot) {
        const std::uint32_t f = l.frame[slot];
        if (f != kNoFrame) box.add_row(database.row(f), database.frame_multiplier()[f], database.frame_bias()[f]);
      }
      l.span_boxes.set(std::size_t{l.span_box_pack[c]} * kLanes + span, box);
    }
  }
  const std::size_t cluster_packs = packs_of(k);
  l.cluster_boxes = detail::BoxPacks(cluster_packs, l.dims);
  l.centroids = detail::BoxPacks(cluster_packs, l.dims);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::size_t at = std::size_t{c} * l.dims;
    l.cluster_boxes.set(c, t.box_min.data() + at, t.box_max.data() + at, t.min_multiplier[c],
                        t.min_bias[c]);
    l.centroids.set(c, t.centroids.data() + at, t.centroids.data() + at, 1.0f, 0.0f);
  }
  l.group_count = static_cast<std::uint32_t>((k + kGroupClusters - 1) / kGroupClusters);
  l.group_boxes = detail::BoxPacks(packs_of(l.group_count), l.dims);
  l.group_centroids = detail::BoxPacks(packs_of(l.group_count), l.dims);
  l.group_has_candidate.assign(l.group_count, 0);
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    detail::BoxAccumulator box(l.dims);
    detail::BoxAccumulator centres(l.dims);
    for (std::uint32_t c = g * kGroupClusters; c < std::min(k, (g + 1) * kGroupClusters); ++c) {
      if (l.never_candidate[c]) continue;
      const std::size_t at = std::size_t{c} * l.dims;
      box.add(t.box_min.data() + at, t.box_max.data() + at, t.min_multiplier[c], t.min_bias[c]);
      centres.add(t.centroids.data() + at, t.centroids.data() + at, 1.0f, 0.0f);
    }
    l.group_has_candidate[g] = box.empty ? 0 : 1;
    l.group_boxes.set(g, box);
    l.group_centroids.set(g, centres);
  }
  l.scratch.resize(pool.thread_count());
  for (Scratch& s : l.scratch) {
    s.order.reserve(k);
    s.bound.resize(cluster_packs * kLanes);
    s.distance.resize(cluster_packs * kLanes);
    s.tile_bound.resize(packs_of(l.max_cluster_tiles) * kLanes);
    s.span_bound.resize(packs_of(packs_of(l.max_cluster_tiles)) * kLanes);
    s.passing.resize(l.max_cluster_tiles);
    s.staging.resize(k);
    s.batch_bound.resize(kSubBatch * cluster_packs * kLanes);
    s.group_bound.resize(packs_of(l.group_count) * kLanes);
    s.group_distance.resize(packs_of(l.group_count) * kLanes);
    s.batch_group_bound.resize(kSubBatch * packs_of(l.group_count) * kLanes);
    s.seed.resize(kSubBatch);
    s.group_done.resize(l.group_count);
    s.batch_group_done.resize(kSubBatch * l.group_count);
    s.bound_state.resize(kSubBatch);
    s.cursor.resize(kSubBatch);
    s.candidate_end.resize(kSubBatch);
  }
  return std::unique_ptr<ClusterSearch>(new ClusterSearch(database, pool, options, std::move(layout)));
}

ClusterSearch::ClusterSearch(const Database& database, ThreadPool& pool, ClusterSearchOptions options,
                             std::unique_ptr<Layout> layout)
    : database_(&database), pool_(&pool), options_(options), layout_(std::move(layout)) {}

ClusterSearch::~ClusterSearch() = default;

std::uint32_t ClusterSearch::cluster_count() const { return layout_->table.cluster_count; }
std::string_view ClusterSearch::kernel_name() const { return layout_->kernels.name; }

namespace {

// One query as the walks see it.
struct QueryView {
  const float* q;
  const float* w;
  const QueryParams* params;
  std::span<Match> best;  // sorted, k entries
};

// What every walk needs besides the query.
struct WalkContext {
  const Database& db;
  const ClusterSearch::Layout& l;
  const ClusterSearchOptions& options;
  detail::TileArrays tiles;
  detail::BoxArrays tile_boxes;
  detail::BoxArrays span_boxes;
};

// Evaluates the tiles of cluster c whose own bound is at most the k-th best
// (strictly greater is skipped: a member costing exactly the k-th best could
// still win on a lower frame id).
void visit_cluster(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t c) {
  const ClusterSearch::Layout& l = x.l;
  ++s.counters.clusters_visited;
  const std::uint32_t first_tile = l.tile_offsets[c];
  const std::uint32_t tiles = l.tile_offsets[c + 1] - first_tile;
  if (x.options.tile_bound && (!x.options.span_bound || l.span_box_pack[c] == kNoCluster)) {
    // Members are in frame order, so a tile mostly holds neighbouring
    // frames of a clip and its box is tight.
    l.kernels.box_bounds(x.tile_boxes, l.tile_box_pack[c], packs_of(tiles), v.q, v.w, s.tile_bound.data());
    s.counters.tiles_checked += tiles;
  } else if (x.options.tile_bound) {
    // Spans of 16 tiles first: the tile bounds of a span whose own bound is
    // above the k-th best are never computed (+inf: skipped below).
    const std::size_t spans = packs_of(tiles);
    l.kernels.box_bounds(x.span_boxes, l.span_box_pack[c], packs_of(spans), v.q, v.w, s.span_bound.data());
    const float threshold = v.best.back().cost;
    for (std::size_t span = 0; span < spans;) {
      if (s.span_bound[span] > threshold) {
        std::fill_n(s.tile_bound.data() + span * kLanes, kLanes, std::numeric_limits<float>::infinity());
        ++span;
        continue;
      }
      std::size_t run_end = span + 1;
      while (run_end < spans && !(s.span_bound[run_end] > threshold)) ++run_end;
      l.kernels.box_bounds(x.tile_boxes, l.tile_box_pack[c] + span, run_end - span, v.q, v.w,
                           s.tile_bound.data() + span * kLanes);
      s.counters.tiles_checked += (run_end - span) * kLanes;
      span = run_end;
    }
  }
  // Tiles that pass are evaluated kTileChunk at a time (the kernel overlaps
  // their sums), against the k-th best from before the chunk.
  std::array<std::uint32_t, kTileChunk> chunk{};
  std::uint32_t chunk_size = 0;
  const auto flush = [&] {
    const detail::KernelQuery kernel_query{v.q, v.w, v.best.back().cost};
    const std::size_t hits = l.kernels.evaluate_tiles(x.tiles, &kernel_query, 1, chunk.data(), chunk_size, s.hits.data());
    chunk_size = 0;
    for (std::size_t h = 0; h < hits; ++h) {
      detail::offer_tile_row(x.db, *v.params, v.best, Match{l.frame[s.hits[h].slot], s.hits[h].cost});
    }
  };
  // The tiles whose bound passes the k-th best from before the walk,
  // compacted without a branch (most tiles fail, in no pattern a predictor
  // learns); each is checked again below as the k-th best tightens.
  std::uint32_t* passing = s.passing.data();
  std::uint32_t passing_count = 0;
  const float threshold_before = v.best.back().cost;
  for (std::uint32_t i = 0; i < tiles; ++i) {
    passing[passing_count] = i;
    passing_count += !x.options.tile_bound || !(s.tile_bound[i] > threshold_before) ? 1u : 0u;
  }
  for (std::uint32_t j = 0; j < passing_count; ++j) {
    const std::uint32_t i = passing[j];
    if (x.options.tile_bound && s.tile_bound[i] > v.best.back().cost) continue;
    const std::uint32_t tile = first_tile + i;
    s.rows += l.tile_rows[tile];
    chunk[chunk_size++] = tile;
    if (chunk_size == kTileChunk) flush();
  }
  if (chunk_size != 0) flush();
}

bool cluster_eligible(const ClusterSearch::Layout& l, const QueryParams& params, std::uint32_t c) {
  const ClusterTable& t = l.table;
  return !l.never_candidate[c] && (t.tag_union[c] & params.require_all) == params.require_all &&
         (t.tag_intersection[c] & params.exclude_any) == 0;
}

// Clears the query's list and seeds it with the continuing frame: its cost
// carries continuing_bias (possibly negative), which no cluster bound
// covers, so it is evaluated on its own and skipped by the tiles.
void start_query(const WalkContext& x, Scratch& s, const QueryView& v) {
  std::fill(v.best.begin(), v.best.end(), Match{});
  const std::uint32_t continuing = v.params->continuing_frame;
  if (continuing != kNoFrame && is_candidate(x.db, continuing, *v.params)) {
    detail::insert_sorted(v.best, Match{continuing, frame_cost(x.db, continuing, {v.q, x.l.dims}, *v.params)});
    ++s.rows;
  }
}

// Rules out (NaN: never <= any threshold) each cluster of bound[first,
// last) that query `params` cannot take a frame from, and turns a bound that
// overflowed to NaN into -inf (it proves nothing: visited first). Returns
// the number of eligible clusters of the range. It runs for every query
// over every cluster, so the common case (no tag rules) is a branch-free
// loop that vectorizes; queries with tag rules take cluster_eligible() per
// cluster.
std::uint32_t mark_ineligible(const ClusterSearch::Layout& l, const QueryParams& params, float* bound,
                              std::uint32_t first, std::uint32_t last) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kMinusInfinity = -std::numeric_limits<float>::infinity();
  // A tag both required and excluded rules out every frame.
  if ((params.require_all & params.exclude_any) != 0) {
    std::fill(bound + first, bound + last, kNaN);
    return 0;
  }
  const std::uint8_t* never = l.never_candidate.data();
  if (params.require_all == 0 && params.exclude_any == 0) {
    // No tag rules (most queries): the table's own eligibility.
    std::uint32_t eligible = 0;
    for (std::uint32_t c = first; c < last; ++c) {
      const float b = std::isnan(bound[c]) ? kMinusInfinity : bound[c];
      bound[c] = never[c] != 0 ? kNaN : b;
      eligible += never[c] == 0 ? 1u : 0u;
    }
    return eligible;
  }
  std::uint32_t eligible = 0;
  for (std::uint32_t c = first; c < last; ++c) {
    const bool ok = cluster_eligible(l, params, c);
    const float b = std::isnan(bound[c]) ? kMinusInfinity : bound[c];
    bound[c] = ok ? b : kNaN;
    eligible += ok ? 1u : 0u;
  }
  return eligible;
}

// The eligible cluster (bound not NaN) with the smallest centroid distance,
// ties to the lower cluster id; kNoCluster when none is eligible. Two
// branch-free passes (the minimum, then its first cluster) rather than one
// branchy one: they run for every query over every cluster. Distances are
// finite or +inf (queries are validated finite); an eligible cluster with a
// NaN distance is taken only when no eligible one has a number.
std::uint32_t nearest_centroid(const float* distance, const float* bound, std::uint32_t clusters) {
  float nearest = std::numeric_limits<float>::infinity();
  for (std::uint32_t c = 0; c < clusters; ++c) {
    const float d = std::isnan(bound[c]) ? std::numeric_limits<float>::infinity() : distance[c];
    nearest = d < nearest ? d : nearest;
  }
  std::uint32_t first_eligible = kNoCluster;
  for (std::uint32_t c = 0; c < clusters; ++c) {
    if (std::isnan(bound[c])) continue;
    if (first_eligible == kNoCluster) first_eligible = c;
    if (distance[c] == nearest) return c;
  }
  return first_eligible;
}

// Lower bounds of every cluster into bound[] (padded to whole
// packs): NaN for a cluster the query rules out (never <= any threshold),
// -inf for a bound that overflowed to NaN (proves nothing: visited first).
// Returns the eligible cluster with the nearest centroid when seeding
// (ties: the lower cluster id), else kNoCluster. In nprobe mode the clusters
// beyond the nprobe nearest centroids are ruled out (NaN) as well.
std::uint32_t all_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  const ClusterTable& t = l.table;
  const std::size_t cluster_packs = packs_of(t.cluster_count);
  if (x.options.box_bound) {
    l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, bound);
  } else {
    std::copy(t.min_bias.begin(), t.min_bias.end(), bound);
  }
  const std::uint32_t eligible = mark_ineligible(l, *v.params, bound, 0, t.cluster_count);
  const bool probing = x.options.nprobe != 0 && x.options.nprobe < eligible;
  if (!probing && (!x.options.seed_nearest || eligible < 2)) return kNoCluster;
  l.kernels.box_bounds(l.centroids.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, s.distance.data());
  if (probing) {
    // nprobe mode: only the nprobe eligible clusters with the nearest
    // centroids (ties: the lower cluster id) stay eligible; the result is
    // the exact best over them, as in the one-query walk.
    s.order.clear();
    for (std::uint32_t c = 0; c < t.cluster_count; ++c) {
      if (!std::isnan(bound[c])) s.order.push_back({s.distance[c], l.table_id[c], 0.0f});
    }
    std::nth_element(s.order.begin(), s.order.begin() + x.options.nprobe, s.order.end());
    for (auto it = s.order.begin() + x.options.nprobe; it != s.order.end(); ++it) {
      bound[l.internal_id[it->cluster]] = std::numeric_limits<float>::quiet_NaN();
    }
  }
  return nearest_centroid(s.distance.data(), bound, t.cluster_count);
}

// The clusters [first, last) of group g.
std::uint32_t group_first(std::uint32_t g) { return g * kGroupClusters; }
std::uint32_t group_last(const ClusterSearch::Layout& l, std::uint32_t g) {
  return std::min(l.table.cluster_count, (g + 1) * kGroupClusters);
}

// The cluster bounds of group g into bound[], ineligible ones ruled out.
// Returns the number of eligible clusters.
std::uint32_t group_cluster_bounds(const WalkContext& x, const QueryView& v, std::uint32_t g, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  const std::uint32_t first = group_first(g);
  const std::uint32_t last = group_last(l, g);
  const std::size_t first_pack = first / kLanes;
  l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), first_pack, packs_of(last) - first_pack, v.q, v.w,
                       bound + first);
  return mark_ineligible(l, *v.params, bound, first, last);
}

// The cluster bounds of group g (group_cluster_bounds) and, when one is
// eligible, its centroid distances into s.distance. Returns the number of
// eligible clusters.
std::uint32_t examine_group(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t g, float* bound) {
  const std::uint32_t eligible = group_cluster_bounds(x, v, g, bound);
  if (eligible == 0) return 0;
  const std::uint32_t first = group_first(g);
  const std::size_t first_pack = first / kLanes;
  x.l.kernels.box_bounds(x.l.centroids.arrays(x.l.rows.channel_end), first_pack,
                         packs_of(group_last(x.l, g)) - first_pack, v.q, v.w, s.distance.data() + first);
  return eligible;
}

// The group not done with the smallest group_distance (the first of equal
// ones, a NaN only when no number is left), kNoCluster when all are done.
std::uint32_t nearest_open_group(const ClusterSearch::Layout& l, const float* group_distance, const std::uint8_t* done) {
  std::uint32_t next = kNoCluster;
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (!done[g] && (next == kNoCluster || group_distance[g] < group_distance[next])) next = g;
  }
  return next;
}

// nprobe mode with the group level: the same probed set as all_bounds()
// (the nprobe eligible clusters with the nearest centroids, ties to the
// caller's lower id) without ranking every centroid. Groups are examined in
// order of the bound of their centroids' box, which is at most any member's
// distance, until that bound is above the nprobe-th nearest distance found
// (equal: examined, it may hold a tie with a lower id); their cluster bounds
// and centroid distances are computed, and a max-heap keeps the nprobe
// nearest; the examined groups are marked done, and within them every
// cluster but the probed ones is ruled out (NaN). Leaves the probed
// clusters in s.order, nearest first (the caller's ids in .cluster, the
// lower bounds in .lower), and returns the nearest (kNoCluster when none is
// eligible).
std::uint32_t probe_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, std::uint8_t* done) {
  const ClusterSearch::Layout& l = x.l;
  const std::uint32_t nprobe = x.options.nprobe;
  const std::size_t group_packs = packs_of(l.group_count);
  float* group_distance = s.group_distance.data();
  l.kernels.box_bounds(l.group_centroids.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_distance);
  for (std::uint32_t g = 0; g < l.group_count; ++g) done[g] = l.group_has_candidate[g] ? 0 : 1;
  std::vector<ClusterBound>& heap = s.order;  // max-heap by (distance, caller's id): the farthest on top
  heap.clear();
  for (;;) {
    const std::uint32_t next = nearest_open_group(l, group_distance, done);
    if (next == kNoCluster || (heap.size() == nprobe && group_distance[next] > heap.front().bound)) break;
    done[next] = 1;
    if (examine_group(x, s, v, next, bound) == 0) continue;
    const std::uint32_t first = group_first(next);
    const std::uint32_t last = group_last(l, next);
    for (std::uint32_t c = first; c < last; ++c) {
      if (std::isnan(bound[c])) continue;
      const ClusterBound candidate{s.distance[c], l.table_id[c], bound[c]};
      if (heap.size() < nprobe) {
        heap.push_back(candidate);
        std::push_heap(heap.begin(), heap.end());
      } else if (candidate < heap.front()) {
        std::pop_heap(heap.begin(), heap.end());
        heap.back() = candidate;
        std::push_heap(heap.begin(), heap.end());
      }
    }
  }
  std::sort_heap(heap.begin(), heap.end());
  // Only the probed clusters keep their bounds (carried in .lower); the
  // groups left unexamined (done 0) are never read.
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (done[g] && l.group_has_candidate[g]) {
      std::fill(bound + group_first(g), bound + group_last(l, g), std::numeric_limits<float>::quiet_NaN());
    }
  }
  for (const ClusterBound& b : heap) bound[l.internal_id[b.cluster]] = b.lower;
  return heap.empty() ? kNoCluster : l.internal_id[heap.front().cluster];
}

// The group level applies (more than one group, box bounds on).
bool use_groups(const WalkContext& x) { return x.options.box_bound && x.l.group_count > 1; }

// nprobe takes probe_bounds() up to a group's worth of probes: beyond that
// it examines most groups, and ranking every centroid at once was cheaper
// (volume set, 646 clusters: nprobe 1 and 16 took 26% and 11% less CPU
// time, nprobe 64 10% more).
bool probe_by_group(const WalkContext& x) {
  return x.options.nprobe != 0 && x.options.nprobe <= kGroupClusters && use_groups(x);
}

// Exact mode's bounds before the seed is visited. With the group level (box
// bounds and seeding on, more than one group; state Partial): the group
// bounds into group_bound[], and the seed, the eligible cluster with the
// nearest centroid (as all_bounds(), up to ties), found by visiting the
// groups in order of the bound of their centroids' box until that bound is
// above the nearest centroid found; the cluster bounds of those groups are
// computed (done[g] = 1), the rest is left to complete_bounds(), once the
// seed has tightened the k-th best. nprobe through the groups:
// probe_bounds() (state Probed). Otherwise every bound, as all_bounds()
// (state All).
std::uint32_t exact_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, float* group_bound,
                           std::uint8_t* done, BoundState& state) {
  const ClusterSearch::Layout& l = x.l;
  if (probe_by_group(x)) {
    state = BoundState::Probed;
    return probe_bounds(x, s, v, bound, done);
  }
  state = BoundState::All;
  if (x.options.nprobe != 0 || !x.options.seed_nearest || !use_groups(x)) return all_bounds(x, s, v, bound);
  state = BoundState::Partial;
  const std::size_t group_packs = packs_of(l.group_count);
  l.kernels.box_bounds(l.group_boxes.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_bound);
  float* group_distance = s.group_distance.data();
  l.kernels.box_bounds(l.group_centroids.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_distance);
  for (std::uint32_t g = 0; g < l.group_count; ++g) done[g] = l.group_has_candidate[g] ? 0 : 1;
  std::uint32_t seed = kNoCluster;
  float nearest = std::numeric_limits<float>::infinity();
  for (;;) {
    const std::uint32_t next = nearest_open_group(l, group_distance, done);
    // A distance (or its group's lower bound) may be +inf or NaN: such
    // groups are only examined while no seed is found.
    if (next == kNoCluster || (seed != kNoCluster && !(group_distance[next] < nearest))) break;
    done[next] = 1;
    if (examine_group(x, s, v, next, bound) == 0) continue;
    const std::uint32_t first = group_first(next);
    const std::uint32_t last = group_last(l, next);
    const std::uint32_t in_group = nearest_centroid(s.distance.data() + first, bound + first, last - first);
    if (seed == kNoCluster || s.distance[first + in_group] < nearest) {
      seed = first + in_group;
      nearest = s.distance[seed];
    }
  }
  return seed;
}

// Exact mode after the seed (state Partial): the bounds of the clusters of
// the groups not done whose group bound is at most the k-th best, marked
// done. A group left out has its bound above a finite k-th best, which only
// falls, so none of its clusters could be visited.
void complete_bounds(const WalkContext& x, const QueryView& v, const float* group_bound, std::uint8_t* done,
                     BoundState state, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  if (state != BoundState::Partial) return;
  const float threshold = v.best.back().cost;
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (done[g] || group_bound[g] > threshold) continue;
    group_cluster_bounds(x, v, g, bound);
    done[g] = 1;
  }
}

// Appends the clusters other than `skip` whose bound is at most `threshold`,
// sorted by (bound, cluster): over every cluster (state All) or over the
// groups done that hold candidates. They are compacted into `staging` (one
// slot per cluster) without a branch first: this runs for every query over
// every cluster, and which clusters pass follows no pattern a predictor
// learns.
void collect_candidates(const ClusterSearch::Layout& l, const float* bound, BoundState state,
                        const std::uint8_t* done, std::uint32_t skip, float threshold,
                        std::vector<ClusterBound>& staging, std::vector<ClusterBound>& out) {
  ClusterBound* passing = staging.data();
  std::size_t count = 0;
  const auto scan = [&](std::uint32_t first, std::uint32_t last) {
    for (std::uint32_t c = first; c < last; ++c) {
      passing[count] = {bound[c], c, 0.0f};
      count += c != skip && bound[c] <= threshold ? 1u : 0u;
    }
  };
  if (state == BoundState::All) {
    scan(0, l.table.cluster_count);
  } else {
    for (std::uint32_t g = 0; g < l.group_count; ++g) {
      if (done[g] && l.group_has_candidate[g]) scan(group_first(g), group_last(l, g));
    }
  }
  std::sort(passing, passing + count);
  out.insert(out.end(), passing, passing + count);
}

// The per-query walk: one query's clusters in order, with no batch
// bookkeeping (batch_by_cluster off, and a thread's share of a small batch).
void walk_one(const WalkContext& x, Scratch& s, const QueryView& v) {
  const ClusterSearch::Layout& l = x.l;
  const ClusterTable& t = l.table;
  const ClusterSearchOptions& options = x.options;
  const std::span<Match> best = v.best;
  const std::size_t k = best.size();
  float* bound = s.bound.data();
  if (probe_by_group(x)) {
    // The probed clusters nearest first (the most likely home of the answer,
    // so the k-th best tightens early); one whose lower bound is above the
    // k-th best is skipped, which never changes the result.
    probe_bounds(x, s, v, bound, s.group_done.data());
    for (const ClusterBound& b : s.order) {
      if (b.lower > best[k - 1].cost) continue;
      visit_cluster(x, s, v, l.internal_id[b.cluster]);
    }
    return;
  }
  if (options.nprobe != 0) {
    s.order.clear();
    // A tag both required and excluded rules out every frame.
    const bool contradictory = (v.params->require_all & v.params->exclude_any) != 0;
    for (std::uint32_t c = 0; c < t.cluster_count && !contradictory; ++c) {
      if (cluster_eligible(l, *v.params, c)) s.order.push_back({0.0f, c, 0.0f});
    }
    if (options.nprobe < s.order.size()) {
      // The nprobe nearest centroids (channel-weighted squared distances, a
      // box bound of the zero-size boxes [centroid, centroid] with unit
      // multipliers), nearest first (the most likely home of the answer, so
      // the k-th best tightens early; ties: the caller's cluster id); a
      // probed cluster whose lower bound is above the k-th best is skipped,
      // which never changes the result.
      const std::size_t cluster_packs = packs_of(t.cluster_count);
      l.kernels.box_bounds(l.centroids.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, s.distance.data());
      if (options.box_bound) {
        l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, bound);
      } else {
        std::copy(t.min_bias.begin(), t.min_bias.end(), bound);
      }
      for (ClusterBound& b : s.order) {
        b.lower = bound[b.cluster];
        b.bound = s.distance[b.cluster];
        b.cluster = l.table_id[b.cluster];
      }
      std::nth_element(s.order.begin(), s.order.begin() + options.nprobe, s.order.end());
      s.order.resize(options.nprobe);
      std::sort(s.order.begin(), s.order.end());
      for (const ClusterBound& b : s.order) {
        if (b.lower > best[k - 1].cost) continue;
        visit_cluster(x, s, v, l.internal_id[b.cluster]);
      }
      return;
    }
  }
  // Exact (or nprobe covering every eligible cluster): the seed cluster
  // first, to tighten the k-th best early, then every cluster in
  // lower-bound order until the next bound is above the k-th best.
  BoundState state = BoundState::All;
  const std::uint32_t seed = exact_bounds(x, s, v, bound, s.group_bound.data(), s.group_done.data(), state);
  if (seed != kNoCluster && bound[seed] <= best[k - 1].cost) visit_cluster(x, s, v, seed);
  complete_bounds(x, v, s.group_bound.data(), s.group_done.data(), state, bound);
  s.order.clear();
  collect_candidates(l, bound, state, s.group_done.data(), seed, best[k - 1].cost, s.staging, s.order);
  for (const ClusterBound& b : s.order) {
    if (b.bound > best[k - 1].cost) break;
    visit_cluster(x, s, v, b.cluster);
  }
}

// Visits the (cluster, query) pairs grouped by cluster, so a cluster's tiles
// and tile boxes are loaded once for every query of the sub-batch that
// visits it, and stay in cache between those queries. A pair is skipped when
// the cluster's bound has risen above the query's k-th best meanwhile.
// Buckets go in the caller's cluster order, not the internal one: the
// internal order sweeps space (groups of nearby centroids), so a query's
// clusters would come far side first for many queries (49.4 clusters
// visited per query against 47.4 on the volume set).
template <class ViewOf>
void visit_grouped(const WalkContext& x, Scratch& s, const ViewOf& view_of) {
  const std::uint32_t clusters = x.l.table.cluster_count;
  const std::uint32_t* bucket_of = x.l.table_id.data();
  s.bucket_start.assign(clusters + 1, 0);
  for (const VisitPair& p : s.pairs) ++s.bucket_start[bucket_of[p.cluster] + 1];
  for (std::uint32_t c = 0; c < clusters; ++c) s.bucket_start[c + 1] += s.bucket_start[c];
  s.bucketed.resize(s.pairs.size());
  s.bucket_fill.assign(s.bucket_start.begin(), s.bucket_start.end() - 1);
  for (const VisitPair& p : s.pairs) s.bucketed[s.bucket_fill[bucket_of[p.cluster]]++] = p;
  for (const VisitPair& p : s.bucketed) {
    const QueryView v = view_of(p.query);
    if (p.bound <= v.best.back().cost) visit_cluster(x, s, v, p.cluster);
  }
}

// Exact mode over queries [first, last), in sub-batches: bounds and seeds per
// query (exact_bounds), then the seed clusters grouped by cluster, then the
// rest of each query's bounds (complete_bounds) and its remaining
// candidates (bound <= its k-th best after the seed) in rounds:
// the next candidate of every query per round for the first rounds (the
// most promising cluster first, as in the one-query walk), then all the
// rest at once, each round grouped by cluster.
template <class ViewOf>
void walk_batched(const WalkContext& x, Scratch& s, const ViewOf& view_of, std::size_t first, std::size_t last) {
  const std::uint32_t clusters = x.l.table.cluster_count;
  const std::size_t stride = packs_of(clusters) * kLanes;
  const std::size_t group_stride = packs_of(x.l.group_count) * kLanes;
  for (std::size_t base = first; base < last; base += kSubBatch) {
    const std::uint32_t n = static_cast<std::uint32_t>(std::min(kSubBatch, last - base));
    const auto local = [&](std::uint32_t i) { return view_of(base + i); };
    s.pairs.clear();
    for (std::uint32_t i = 0; i < n; ++i) {
      const QueryView v = local(i);
      start_query(x, s, v);
      float* bound = s.batch_bound.data() + i * stride;
      s.seed[i] = exact_bounds(x, s, v, bound, s.batch_group_bound.data() + i * group_stride,
                               s.batch_group_done.data() + std::size_t{i} * x.l.group_count, s.bound_state[i]);
      if (s.seed[i] != kNoCluster && bound[s.seed[i]] <= v.best.back().cost) {
        s.pairs.push_back({s.seed[i], i, bound[s.seed[i]]});
      }
    }
    visit_grouped(x, s, local);

    s.candidates.clear();
    for (std::uint32_t i = 0; i < n; ++i) {
      s.candidate_end[i] = static_cast<std::uint32_t>(s.candidates.size());  // this query's begin, for now
      std::uint8_t* done = s.batch_group_done.data() + std::size_t{i} * x.l.group_count;
      float* bound = s.batch_bound.data() + i * stride;
      complete_bounds(x, local(i), s.batch_group_bound.data() + i * group_stride, done, s.bound_state[i], bound);
      collect_candidates(x.l, bound, s.bound_state[i], done, s.seed[i], local(i).best.back().cost, s.staging,
                         s.candidates);
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      s.cursor[i] = s.candidate_end[i];
      s.candidate_end[i] = i + 1 < n ? s.candidate_end[i + 1] : static_cast<std::uint32_t>(s.candidates.size());
    }
    for (std::uint32_t round = 0;; ++round) {
      const std::size_t take = round < kRankedRounds ? 1 : s.candidates.size();
      s.pairs.clear();
      for (std::uint32_t i = 0; i < n; ++i) {
        const float threshold = local(i).best.back().cost;
        for (std::size_t taken = 0; taken < take && s.cursor[i] < s.candidate_end[i]; ++taken) {
          const ClusterBound& b = s.candidates[s.cursor[i]++];
          if (!(b.bound <= threshold)) {
            s.cursor[i] = s.candidate_end[i];  // sorted: the rest are above it too
            break;
          }
          s.pairs.push_back({b.cluster, i, b.bound});
        }
      }
      if (s.pairs.empty()) break;
      visit_grouped(x, s, local);
    }
  }
}

}  // namespace

Status ClusterSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  Layout& l = *layout_;
  const QueryParams default_params;
  const ClusterSearchOptions options = options_;
  const WalkContext x{*database_, l, options, l.rows.arrays(), l.tile_boxes.arrays(l.rows.channel_end),
                      l.span_boxes.arrays(l.rows.channel_end)};
  for (Scratch& s : l.scratch) {
    s.rows = 0;
    s.counters = {};
  }
  const auto view_of = [&](std::size_t qi) {
    const QueryParams& params = batch.params.empty() ? default_params : batch.params[qi];
    return QueryView{batch.features.data() + qi * l.dims, params.channel_weights.data(), &params, out.subspan(qi * k, k)};
  };
  pool_->parallel_for(batch.size, [&](std::size_t first, std::size_t last, unsigned thread) {
    Scratch& s = l.scratch[thread];
    if (options.batch_by_cluster && last - first > kOneQueryShare) {
      walk_batched(x, s, view_of, first, last);
      return;
    }
    for (std::size_t qi = first; qi < last; ++qi) {
      const QueryView v = view_of(qi);
      start_query(x, s, v);
      walk_one(x, s, v);
    }
  });

  stats_.queries += batch.size;
  for (const Scratch& s : l.scratch) {
    stats_.rows_evaluated += s.rows;
    counters_.clusters_visited += s.counters.clusters_visited;
    counters_.tiles_checked += s.counters.tiles_checked;
  }
  return {};
}

}  // namespace mmvk
