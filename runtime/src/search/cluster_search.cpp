#include "mmvk/cluster_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

// The vectorizable loops are compiled for AVX2 and for the baseline; the
// loader picks the clone the CPU supports (no -march=native, so the library
// stays portable). Lanes never mix, so every clone gives the same bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MMVK_KERNEL __attribute__((target_clones("avx2", "default")))
#else
#define MMVK_KERNEL
#endif

namespace mmvk {

namespace {

constexpr std::uint32_t kLanes = 16;  // rows per tile, stored dim-major
// 8 floats, one AVX register (two SSE registers in the baseline clone).
typedef float V8 __attribute__((vector_size(32)));

std::size_t pad8(std::size_t n) { return (n + 7) / 8 * 8; }

constexpr std::uint32_t kNeverCandidate = kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition;

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
  std::vector<float> total, box, distance;    // [max(clusters, tiles per cluster), padded to 8]
  std::vector<double> radius_sum, radius_total;  // [clusters]
  std::uint64_t rows = 0;
  ClusterSearchCounters counters;
};

// Costs of the 16 rows of one tile, each lane in the reference's order
// (frame_cost): per channel a float sum of squared differences from 0, the
// weighted channel sums added in schema order, then multiplier and bias.
// Explicit 8-lane vectors across rows: no lane's sum is ever reassociated.
MMVK_KERNEL void tile_costs(const float* tile, const float* query, const float* weights, const std::uint32_t* channel_end,
                            std::uint32_t channels, const float* multiplier, const float* bias, float* cost) {
  V8 total0 = {};
  V8 total1 = {};
  std::uint32_t d = 0;
  for (std::uint32_t ch = 0; ch < channels; ++ch) {
    V8 sum0 = {};
    V8 sum1 = {};
    for (; d < channel_end[ch]; ++d) {
      V8 x0;
      V8 x1;
      std::memcpy(&x0, tile + std::size_t{d} * kLanes, sizeof(V8));
      std::memcpy(&x1, tile + std::size_t{d} * kLanes + 8, sizeof(V8));
      const V8 diff0 = x0 - query[d];
      const V8 diff1 = x1 - query[d];
      sum0 += diff0 * diff0;
      sum1 += diff1 * diff1;
    }
    total0 += weights[ch] * sum0;
    total1 += weights[ch] * sum1;
  }
  V8 m0, m1, b0, b1;
  std::memcpy(&m0, multiplier, sizeof(V8));
  std::memcpy(&m1, multiplier + 8, sizeof(V8));
  std::memcpy(&b0, bias, sizeof(V8));
  std::memcpy(&b1, bias + 8, sizeof(V8));
  const V8 cost0 = m0 * total0 + b0;
  const V8 cost1 = m1 * total1 + b1;
  std::memcpy(cost, &cost0, sizeof(V8));
  std::memcpy(cost + 8, &cost1, sizeof(V8));
}

// Inserts into a (cost, frame)-sorted list of k (the reference's rule).
void insert(std::span<Match> best, const Match& candidate) {
  std::size_t slot = best.size() - 1;
  while (slot > 0 && match_less(candidate, best[slot - 1])) {
    best[slot] = best[slot - 1];
    --slot;
  }
  best[slot] = candidate;
}

}  // namespace

struct ClusterSearch::Layout {
  ClusterTable table;
  std::uint32_t dims = 0;
  std::uint32_t channels = 0;
  std::vector<std::uint32_t> channel_begin;  // [channels]
  std::vector<std::uint32_t> channel_end;    // [channels]
  std::vector<std::uint32_t> tile_offsets;   // [clusters + 1]
  std::vector<float> features;               // [tiles][dims][16]
  std::vector<std::uint32_t> frame;          // [tiles x 16], kNoFrame in padding lanes
  std::vector<float> multiplier;             // [tiles x 16]
  std::vector<float> bias;                   // [tiles x 16]
  std::vector<std::uint32_t> flags;          // [tiles x 16], padding: do-not-use
  // Boxes are stored dim-major, with the box count padded to a multiple of
  // 8 (padding boxes are [0, 0]), so bounds of many boxes vectorize: tile i
  // of cluster c at [tile_box_offset[c] + d * pad8(tiles_c) + i].
  std::vector<float> tile_lo;                // box of the tile's member rows
  std::vector<float> tile_hi;
  std::vector<std::size_t> tile_box_offset;  // [clusters]
  std::vector<float> tile_min_multiplier;    // [tiles]
  std::vector<float> tile_min_bias;          // [tiles]
  std::vector<std::uint8_t> tile_rows;       // [tiles]: member rows (the rest is padding)
  std::uint32_t max_cluster_tiles = 0;
  std::vector<float> cluster_lo;             // [dims x pad8(clusters)] (table.box_min transposed)
  std::vector<float> cluster_hi;             // [dims x pad8(clusters)]
  std::vector<float> centroid_t;             // [dims x pad8(clusters)]
  std::vector<float> ones;                   // [clusters]: unit multipliers for centroid distances
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
  std::uint32_t begin = 0;
  for (const FeatureChannel& channel : database.schema().channels) {
    l.channel_begin.push_back(begin);
    begin += channel.dims();
    l.channel_end.push_back(begin);
  }
  const std::uint32_t k = table.cluster_count;
  l.tile_offsets.assign(k + 1, 0);
  l.never_candidate.resize(k);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::uint32_t size = table.offsets[c + 1] - table.offsets[c];
    l.never_candidate[c] = size == 0 || (table.flags_intersection[c] & kNeverCandidate) != 0;
    l.tile_offsets[c + 1] = l.tile_offsets[c] + (size + kLanes - 1) / kLanes;
  }
  const std::size_t tiles = l.tile_offsets[k];
  l.features.assign(tiles * l.dims * kLanes, 0.0f);
  l.frame.assign(tiles * kLanes, kNoFrame);
  l.multiplier.assign(tiles * kLanes, 1.0f);
  l.bias.assign(tiles * kLanes, 0.0f);
  l.flags.assign(tiles * kLanes, kFrameDoNotUse);
  l.tile_box_offset.resize(k);
  std::size_t box_values = 0;
  for (std::uint32_t c = 0; c < k; ++c) {
    l.tile_box_offset[c] = box_values;
    box_values += pad8(l.tile_offsets[c + 1] - l.tile_offsets[c]) * l.dims;
  }
  l.tile_lo.assign(box_values, std::numeric_limits<float>::infinity());
  l.tile_hi.assign(box_values, -std::numeric_limits<float>::infinity());
  l.tile_min_multiplier.assign(tiles, std::numeric_limits<float>::infinity());
  l.tile_min_bias.assign(tiles, std::numeric_limits<float>::infinity());
  l.tile_rows.assign(tiles, 0);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::uint32_t tiles_c = l.tile_offsets[c + 1] - l.tile_offsets[c];
    l.max_cluster_tiles = std::max(l.max_cluster_tiles, tiles_c);
    for (std::uint32_t m = table.offsets[c]; m < table.offsets[c + 1]; ++m) {
      const std::uint32_t f = table.members[m];
      const std::size_t slot = std::size_t{l.tile_offsets[c]} * kLanes + (m - table.offsets[c]);
      const std::size_t tile = slot / kLanes;
      const std::size_t lane = slot % kLanes;
      const auto row = database.row(f);
      for (std::uint32_t d = 0; d < l.dims; ++d) {
        l.features[(tile * l.dims + d) * kLanes + lane] = row[d];
        const std::size_t at = l.tile_box_offset[c] + std::size_t{d} * pad8(tiles_c) + (tile - l.tile_offsets[c]);
        l.tile_lo[at] = std::min(l.tile_lo[at], row[d]);
        l.tile_hi[at] = std::max(l.tile_hi[at], row[d]);
      }
      l.tile_min_multiplier[tile] = std::min(l.tile_min_multiplier[tile], database.frame_multiplier()[f]);
      l.tile_min_bias[tile] = std::min(l.tile_min_bias[tile], database.frame_bias()[f]);
      ++l.tile_rows[tile];
      l.frame[slot] = f;
      l.multiplier[slot] = database.frame_multiplier()[f];
      l.bias[slot] = database.frame_bias()[f];
      l.flags[slot] = database.frame_flags()[f];
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
  for (std::size_t i = 0; i < box_values; ++i) {
    if (l.tile_lo[i] > l.tile_hi[i]) l.tile_lo[i] = l.tile_hi[i] = 0.0f;  // padding boxes
  }
  const std::size_t k8 = pad8(k);
  l.cluster_lo.assign(k8 * l.dims, 0.0f);
  l.cluster_hi.assign(k8 * l.dims, 0.0f);
  l.centroid_t.assign(k8 * l.dims, 0.0f);
  l.ones.assign(k, 1.0f);
  l.radius_t.resize(std::size_t{k} * l.channels);
  for (std::uint32_t c = 0; c < k; ++c) {
    for (std::uint32_t d = 0; d < l.dims; ++d) {
      l.cluster_lo[d * k8 + c] = table.box_min[std::size_t{c} * l.dims + d];
      l.cluster_hi[d * k8 + c] = table.box_max[std::size_t{c} * l.dims + d];
      l.centroid_t[d * k8 + c] = table.centroids[std::size_t{c} * l.dims + d];
    }
    for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
      l.radius_t[std::size_t{ch} * k + c] = table.channel_radius[std::size_t{c} * l.channels + ch];
    }
  }
  l.scratch.resize(pool.thread_count());
  const std::size_t width = std::max<std::size_t>(k8, pad8(l.max_cluster_tiles));
  for (Scratch& s : l.scratch) {
    s.order.reserve(k);
    s.total.resize(width);
    s.box.resize(width);
    s.distance.resize(width);
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

namespace {

// Box bounds of n boxes stored dim-major (lo[d * stride + i], stride a
// multiple of 8), before the bias: out[i] = min_multiplier[i] * sum_ch w_ch *
// sum_d gap_d^2 in the reference's order, gap_d = the distance of q_d to
// [lo, hi]. For a member x, |fl(x_d - q_d)| >= fl(gap_d) (rounding is
// monotone), so every later step stays at or below the member's own
// evaluation. Channels of weight 0 are skipped: adding +0 changes no sum.
// Explicit 8-lane vectors: the compiler will not if-convert float compares
// by itself (they may trap); each lane keeps the scalar order.
MMVK_KERNEL void box_bounds(const ClusterSearch::Layout& l, const float* lo, const float* hi, std::size_t stride,
                            std::size_t n, const float* min_multiplier, const float* q, const float* w, Scratch& s,
                            float* out) {
  float* total = s.total.data();
  for (std::size_t i = 0; i < stride; i += 8) {
    V8 lane_total = {};
    for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
      const float weight = w[ch];
      if (weight == 0.0f) continue;
      V8 sum = {};
      for (std::uint32_t d = l.channel_begin[ch]; d < l.channel_end[ch]; ++d) {
        V8 lo_v;
        V8 hi_v;
        std::memcpy(&lo_v, lo + std::size_t{d} * stride + i, sizeof(V8));
        std::memcpy(&hi_v, hi + std::size_t{d} * stride + i, sizeof(V8));
        // At most one is > 0 (lo <= hi): below exactly when q_d < lo,
        // above exactly when q_d > hi.
        const V8 below = lo_v - q[d];
        const V8 above = q[d] - hi_v;
        const V8 outside = below > above ? below : above;
        const V8 gap = outside > 0.0f ? outside : V8{};
        sum += gap * gap;
      }
      lane_total += weight * sum;
    }
    std::memcpy(total + i, &lane_total, sizeof(V8));
  }
  for (std::size_t i = 0; i < n; ++i) out[i] = min_multiplier[i] * total[i];
}

// Radius bounds of every cluster before the bias, raised into out[] (see the
// margin proof in create()).
void radius_bounds(const ClusterSearch::Layout& l, const float* q, const float* w, Scratch& s, float* out) {
  const std::size_t n = l.table.cluster_count;
  double* sum = s.radius_sum.data();
  double* total = s.radius_total.data();
  std::fill_n(total, n, 0.0);
  for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
    const double weight = w[ch];
    if (weight == 0.0) continue;
    std::fill_n(sum, n, 0.0);
    for (std::uint32_t d = l.channel_begin[ch]; d < l.channel_end[ch]; ++d) {
      const double qd = q[d];
      const float* centroid_d = l.centroid_t.data() + std::size_t{d} * pad8(n);
      for (std::size_t i = 0; i < n; ++i) {
        const double diff = qd - double(centroid_d[i]);
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
    const double bound = double(l.table.min_multiplier[i]) * total[i] * (1.0 - l.radius_margin);
    if (!(bound >= 1e-30)) continue;
    float down = static_cast<float>(bound);
    if (double(down) > bound) down = std::nextafter(down, 0.0f);
    out[i] = std::max(out[i], down);
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
  for (Scratch& s : l.scratch) {
    s.rows = 0;
    s.counters = {};
  }

  pool_->parallel_for(batch.size, [&](std::size_t first, std::size_t last, unsigned thread) {
    Scratch& s = l.scratch[thread];
    float cost[kLanes];
    for (std::size_t qi = first; qi < last; ++qi) {
      const QueryParams& params = batch.params.empty() ? default_params : batch.params[qi];
      const float* q = batch.features.data() + qi * l.dims;
      const float* w = params.channel_weights.data();
      const std::span<Match> best = out.subspan(qi * k, k);
      std::fill(best.begin(), best.end(), Match{});
      const std::uint32_t continuing = params.continuing_frame;
      if (continuing != kNoFrame && is_candidate(db, continuing, params)) {
        insert(best, Match{continuing, frame_cost(db, continuing, {q, l.dims}, params)});
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
      if (by_centroid || seeding) {
        box_bounds(l, l.centroid_t.data(), l.centroid_t.data(), pad8(t.cluster_count), t.cluster_count, l.ones.data(), q,
                   w, s, s.distance.data());
      }
      float* bound = s.box.data();
      if (!s.order.empty()) {
        if (options.box_bound) {
          box_bounds(l, l.cluster_lo.data(), l.cluster_hi.data(), pad8(t.cluster_count), t.cluster_count,
                     t.min_multiplier.data(), q, w, s, bound);
        } else {
          std::fill_n(bound, t.cluster_count, 0.0f);
        }
        if (options.radius_bound) radius_bounds(l, q, w, s, bound);
        for (ClusterBound& b : s.order) b.bound = bound[b.cluster] + t.min_bias[b.cluster];
      }

      // Evaluates the tiles of cluster c whose own bound is at most the k-th
      // best (strictly greater is skipped: a member costing exactly the k-th
      // best could still win on a lower frame id). Uses s.box as scratch.
      const auto visit = [&](std::uint32_t c) {
        ++s.counters.clusters_visited;
        const std::uint32_t first_tile = l.tile_offsets[c];
        const std::uint32_t tiles = l.tile_offsets[c + 1] - first_tile;
        float* tile_bound = s.box.data();
        if (options.tile_bound) {
          // Members are in frame order, so a tile mostly holds neighbouring
          // frames of a clip and its box is tight.
          const std::size_t at = l.tile_box_offset[c];
          box_bounds(l, l.tile_lo.data() + at, l.tile_hi.data() + at, pad8(tiles), tiles,
                     l.tile_min_multiplier.data() + first_tile, q, w, s, tile_bound);
          s.counters.tiles_checked += tiles;
        }
        for (std::uint32_t i = 0; i < tiles; ++i) {
          const std::uint32_t tile = first_tile + i;
          if (options.tile_bound && tile_bound[i] + l.tile_min_bias[tile] > best[k - 1].cost) continue;
          s.rows += l.tile_rows[tile];
          const std::size_t base = std::size_t{tile} * kLanes;
          tile_costs(l.features.data() + base * l.dims, q, w, l.channel_end.data(), l.channels,
                     l.multiplier.data() + base, l.bias.data() + base, cost);
          for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
            const Match candidate{l.frame[base + lane], cost[lane]};
            if (!match_less(candidate, best[k - 1])) continue;
            // Padding lanes and never-candidates carry flags that fail here;
            // the continuing frame was already seeded.
            if ((l.flags[base + lane] & kNeverCandidate) != 0 || candidate.frame == continuing) continue;
            if (!is_candidate(db, candidate.frame, params)) continue;
            insert(best, candidate);
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
