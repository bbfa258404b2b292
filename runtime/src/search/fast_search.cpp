#include "mmvk/search/fast_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "search/fast_search_layout.hpp"
#include "search/top_k.hpp"

namespace mmvk {

namespace {

static_assert(kFastTileRows == detail::kLanes && kFastGroupTiles == detail::kLanes,
              "a group's tile boxes fill one 16-lane pack");

constexpr std::uint32_t kGroupRows = kFastTileRows * kFastGroupTiles;
// Queries that share one pass over a tile in brute force (loads are shared,
// and the independent sums hide the add latency): at most this many, and
// Kernels::brute_queries for the chosen set.
constexpr std::uint32_t kBruteQueries = 4;

// The kernels the options ask for (create() has refused a set the CPU
// lacks; the constructor falls back to the widest).
detail::Kernels kernels_of(const FastSearchOptions& options) {
  detail::Kernels kernels{};
  if (!detail::select_kernels(options.kernels, kernels)) kernels = detail::select_kernels(false);
  return kernels;
}

}  // namespace

struct FastSearch::Workspace {
  struct Thread {
    std::vector<std::pair<float, std::uint32_t>> group_order;  // (bound, group)
    std::array<std::uint32_t, kFastGroupTiles> tile_ids{};
    std::array<detail::LaneHit, kFastGroupTiles * detail::kLanes * 4> hits{};
  };
  std::vector<Thread> threads;
  std::vector<Match> partial;  // [parts x B x k] when one query is split over threads
  std::vector<Match> merged;   // [parts x k]: one query's lists, merged (kept, so a search allocates nothing)
};

FastSearch::FastSearch(const Database& database, ThreadPool& pool, FastSearchOptions options)
    : database_(&database),
      pool_(&pool),
      options_(options),
      layout_(Layout::build(database, kernels_of(options))),
      workspace_(std::make_unique<Workspace>()),
      thread_rows_(pool.thread_count(), 0) {
  workspace_->threads.resize(pool.thread_count());
  for (Workspace::Thread& thread : workspace_->threads) thread.group_order.reserve(layout_->groups);
}

Result<std::unique_ptr<FastSearch>> FastSearch::create(const Database& database, ThreadPool& pool,
                                                       FastSearchOptions options) {
  // rows_per_block rounds up to a group; only a kernel set this CPU cannot
  // run is refused.
  detail::Kernels kernels{};
  if (!detail::select_kernels(options.kernels, kernels)) {
    return make_error("fast search: this CPU cannot run the requested kernels (FastSearchOptions::kernels)");
  }
  return std::unique_ptr<FastSearch>(new FastSearch(database, pool, options));
}

FastSearch::~FastSearch() = default;

SearchStats FastSearch::stats() const { return stats_; }
std::string_view FastSearch::kernel_name() const { return layout_->kernels.name; }
void FastSearch::reset_stats() { stats_ = {}; }

namespace {

// One thread's pass of FastSearch::search_range over queries
// [first_query, end_query) and the rows of groups [first_group, end_group),
// in its steps: the continuing frames, then brute force or pruning.
class RangePass {
 public:
  RangePass(const Database& db, const FastSearch::Layout& layout, FastSearch::Workspace::Thread& scratch,
            const QueryBatch& batch, const QueryParams& default_params, std::uint32_t k, std::size_t first_query,
            std::size_t end_query, std::uint32_t first_group, std::uint32_t end_group, std::span<Match> best)
      : db_(db), l_(layout), scratch_(scratch), batch_(batch), default_params_(default_params), k_(k),
        first_query_(first_query), end_query_(end_query), first_group_(first_group), end_group_(end_group),
        best_(best) {}

  std::uint64_t rows() const { return rows_; }

  // The continuing frame first: its cost carries continuing_bias (possibly
  // negative), so the tile pass, which knows no such bias, skips it.
  void seed_continuing_frames() {
    const std::uint32_t first_row = first_group_ * kGroupRows;
    const std::uint32_t end_row = std::min<std::uint64_t>(std::uint64_t{end_group_} * kGroupRows, l_.frames);
    for (std::size_t q = first_query_; q < end_query_; ++q) {
      const std::span<Match> list = best_of(q);
      std::fill(list.begin(), list.end(), Match{});
      const QueryParams& params = params_of(q);
      const std::uint32_t cont = params.continuing_frame;
      if (cont != kNoFrame && cont >= first_row && cont < end_row && is_candidate(db_, cont, params)) {
        detail::insert_sorted(list, Match{cont, frame_cost(db_, cont, query_of(q), params)});
        ++rows_;
      }
    }
  }

  // Every candidate row, blocks of rows_per_block at a time, up to
  // Kernels::brute_queries queries sharing each pass over a block.
  void brute(std::uint32_t rows_per_block) {
    const detail::TileArrays tiles = l_.tile_arrays();
    const std::uint32_t block_groups = std::max<std::uint32_t>(1, (rows_per_block + kGroupRows - 1) / kGroupRows);
    for (std::uint32_t block = first_group_; block < end_group_; block += block_groups) {
      const std::uint32_t block_end = std::min(end_group_, block + block_groups);
      for (std::size_t q = first_query_; q < end_query_;) {
        std::uint32_t count = 1;
        while (count * 2 <= l_.kernels.brute_queries && q + count * 2 <= end_query_) count *= 2;
        brute_block(tiles, block, block_end, q, count);
        q += count;
      }
    }
  }

  // Pruned: visit groups by ascending lower bound, stop at the first bound
  // above the k-th best (strictly: an equal cost may still win on frame id).
  void pruned() {
    const detail::TileArrays tiles = l_.tile_arrays();
    const detail::BoxArrays group_boxes = l_.group_boxes();
    const detail::BoxArrays tile_boxes = l_.tile_boxes();
    for (std::size_t q = first_query_; q < end_query_; ++q) {
      order_groups(group_boxes, q);
      std::vector<std::pair<float, std::uint32_t>>& order = scratch_.group_order;
      if (order.empty()) continue;
      const std::span<Match> list = best_of(q);
      // Visit the most promising group first: its rows usually set a k-th
      // best that rules out most groups, so only the rest need sorting.
      const auto seed = std::min_element(order.begin(), order.end());
      const std::uint32_t seed_group = seed->second;
      *seed = order.back();
      order.pop_back();
      visit_group(tiles, tile_boxes, q, seed_group);
      const float worst = list[k_ - 1].cost;
      order.erase(std::remove_if(order.begin(), order.end(), [&](const auto& entry) { return entry.first > worst; }),
                  order.end());
      std::sort(order.begin(), order.end());
      for (const auto& [group_bound, group] : order) {
        if (group_bound > list[k_ - 1].cost) break;
        visit_group(tiles, tile_boxes, q, group);
      }
    }
  }

 private:
  const QueryParams& params_of(std::size_t q) const { return batch_.params.empty() ? default_params_ : batch_.params[q]; }
  std::span<Match> best_of(std::size_t q) const { return best_.subspan((q - first_query_) * k_, k_); }
  std::span<const float> query_of(std::size_t q) const { return batch_.features.subspan(q * l_.dims, l_.dims); }
  std::uint32_t tile_rows(std::uint32_t tile) const { return std::min(kFastTileRows, l_.frames - tile * kFastTileRows); }
  // Tiles hold the frames in order: a hit's slot is its frame.
  void offer(const detail::LaneHit& hit, std::size_t q) {
    detail::offer_tile_row(db_, params_of(q), best_of(q), Match{hit.slot, hit.cost});
  }

  // Queries [q, q + count) over the groups [block, block_end), skipping the
  // groups and tiles that none of them may match.
  void brute_block(const detail::TileArrays& tiles, std::uint32_t block, std::uint32_t block_end, std::size_t q,
                   std::uint32_t count) {
    std::array<detail::KernelQuery, kBruteQueries> queries{};
    for (std::uint32_t i = 0; i < count; ++i) {
      queries[i].features = query_of(q + i).data();
      queries[i].weights = params_of(q + i).channel_weights.data();
    }
    auto any_query_may_match = [&](const detail::BlockSummary& summary) {
      for (std::uint32_t i = 0; i < count; ++i) {
        if (detail::block_may_match(summary, params_of(q + i))) return true;
      }
      return false;
    };
    for (std::uint32_t group = block; group < block_end; ++group) {
      if (!any_query_may_match(l_.group_summary[group])) continue;
      std::size_t tile_count = 0;
      std::uint32_t group_rows = 0;
      const std::uint32_t end_tile = std::min(l_.tiles, (group + 1) * kFastGroupTiles);
      for (std::uint32_t tile = group * kFastGroupTiles; tile < end_tile; ++tile) {
        if (!any_query_may_match(l_.tile_summary[tile])) continue;
        scratch_.tile_ids[tile_count++] = tile;
        group_rows += tile_rows(tile);
      }
      for (std::uint32_t i = 0; i < count; ++i) queries[i].threshold = best_of(q + i)[k_ - 1].cost;
      const std::size_t hits = l_.kernels.evaluate_tiles(tiles, queries.data(), count, scratch_.tile_ids.data(),
                                                         tile_count, scratch_.hits.data());
      rows_ += std::uint64_t{group_rows} * count;
      for (std::size_t h = 0; h < hits; ++h) offer(scratch_.hits[h], q + scratch_.hits[h].query);
    }
  }

  // scratch_.group_order = (lower bound, group) for the groups query q may match.
  void order_groups(const detail::BoxArrays& group_boxes, std::size_t q) {
    const QueryParams& params = params_of(q);
    std::array<float, detail::kLanes> bounds{};
    scratch_.group_order.clear();
    for (std::uint32_t pack = first_group_ / detail::kLanes; pack * detail::kLanes < end_group_; ++pack) {
      l_.kernels.box_bounds(group_boxes, pack, 1, query_of(q).data(), params.channel_weights.data(), bounds.data());
      for (std::uint32_t lane = 0; lane < detail::kLanes; ++lane) {
        const std::uint32_t group = pack * detail::kLanes + lane;
        if (group < first_group_ || group >= end_group_ || !detail::block_may_match(l_.group_summary[group], params)) {
          continue;
        }
        // A NaN bound (0 x inf on overflow) proves nothing: visit first.
        const float bound = std::isnan(bounds[lane]) ? -std::numeric_limits<float>::infinity() : bounds[lane];
        scratch_.group_order.emplace_back(bound, group);
      }
    }
  }

  // Query q over the tiles of one group whose bounds may beat its k-th best.
  void visit_group(const detail::TileArrays& tiles, const detail::BoxArrays& tile_boxes, std::size_t q,
                   std::uint32_t group) {
    const QueryParams& params = params_of(q);
    const std::span<Match> list = best_of(q);
    detail::KernelQuery kernel_query{query_of(q).data(), params.channel_weights.data(), 0.0f};
    std::array<float, detail::kLanes> bounds{};
    l_.kernels.box_bounds(tile_boxes, group, 1, kernel_query.features, kernel_query.weights, bounds.data());
    std::size_t tile_count = 0;
    std::uint32_t group_rows = 0;
    const std::uint32_t first_tile = group * kFastGroupTiles;
    const std::uint32_t end_tile = std::min(l_.tiles, first_tile + kFastGroupTiles);
    for (std::uint32_t tile = first_tile; tile < end_tile; ++tile) {
      if (bounds[tile - first_tile] > list[k_ - 1].cost || !detail::block_may_match(l_.tile_summary[tile], params)) {
        continue;
      }
      scratch_.tile_ids[tile_count++] = tile;
      group_rows += tile_rows(tile);
    }
    if (tile_count == 0) return;
    kernel_query.threshold = list[k_ - 1].cost;
    const std::size_t hits =
        l_.kernels.evaluate_tiles(tiles, &kernel_query, 1, scratch_.tile_ids.data(), tile_count, scratch_.hits.data());
    rows_ += group_rows;
    for (std::size_t h = 0; h < hits; ++h) offer(scratch_.hits[h], q);
  }

  const Database& db_;
  const FastSearch::Layout& l_;
  FastSearch::Workspace::Thread& scratch_;
  const QueryBatch& batch_;
  // Kept outside the pass, like every array the kernels are given: no
  // pointer into the pass escapes to them, so its fields stay in registers.
  const QueryParams& default_params_;
  const std::uint32_t k_;
  const std::size_t first_query_, end_query_;
  const std::uint32_t first_group_, end_group_;
  const std::span<Match> best_;
  std::uint64_t rows_ = 0;
};

}  // namespace

void FastSearch::search_range(const QueryBatch& batch, std::uint32_t k, std::size_t first_query, std::size_t end_query,
                              std::uint32_t first_group, std::uint32_t end_group, std::span<Match> best,
                              unsigned thread) {
  const QueryParams default_params;
  RangePass pass(*database_, *layout_, workspace_->threads[thread], batch, default_params, k, first_query, end_query,
                 first_group, end_group, best);
  pass.seed_continuing_frames();
  if (options_.prune) {
    pass.pruned();
  } else {
    pass.brute(options_.rows_per_block);
  }
  thread_rows_[thread] += pass.rows();
}

Status FastSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(validate_search(*database_, batch, k, out));
  const std::size_t count = batch.size;
  if (count == 0) return {};
  std::fill(thread_rows_.begin(), thread_rows_.end(), 0);
  const unsigned threads = pool_->thread_count();
  const std::uint32_t groups = layout_->groups;
  if (count >= threads || threads == 1 || groups < 2) {
    // Enough queries for every thread: split the queries.
    pool_->parallel_for(count, [&](std::size_t begin, std::size_t end, unsigned thread) {
      search_range(batch, k, begin, end, 0, groups, out.subspan(begin * k, (end - begin) * k), thread);
    });
  } else {
    // Fewer queries than threads: split the rows, then merge the lists.
    const unsigned parts = std::min<unsigned>(threads, groups);
    std::vector<Match>& partial = workspace_->partial;
    partial.assign(std::size_t{parts} * count * k, Match{});
    pool_->parallel_for(parts, [&](std::size_t begin, std::size_t end, unsigned thread) {
      for (std::size_t part = begin; part < end; ++part) {
        const std::uint32_t first_group = static_cast<std::uint32_t>(std::uint64_t{groups} * part / parts);
        const std::uint32_t end_group = static_cast<std::uint32_t>(std::uint64_t{groups} * (part + 1) / parts);
        search_range(batch, k, 0, count, first_group, end_group,
                     std::span<Match>(partial).subspan(part * count * k, count * k), thread);
      }
    });
    std::vector<Match>& merged = workspace_->merged;
    merged.reserve(std::size_t{parts} * k);
    for (std::size_t q = 0; q < count; ++q) {
      merged.clear();
      for (unsigned part = 0; part < parts; ++part) {
        const Match* list = partial.data() + (part * count + q) * k;
        merged.insert(merged.end(), list, list + k);
      }
      std::sort(merged.begin(), merged.end(), match_less);
      std::copy(merged.begin(), merged.begin() + k, out.begin() + static_cast<std::ptrdiff_t>(q * k));
    }
  }
  stats_.queries += count;
  for (std::uint64_t rows : thread_rows_) stats_.rows_evaluated += rows;
  return {};
}

}  // namespace mmvk
