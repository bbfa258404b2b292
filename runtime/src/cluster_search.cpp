#include "mmvk/cluster_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace mmvk {

namespace {

constexpr std::uint32_t kLanes = 16;  // rows per tile, stored dim-major
constexpr std::uint32_t kNeverCandidate = kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition;

struct ClusterBound {
  float bound;
  std::uint32_t cluster;
  friend bool operator<(const ClusterBound& a, const ClusterBound& b) {
    return a.bound < b.bound || (a.bound == b.bound && a.cluster < b.cluster);
  }
};

struct Scratch {
  std::vector<ClusterBound> order;
  std::uint64_t rows = 0;
};

// Costs of the 16 rows of one tile, each lane in the reference's order
// (frame_cost): per channel a float sum of squared differences from 0, the
// weighted channel sums added in schema order, then multiplier and bias.
// The lanes are independent, so the compiler vectorizes across rows without
// reassociating any lane's sum.
void tile_costs(const float* tile, const float* query, const float* weights, const std::uint32_t* channel_end,
                std::uint32_t channels, const float* multiplier, const float* bias, float* cost) {
  float total[kLanes] = {};
  std::uint32_t d = 0;
  for (std::uint32_t ch = 0; ch < channels; ++ch) {
    float sum[kLanes] = {};
    for (; d < channel_end[ch]; ++d) {
      const float q = query[d];
      const float* x = tile + std::size_t{d} * kLanes;
      for (std::uint32_t l = 0; l < kLanes; ++l) {
        const float diff = x[l] - q;
        sum[l] += diff * diff;
      }
    }
    const float w = weights[ch];
    for (std::uint32_t l = 0; l < kLanes; ++l) total[l] += w * sum[l];
  }
  for (std::uint32_t l = 0; l < kLanes; ++l) cost[l] = multiplier[l] * total[l] + bias[l];
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
  std::vector<float> tile_lo;                // [tiles x dims]: box of the tile's member rows
  std::vector<float> tile_hi;                // [tiles x dims]
  std::vector<float> tile_min_multiplier;    // [tiles]
  std::vector<float> tile_min_bias;          // [tiles]
  std::vector<std::uint8_t> tile_rows;       // [tiles]: member rows (the rest is padding)
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
  l.tile_lo.assign(tiles * l.dims, std::numeric_limits<float>::infinity());
  l.tile_hi.assign(tiles * l.dims, -std::numeric_limits<float>::infinity());
  l.tile_min_multiplier.assign(tiles, std::numeric_limits<float>::infinity());
  l.tile_min_bias.assign(tiles, std::numeric_limits<float>::infinity());
  l.tile_rows.assign(tiles, 0);
  for (std::uint32_t c = 0; c < k; ++c) {
    for (std::uint32_t m = table.offsets[c]; m < table.offsets[c + 1]; ++m) {
      const std::uint32_t f = table.members[m];
      const std::size_t slot = std::size_t{l.tile_offsets[c]} * kLanes + (m - table.offsets[c]);
      const std::size_t tile = slot / kLanes;
      const std::size_t lane = slot % kLanes;
      const auto row = database.row(f);
      for (std::uint32_t d = 0; d < l.dims; ++d) {
        l.features[(tile * l.dims + d) * kLanes + lane] = row[d];
        l.tile_lo[tile * l.dims + d] = std::min(l.tile_lo[tile * l.dims + d], row[d]);
        l.tile_hi[tile * l.dims + d] = std::max(l.tile_hi[tile * l.dims + d], row[d]);
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
  l.scratch.resize(pool.thread_count());
  for (Scratch& s : l.scratch) s.order.reserve(k);
  return std::unique_ptr<ClusterSearch>(new ClusterSearch(database, pool, options, std::move(layout)));
}

ClusterSearch::ClusterSearch(const Database& database, ThreadPool& pool, ClusterSearchOptions options,
                             std::unique_ptr<Layout> layout)
    : database_(&database), pool_(&pool), options_(options), layout_(std::move(layout)) {}

ClusterSearch::~ClusterSearch() = default;

std::uint32_t ClusterSearch::cluster_count() const { return layout_->table.cluster_count; }

namespace {

// Box bound of a cluster or tile before the bias: min_multiplier * sum_ch w_ch *
// sum_d gap_d^2 in the reference's order. For a member x, fl(x_d - q_d) is at
// least fl(gap_d) in magnitude (rounding is monotone), so every step stays at
// or below the member's own evaluation.
float box_bound(const ClusterSearch::Layout& l, const float* lo, const float* hi, float min_multiplier, const float* q,
                const float* w) {
  float total = 0.0f;
  for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
    float sum = 0.0f;
    for (std::uint32_t d = l.channel_begin[ch]; d < l.channel_end[ch]; ++d) {
      float gap = 0.0f;
      if (q[d] < lo[d]) gap = lo[d] - q[d];
      if (q[d] > hi[d]) gap = q[d] - hi[d];
      sum += gap * gap;
    }
    total += w[ch] * sum;
  }
  return min_multiplier * total;
}

// Radius bound before the bias (see the margin proof in create()).
float radius_bound(const ClusterSearch::Layout& l, std::uint32_t c, const float* q, const float* w) {
  const float* centroid = l.table.centroids.data() + std::size_t{c} * l.dims;
  const float* radius = l.table.channel_radius.data() + std::size_t{c} * l.channels;
  double total = 0.0;
  for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
    if (w[ch] == 0.0f) continue;
    double sum = 0.0;
    for (std::uint32_t d = l.channel_begin[ch]; d < l.channel_end[ch]; ++d) {
      const double diff = double(q[d]) - double(centroid[d]);
      sum += diff * diff;
    }
    // 1 - 1e-12 absorbs the double rounding of the distance itself, which
    // a cancellation against the radius could otherwise magnify.
    const double gap = std::sqrt(sum) * (1.0 - 1e-12) - double(radius[ch]);
    if (gap > 0.0) total += double(w[ch]) * gap * gap;
  }
  const double bound = double(l.table.min_multiplier[c]) * total * (1.0 - l.radius_margin);
  if (!(bound >= 1e-30)) return 0.0f;
  float down = static_cast<float>(bound);
  if (double(down) > bound) down = std::nextafter(down, 0.0f);
  return down;
}

float centroid_distance(const ClusterSearch::Layout& l, std::uint32_t c, const float* q, const float* w) {
  const float* centroid = l.table.centroids.data() + std::size_t{c} * l.dims;
  float total = 0.0f;
  for (std::uint32_t ch = 0; ch < l.channels; ++ch) {
    float sum = 0.0f;
    for (std::uint32_t d = l.channel_begin[ch]; d < l.channel_end[ch]; ++d) {
      const float diff = centroid[d] - q[d];
      sum += diff * diff;
    }
    total += w[ch] * sum;
  }
  return total;
}

}  // namespace

Status ClusterSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  const Database& db = *database_;
  Layout& l = *layout_;
  const ClusterTable& t = l.table;
  const QueryParams default_params;
  const ClusterSearchOptions options = options_;
  for (Scratch& s : l.scratch) s.rows = 0;

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
        s.order.push_back({0.0f, c});
      }
      if (options.nprobe != 0 && options.nprobe < s.order.size()) {
        for (ClusterBound& b : s.order) b.bound = centroid_distance(l, b.cluster, q, w);
        std::nth_element(s.order.begin(), s.order.begin() + options.nprobe, s.order.end());
        s.order.resize(options.nprobe);
      }
      for (ClusterBound& b : s.order) {
        float bound = 0.0f;
        if (options.box_bound) {
          bound = box_bound(l, t.box_min.data() + std::size_t{b.cluster} * l.dims,
                            t.box_max.data() + std::size_t{b.cluster} * l.dims, t.min_multiplier[b.cluster], q, w);
        }
        if (options.radius_bound) bound = std::max(bound, radius_bound(l, b.cluster, q, w));
        b.bound = bound + t.min_bias[b.cluster];
      }
      std::sort(s.order.begin(), s.order.end());

      for (const ClusterBound& b : s.order) {
        // Strictly greater: a member costing exactly the k-th best could still
        // win on a lower frame id.
        if (b.bound > best[k - 1].cost) break;
        for (std::uint32_t tile = l.tile_offsets[b.cluster]; tile < l.tile_offsets[b.cluster + 1]; ++tile) {
          // Members are in frame order, so a tile mostly holds neighbouring
          // frames of a clip and its box is tight.
          if (options.tile_bound && box_bound(l, l.tile_lo.data() + std::size_t{tile} * l.dims,
                                              l.tile_hi.data() + std::size_t{tile} * l.dims,
                                              l.tile_min_multiplier[tile], q, w) +
                                            l.tile_min_bias[tile] >
                                        best[k - 1].cost) {
            continue;
          }
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
      }
    }
  });

  stats_.queries += batch.size;
  for (const Scratch& s : l.scratch) stats_.rows_evaluated += s.rows;
  return {};
}

}  // namespace mmvk
