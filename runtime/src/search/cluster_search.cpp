#include "mmvk/cluster_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "search/tile_store.hpp"
#include "search/top_k.hpp"

namespace mmvk {

namespace {

constexpr std::uint32_t kLanes = detail::kLanes;  // rows per tile, boxes per pack

std::size_t packs_of(std::size_t boxes) { return (boxes + kLanes - 1) / kLanes; }

constexpr std::uint32_t kNoCluster = 0xffffffffu;

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

struct Scratch {
  std::vector<ClusterBound> order;
  std::vector<float> bound, distance;            // [clusters, padded to 16]
  std::vector<float> tile_bound;                 // [tiles of the largest cluster, padded to 16]
  std::vector<double> radius_sum, radius_total;  // [clusters]
  std::array<detail::LaneHit, kLanes> hits{};
  std::uint64_t rows = 0;
  ClusterSearchCounters counters;
};

}  // namespace

struct ClusterSearch::Layout {
  ClusterTable table;
  std::uint32_t dims = 0;
  std::uint32_t channels = 0;
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
  detail::BoxPacks cluster_boxes;            // box c: the table's box, min_multiplier and min_bias
  // Box c: [centroid, centroid], multiplier 1, bias 0, so its bound is the
  // channel-weighted squared centroid distance.
  detail::BoxPacks centroids;
  std::vector<float> radius_t;               // [channels x clusters]
  std::vector<bool> never_candidate;         // [clusters]: empty or all members excluded by flags
  double radius_margin = 0.0;
  std::vector<Scratch> scratch;              // [pool threads]
};

Result<std::unique_ptr<ClusterSearch>> ClusterSearch::create(const Database& database, const ClusterTable& table,
                                                            ThreadPool& pool, ClusterSearchOptions options) {
  MMVK_TRY(validate_cluster_table(table, database));
  auto layout = std::make_unique<Layout>();
  Layout& l = *layout;
  l.table = table;
  l.dims = database.dims();
  l.channels = static_cast<std::uint32_t>(database.schema().channels.size());
  l.kernels = detail::select_kernels(options.baseline_kernels);
  const std::uint32_t k = table.cluster_count;
  l.tile_offsets.assign(k + 1, 0);
  l.tile_box_pack.assign(k, 0);
  l.never_candidate.resize(k);
  std::uint32_t tile_packs = 0;
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::uint32_t size = table.offsets[c + 1] - table.offsets[c];
    const std::uint32_t tiles_c = (size + kLanes - 1) / kLanes;
    l.never_candidate[c] = size == 0 || (table.flags_intersection[c] & detail::kNeverCandidate) != 0;
    l.tile_offsets[c + 1] = l.tile_offsets[c] + tiles_c;
    l.tile_box_pack[c] = tile_packs;
    tile_packs += static_cast<std::uint32_t>(packs_of(tiles_c));
    l.max_cluster_tiles = std::max(l.max_cluster_tiles, tiles_c);
  }
  const std::size_t tiles = l.tile_offsets[k];
  l.frame.assign(tiles * kLanes, kNoFrame);
  for (std::uint32_t c = 0; c < k; ++c) {
    std::copy(table.members.begin() + table.offsets[c], table.members.begin() + table.offsets[c + 1],
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
  // Radius-bound margin. For a member row x, the real cost evaluation
  // computes s_ch = fl-sum of fl(fl(x_d - q_d)^2) over n_ch dims: each term
  // is >= its real value times (1-u)^2 (u = 2^-24, round to nearest), and
  // summing n_ch non-negative terms loses at most a factor (1-u)^n_ch. The
  // weighting, the C channel additions and the multiplier lose at most
  // (1-u)^(C+2). So fl(multiplier * total) >= multiplier * sum_ch w_ch S_ch *
  // (1-u)^(D+C+4), S_ch the real squared channel distance, and
  // (1-u)^m >= 1 - m*u. The double evaluation of the bound adds < 1e-12
  // relative error, and its conversion to float is rounded down. Hence a
  // factor 1 - 2*(D+C+8)*u keeps the bound at or below every member's cost
  // (with room to spare). Underflow breaks relative error bounds, so radius
  // bounds below 1e-30 are dropped to 0.
  l.radius_margin = 2.0 * (l.dims + l.channels + 8) * 0x1.0p-24;
  const std::size_t cluster_packs = packs_of(k);
  l.cluster_boxes = detail::BoxPacks(cluster_packs, l.dims);
  l.centroids = detail::BoxPacks(cluster_packs, l.dims);
  l.radius_t.resize(std::size_t{k} * l.channels);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::size_t at = std::size_t{c} * l.dims;
    l.cluster_boxes.set(c, table.box_min.data() + at, table.box_max.data() + at, table.min_multiplier[c],
                        table.min_bias[c]);
    l.centroids.set(c, table.centroids.data() + at, table.centroids.data() + at, 1.0f, 0.0f);
    for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
      l.radius_t[std::size_t{ch} * k + c] = table.channel_radius[std::size_t{c} * l.channels + ch];
    }
  }
  l.scratch.resize(pool.thread_count());
  for (Scratch& s : l.scratch) {
    s.order.reserve(k);
    s.bound.resize(cluster_packs * kLanes);
    s.distance.resize(cluster_packs * kLanes);
    s.tile_bound.resize(packs_of(l.max_cluster_tiles) * kLanes);
    s.radius_sum.resize(k);
    s.radius_total.resize(k);
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

// Radius bounds of every cluster with the bias, raised into out[] (see the
// margin proof in create()). Adding the bias after the max is the max of the
// biased bounds: float addition is monotone.
void radius_bounds(const ClusterSearch::Layout& l, const float* q, const float* w, Scratch& s, float* out) {
  const ClusterTable& t = l.table;
  const std::size_t n = t.cluster_count;
  double* sum = s.radius_sum.data();
  double* total = s.radius_total.data();
  std::fill_n(total, n, 0.0);
  std::uint32_t d = 0;
  for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
    const std::uint32_t end = l.rows.channel_end[ch];
    const double weight = w[ch];
    if (weight == 0.0) {
      d = end;
      continue;
    }
    std::fill_n(sum, n, 0.0);
    for (; d < end; ++d) {
      const double qd = q[d];
      for (std::size_t i = 0; i < n; ++i) {
        const double diff = qd - double(t.centroids[i * l.dims + d]);
        sum[i] += diff * diff;
      }
    }
    const float* radius = l.radius_t.data() + std::size_t{ch} * n;
    for (std::size_t i = 0; i < n; ++i) {
      // 1 - 1e-12 absorbs the double rounding of the distance itself, which
      // a cancellation against the radius could otherwise magnify.
      const double gap = std::sqrt(sum[i]) * (1.0 - 1e-12) - double(radius[i]);
      total[i] += gap > 0.0 ? weight * gap * gap : 0.0;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double bound = double(t.min_multiplier[i]) * total[i] * (1.0 - l.radius_margin);
    if (!(bound >= 1e-30)) continue;
    float down = static_cast<float>(bound);
    if (double(down) > bound) down = std::nextafter(down, 0.0f);
    out[i] = std::max(out[i], down + t.min_bias[i]);
  }
}

}  // namespace

Status ClusterSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  const Database& db = *database_;
  Layout& l = *layout_;
  const ClusterTable& t = l.table;
  const QueryParams default_params;
  const ClusterSearchOptions options = options_;
  const detail::TileArrays tile_arrays = l.rows.arrays();
  const detail::BoxArrays tile_boxes = l.tile_boxes.arrays(l.rows.channel_end);
  for (Scratch& s : l.scratch) {
    s.rows = 0;
    s.counters = {};
  }

  pool_->parallel_for(batch.size, [&](std::size_t first, std::size_t last, unsigned thread) {
    Scratch& s = l.scratch[thread];
    for (std::size_t qi = first; qi < last; ++qi) {
      const QueryParams& params = batch.params.empty() ? default_params : batch.params[qi];
      const float* q = batch.features.data() + qi * l.dims;
      const float* w = params.channel_weights.data();
      const std::span<Match> best = out.subspan(qi * k, k);
      std::fill(best.begin(), best.end(), Match{});
      const std::uint32_t continuing = params.continuing_frame;
      if (continuing != kNoFrame && is_candidate(db, continuing, params)) {
        detail::insert_sorted(best, Match{continuing, frame_cost(db, continuing, {q, l.dims}, params)});
        ++s.rows;
      }

      s.order.clear();
      // A tag both required and excluded rules out every frame.
      const bool contradictory = (params.require_all & params.exclude_any) != 0;
      for (std::uint32_t c = 0; c < t.cluster_count && !contradictory; ++c) {
        if (l.never_candidate[c]) continue;
        if ((t.tag_union[c] & params.require_all) != params.require_all) continue;
        if ((t.tag_intersection[c] & params.exclude_any) != 0) continue;
        s.order.push_back({0.0f, c, 0.0f});
      }
      const bool probing = options.nprobe != 0 && options.nprobe < s.order.size();
      // Nearest-centroid seed (exact mode) or probe order (nprobe mode):
      // channel-weighted squared centroid distances, a box bound of the
      // zero-size boxes [centroid, centroid] with unit multipliers.
      const bool by_centroid = probing && !options.probe_by_bound;
      const bool seeding = !by_centroid && options.seed_nearest && s.order.size() > 1;
      const std::size_t cluster_packs = packs_of(t.cluster_count);
      if (by_centroid || seeding) {
        l.kernels.box_bounds(l.centroids.arrays(l.rows.channel_end), 0, cluster_packs, q, w, s.distance.data());
      }
      float* bound = s.bound.data();
      if (!s.order.empty()) {
        if (options.box_bound) {
          l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), 0, cluster_packs, q, w, bound);
        } else {
          std::copy(t.min_bias.begin(), t.min_bias.end(), bound);
        }
        if (options.radius_bound) radius_bounds(l, q, w, s, bound);
        for (ClusterBound& b : s.order) b.bound = bound[b.cluster];
      }

      // Evaluates the tiles of cluster c whose own bound is at most the k-th
      // best (strictly greater is skipped: a member costing exactly the k-th
      // best could still win on a lower frame id).
      detail::KernelQuery kernel_query{q, w, 0.0f};
      const auto visit = [&](std::uint32_t c) {
        ++s.counters.clusters_visited;
        const std::uint32_t first_tile = l.tile_offsets[c];
        const std::uint32_t tiles = l.tile_offsets[c + 1] - first_tile;
        if (options.tile_bound) {
          // Members are in frame order, so a tile mostly holds neighbouring
          // frames of a clip and its box is tight.
          l.kernels.box_bounds(tile_boxes, l.tile_box_pack[c], packs_of(tiles), q, w, s.tile_bound.data());
          s.counters.tiles_checked += tiles;
        }
        for (std::uint32_t i = 0; i < tiles; ++i) {
          if (options.tile_bound && s.tile_bound[i] > best[k - 1].cost) continue;
          const std::uint32_t tile = first_tile + i;
          s.rows += l.tile_rows[tile];
          kernel_query.threshold = best[k - 1].cost;
          const std::size_t hits = l.kernels.evaluate_tiles(tile_arrays, &kernel_query, 1, &tile, 1, s.hits.data());
          for (std::size_t h = 0; h < hits; ++h) {
            detail::offer_tile_row(db, params, best, Match{l.frame[s.hits[h].slot], s.hits[h].cost});
          }
        }
      };

      if (by_centroid) {
        // The nprobe nearest centroids, nearest first (the most likely home
        // of the answer, so the k-th best tightens early); a probed cluster
        // whose lower bound is above the k-th best is skipped, which never
        // changes the result.
        for (ClusterBound& b : s.order) {
          b.lower = b.bound;
          b.bound = s.distance[b.cluster];
        }
        std::nth_element(s.order.begin(), s.order.begin() + options.nprobe, s.order.end());
        s.order.resize(options.nprobe);
        std::sort(s.order.begin(), s.order.end());
        for (const ClusterBound& b : s.order) {
          if (b.lower > best[k - 1].cost) continue;
          visit(b.cluster);
        }
        continue;
      }

      // Exact: first the cluster of the nearest centroid (when seeding), to
      // tighten the k-th best early, then every cluster in lower-bound order
      // until the next bound is above the k-th best.
      std::uint32_t seeded = kNoCluster;
      std::uint32_t budget = probing ? options.nprobe : t.cluster_count;
      if (seeding) {
        const ClusterBound* nearest = &s.order.front();
        for (const ClusterBound& b : s.order) {
          if (s.distance[b.cluster] < s.distance[nearest->cluster]) nearest = &b;
        }
        seeded = nearest->cluster;
        if (nearest->bound <= best[k - 1].cost) {
          visit(seeded);
          --budget;
        }
      }
      // A min-heap: usually only a few clusters are visited, so popping them
      // in order beats sorting all of them.
      const auto heap_order = [](const ClusterBound& a, const ClusterBound& b) { return b < a; };
      std::make_heap(s.order.begin(), s.order.end(), heap_order);
      for (auto heap_end = s.order.end(); heap_end != s.order.begin() && budget > 0; --heap_end) {
        std::pop_heap(s.order.begin(), heap_end, heap_order);
        const ClusterBound& b = *(heap_end - 1);
        if (b.bound > best[k - 1].cost) break;
        if (b.cluster == seeded) continue;
        visit(b.cluster);
        --budget;
      }
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
