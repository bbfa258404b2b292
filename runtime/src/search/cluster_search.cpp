#include "mmvk/search/cluster_search.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include "search/cluster_groups.hpp"
#include "search/cluster_search_state.hpp"
#include "search/tile_store.hpp"
#include "search/top_k.hpp"

namespace mmvk {

using namespace cluster_walk;  // this file and cluster_bounds.cpp share it

namespace {

// Tiles per cluster (its members in frame order fill them; the last is
// padded with kNoFrame), which clusters can never give a candidate, and
// where each cluster's tile boxes start.
void place_clusters(ClusterSearch::Layout& l, std::uint32_t& tile_packs) {
  const ClusterTable& t = l.table;
  const std::uint32_t k = t.cluster_count;
  l.tile_offsets.assign(k + 1, 0);
  l.tile_box_pack.assign(k, 0);
  l.never_candidate.resize(k);
  tile_packs = 0;
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
  l.frame.assign(std::size_t{l.tile_offsets[k]} * kLanes, kNoFrame);
  for (std::uint32_t c = 0; c < k; ++c) {
    std::copy(t.members.begin() + t.offsets[c], t.members.begin() + t.offsets[c + 1],
              l.frame.begin() + std::ptrdiff_t{l.tile_offsets[c]} * kLanes);
  }
}

// A box per tile (halves, rounded outward), and the rows each tile holds.
void build_tile_boxes(ClusterSearch::Layout& l, const Database& database, std::uint32_t tile_packs) {
  const std::uint32_t k = l.table.cluster_count;
  detail::BoxPacks tile_boxes(tile_packs, l.dims);
  l.tile_rows.assign(l.tile_offsets[k], 0);
  for (std::uint32_t c = 0; c < k; ++c) {
    for (std::uint32_t tile = l.tile_offsets[c]; tile < l.tile_offsets[c + 1]; ++tile) {
      detail::BoxAccumulator box(l.dims);
      for (std::size_t slot = std::size_t{tile} * kLanes; slot < (std::size_t{tile} + 1) * kLanes; ++slot) {
        const std::uint32_t f = l.frame[slot];
        if (f == kNoFrame) continue;
        box.add_row(database.row(f), database.frame_multiplier()[f], database.frame_bias()[f]);
        ++l.tile_rows[tile];
      }
      tile_boxes.set(std::size_t{l.tile_box_pack[c]} * kLanes + (tile - l.tile_offsets[c]), box);
    }
  }
  l.tile_boxes = detail::HalfBoxPacks(std::move(tile_boxes));
}

// A box per span of 16 tiles (halves, rounded outward), for clusters of
// more than one span.
void build_span_boxes(ClusterSearch::Layout& l, const Database& database) {
  const std::uint32_t k = l.table.cluster_count;
  l.span_box_pack.assign(k, kNoCluster);
  std::uint32_t span_packs = 0;
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::size_t spans = packs_of(l.tile_offsets[c + 1] - l.tile_offsets[c]);
    if (spans < 2) continue;
    l.span_box_pack[c] = span_packs;
    span_packs += static_cast<std::uint32_t>(packs_of(spans));
  }
  detail::BoxPacks span_boxes(span_packs, l.dims);
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
      span_boxes.set(std::size_t{l.span_box_pack[c]} * kLanes + span, box);
    }
  }
  l.span_boxes = detail::HalfBoxPacks(std::move(span_boxes));
}

// The clusters' boxes and centroids, from the (reordered) table.
void build_cluster_boxes(ClusterSearch::Layout& l) {
  const ClusterTable& t = l.table;
  const std::uint32_t k = t.cluster_count;
  const std::size_t cluster_packs = packs_of(k);
  l.cluster_boxes = detail::BoxPacks(cluster_packs, l.dims);
  l.centroids = detail::BoxPacks(cluster_packs, l.dims);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::size_t at = std::size_t{c} * l.dims;
    l.cluster_boxes.set(c, t.box_min.data() + at, t.box_max.data() + at, t.min_multiplier[c], t.min_bias[c]);
    l.centroids.set(c, t.centroids.data() + at, t.centroids.data() + at, 1.0f, 0.0f);
  }
}

// The group level: per group of kGroupClusters consecutive (internal)
// clusters, the box over its candidate clusters' boxes and the box over
// their centroids.
void build_group_boxes(ClusterSearch::Layout& l) {
  const ClusterTable& t = l.table;
  const std::uint32_t k = t.cluster_count;
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
}

// Per-thread scratch, sized once so that searches allocate nothing.
void size_scratch(ClusterSearch::Layout& l, unsigned threads) {
  const std::uint32_t k = l.table.cluster_count;
  const std::size_t cluster_packs = packs_of(k);
  const std::size_t group_packs = packs_of(l.group_count);
  l.scratch.resize(threads);
  for (Scratch& s : l.scratch) {
    s.order.reserve(k);
    s.bound.resize(cluster_packs * kLanes);
    s.distance.resize(cluster_packs * kLanes);
    s.tile_bound.resize(packs_of(l.max_cluster_tiles) * kLanes);
    s.span_bound.resize(packs_of(packs_of(l.max_cluster_tiles)) * kLanes);
    s.passing.resize(l.max_cluster_tiles);
    s.staging.resize(k);
    s.batch_bound.resize(kSubBatch * cluster_packs * kLanes);
    s.group_bound.resize(group_packs * kLanes);
    s.group_distance.resize(group_packs * kLanes);
    s.batch_group_bound.resize(kSubBatch * group_packs * kLanes);
    s.seed.resize(kSubBatch);
    s.group_done.resize(l.group_count);
    s.batch_group_done.resize(kSubBatch * l.group_count);
    s.bound_state.resize(kSubBatch);
    s.cursor.resize(kSubBatch);
    s.candidate_end.resize(kSubBatch);
    // Rows deferred per query: about 70 on the Bandai volume set; grown
    // past this once if needed, and kept.
    s.deferred.resize(kSubBatch);
    for (std::vector<DeferredRow>& rows : s.deferred) rows.reserve(l.half.tiles != 0 ? 256 : 0);
  }
}

}  // namespace

Result<std::unique_ptr<ClusterSearch>> ClusterSearch::create(const Database& database, const ClusterTable& table,
                                                            ThreadPool& pool, ClusterSearchOptions options) {
  MMVK_TRY(validate_cluster_table(table, database));
  auto layout = std::make_unique<Layout>();
  Layout& l = *layout;
  // Clusters are held in an internal order that puts nearby centroids in
  // one group; results and counters speak of the table's ids.
  l.table_id = detail::group_order(table, kGroupClusters);
  l.internal_id.resize(table.cluster_count);
  for (std::uint32_t c = 0; c < table.cluster_count; ++c) l.internal_id[l.table_id[c]] = c;
  l.table = detail::reorder_clusters(table, l.table_id);
  l.dims = database.dims();
  if (!detail::select_kernels(options.kernels, l.kernels)) {
    return make_error("cluster search: this CPU cannot run the requested kernels (ClusterSearchOptions::kernels)");
  }
  std::uint32_t tile_packs = 0;
  place_clusters(l, tile_packs);
  if (options.half_filter) {
    // The float tiles would never be read: the filter reads the half copy
    // and the exact stage the database's rows. Only their channel ends.
    l.rows.dims = l.dims;
    l.rows.channel_end = detail::channel_ends(database);
    l.half = detail::HalfTileStore::build(database, l.frame, l.tile_offsets);
  } else {
    l.rows = detail::TileStore::build(database, l.frame);
  }
  build_tile_boxes(l, database, tile_packs);
  build_span_boxes(l, database);
  build_cluster_boxes(l);
  build_group_boxes(l);
  size_scratch(l, pool.thread_count());
  return std::unique_ptr<ClusterSearch>(new ClusterSearch(database, pool, options, std::move(layout)));
}

ClusterSearch::ClusterSearch(const Database& database, ThreadPool& pool, ClusterSearchOptions options,
                             std::unique_ptr<Layout> layout)
    : database_(&database), pool_(&pool), options_(options), layout_(std::move(layout)) {}

ClusterSearch::~ClusterSearch() = default;

std::uint32_t ClusterSearch::cluster_count() const { return layout_->table.cluster_count; }
std::string_view ClusterSearch::kernel_name() const { return layout_->kernels.name; }

namespace {

// The bounds of cluster c's `tiles` tiles into s.tile_bound: by the tile
// boxes, or first by their spans (a failing span's tiles get +inf).
void bound_tiles(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t c, std::uint32_t tiles) {
  const ClusterSearch::Layout& l = x.l;
  if (x.options.tile_bound && (!x.options.span_bound || l.span_box_pack[c] == kNoCluster)) {
    // Members are in frame order, so a tile mostly holds neighbouring
    // frames of a clip and its box is tight.
    l.kernels.half_box_bounds(x.tile_boxes, l.tile_box_pack[c], packs_of(tiles), v.q, v.w, s.tile_bound.data());
    s.counters.tiles_checked += tiles;
  } else if (x.options.tile_bound) {
    // Spans of 16 tiles first: the tile bounds of a span whose own bound is
    // above the k-th best are never computed (+inf: skipped below).
    const std::size_t spans = packs_of(tiles);
    l.kernels.half_box_bounds(x.span_boxes, l.span_box_pack[c], packs_of(spans), v.q, v.w, s.span_bound.data());
    const float threshold = v.best.back().cost;
    for (std::size_t span = 0; span < spans;) {
      if (s.span_bound[span] > threshold) {
        std::fill_n(s.tile_bound.data() + span * kLanes, kLanes, std::numeric_limits<float>::infinity());
        ++span;
        continue;
      }
      std::size_t run_end = span + 1;
      while (run_end < spans && !(s.span_bound[run_end] > threshold)) ++run_end;
      l.kernels.half_box_bounds(x.tile_boxes, l.tile_box_pack[c] + span, run_end - span, v.q, v.w,
                                s.tile_bound.data() + span * kLanes);
      s.counters.tiles_checked += (run_end - span) * kLanes;
      span = run_end;
    }
  }
}

// half_filter: the lanes whose half-precision bound passes the k-th best
// are deferred to the query's end (finish_query), and enter the list now
// with an upper bound of their cost. An exact cost reads the row from the
// database (a cache miss: frame order, not cluster order), and most rows
// that pass early are beaten later. While the list is not full (k-th best
// +inf) every lane passes: a tile at a time then, which fills a list of
// k <= 16.
void filter_half_tiles(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t c,
                       detail::HalfFilterLimits& half_limits, const std::uint32_t* chunk, std::uint32_t chunk_size) {
  const ClusterSearch::Layout& l = x.l;
  for (std::uint32_t first = 0; first < chunk_size;) {
    const float threshold = v.best.back().cost;
    const std::uint32_t count = threshold < std::numeric_limits<float>::infinity() ? chunk_size - first : 1;
    l.kernels.half_filter(x.half_tiles, v.q, v.w, chunk + first, half_limits(c, threshold), count,
                          s.masks.data(), s.distances.data());
    s.counters.tiles_filtered += count;
    for (std::uint32_t i = 0; i < count; ++i) {
      for (std::uint32_t mask = s.masks[i]; mask != 0; mask &= mask - 1) {
        const auto lane = static_cast<std::uint32_t>(std::countr_zero(mask));
        const std::uint32_t frame = l.frame[std::size_t{chunk[first + i]} * kLanes + lane];
        const float distance = s.distances[i * kLanes + lane];
        v.deferred->push_back({frame, distance, c});
        ++s.counters.rows_rechecked;
        // As offer_tile_row (the continuing frame is seeded on its own),
        // with the candidate test, a look-up in the frame's tags, only
        // for rows that enter the list; finish_query tests the others.
        const Match entry{frame, half_limits.upper(c, distance)};
        if (!match_less(entry, v.best.back())) continue;
        if (frame == v.params->continuing_frame || !is_candidate(x.db, frame, *v.params)) continue;
        detail::insert_sorted(v.best, entry);
      }
    }
    first += count;
  }
}

// Evaluates the tiles of cluster c whose own bound is at most the k-th best
// (strictly greater is skipped: a member costing exactly the k-th best could
// still win on a lower frame id).
void visit_cluster(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t c) {
  const ClusterSearch::Layout& l = x.l;
  ++s.counters.clusters_visited;
  const std::uint32_t first_tile = l.tile_offsets[c];
  const std::uint32_t tiles = l.tile_offsets[c + 1] - first_tile;
  bound_tiles(x, s, v, c, tiles);
  // Tiles that pass are evaluated kTileChunk (half_filter: kHalfChunk) at a
  // time (the kernel overlaps their sums), against the k-th best from
  // before the chunk.
  std::array<std::uint32_t, std::max(kTileChunk, kHalfChunk)> chunk{};
  std::uint32_t chunk_size = 0;
  const auto evaluate = [&](const std::uint32_t* tiles_to_evaluate, std::uint32_t count) {
    const detail::KernelQuery kernel_query{v.q, v.w, v.best.back().cost};
    const std::size_t hits = l.kernels.evaluate_tiles(x.tiles, &kernel_query, 1, tiles_to_evaluate, count, s.hits.data());
    for (std::size_t h = 0; h < hits; ++h) {
      detail::offer_tile_row(x.db, *v.params, v.best, Match{l.frame[s.hits[h].slot], s.hits[h].cost});
    }
  };
  const bool half_filter = x.options.half_filter;
  detail::HalfFilterLimits half_limits =
      half_filter ? detail::HalfFilterLimits(l.half, l.rows.channel_end, v.w) : detail::HalfFilterLimits{};
  const auto flush = [&] {
    if (half_filter) {
      filter_half_tiles(x, s, v, c, half_limits, chunk.data(), chunk_size);
    } else {
      evaluate(chunk.data(), chunk_size);
    }
    chunk_size = 0;
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
    if (chunk_size == (half_filter ? kHalfChunk : kTileChunk)) flush();
  }
  if (chunk_size != 0) flush();
}

// Seeds the query's (cleared) list with the continuing frame: its cost
// carries continuing_bias (possibly negative), which no cluster bound
// covers, so it is evaluated on its own and skipped by the tiles.
bool seed_continuing(const WalkContext& x, const QueryView& v) {
  const std::uint32_t continuing = v.params->continuing_frame;
  if (continuing == kNoFrame || !is_candidate(x.db, continuing, *v.params)) return false;
  detail::insert_sorted(v.best, Match{continuing, frame_cost(x.db, continuing, {v.q, x.l.dims}, *v.params)});
  return true;
}

void start_query(const WalkContext& x, Scratch& s, const QueryView& v) {
  std::fill(v.best.begin(), v.best.end(), Match{});
  if (v.deferred != nullptr) v.deferred->clear();
  if (seed_continuing(x, v)) ++s.rows;
}

// half_filter: the exact re-rank. The k-th entry of the list (upper bounds)
// is at least the k-th best cost, so every row of the result, and every row
// tied with one, has a half-precision distance within the limit of that
// entry: those rows, and only those, get their exact cost (the reference's
// frame_cost, the bits of the tile kernel) and make the list again, with
// the continuing frame.
void finish_query(const WalkContext& x, Scratch& s, const QueryView& v) {
  if (!x.options.half_filter) return;
  std::vector<DeferredRow>& rows = *v.deferred;
  detail::HalfFilterLimits limits(x.l.half, x.l.rows.channel_end, v.w);
  const float threshold = v.best.back().cost;
  std::size_t kept = 0;
  for (const DeferredRow& row : rows) {
    if (row.distance > limits(row.block, threshold)) continue;
    __builtin_prefetch(x.db.row(row.frame).data());  // scattered rows: all requested before the first is read
    rows[kept++] = row;
  }
  std::fill(v.best.begin(), v.best.end(), Match{});
  seed_continuing(x, v);
  for (std::size_t i = 0; i < kept; ++i) {
    const std::uint32_t frame = rows[i].frame;
    if (frame == v.params->continuing_frame || !is_candidate(x.db, frame, *v.params)) continue;
    detail::insert_sorted(v.best, Match{frame, frame_cost(x.db, frame, {v.q, x.l.dims}, *v.params)});
  }
  s.counters.rows_exact += kept;
  rows.clear();
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
    const auto local = [&](std::uint32_t i) {
      QueryView v = view_of(base + i);
      v.deferred = &s.deferred[i];
      return v;
    };
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
    for (std::uint32_t i = 0; i < n; ++i) finish_query(x, s, local(i));
  }
}

}  // namespace

Status ClusterSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  Layout& l = *layout_;
  const QueryParams default_params;
  const ClusterSearchOptions options = options_;
  const WalkContext x{*database_, l, options, l.rows.arrays(), l.tile_boxes.arrays(l.rows.channel_end),
                      l.span_boxes.arrays(l.rows.channel_end),
                      l.half.arrays(l.rows.channel_end.data())};
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
      QueryView v = view_of(qi);
      v.deferred = &s.deferred[0];
      start_query(x, s, v);
      walk_one(x, s, v);
      finish_query(x, s, v);
    }
  });

  stats_.queries += batch.size;
  for (const Scratch& s : l.scratch) {
    stats_.rows_evaluated += s.rows;
    counters_.clusters_visited += s.counters.clusters_visited;
    counters_.tiles_checked += s.counters.tiles_checked;
    counters_.tiles_filtered += s.counters.tiles_filtered;
    counters_.rows_rechecked += s.counters.rows_rechecked;
    counters_.rows_exact += s.counters.rows_exact;
  }
  return {};
}

}  // namespace mmvk
