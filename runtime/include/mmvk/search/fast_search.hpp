// The exact fast CPU backend: the reference's answers (same frames,
// bit-identical costs), batched, on a caller-owned ThreadPool and vectorized
// across rows.
//
// Layout: the feature matrix is copied into tiles of kFastTileRows = 16
// consecutive frames stored dim-major ([tile][dim][16]), so one vector
// instruction works on 16 rows while every row keeps the reference's
// accumulation order. Pruning uses two levels of per-dimension min/max boxes,
// over a tile (16 rows) and over a group of 16 tiles (256 rows), each with
// the minimum multiplier and bias of its candidate rows, so the lower bound
// never exceeds a real cost (see docs/search.md). Tiles and groups also keep
// the union and intersection of their candidate rows' tags, so blocks that
// a query's tag masks rule out are skipped without evaluation.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "mmvk/search/search.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

inline constexpr std::uint32_t kFastTileRows = 16;   // rows per tile (one 16-lane vector)
inline constexpr std::uint32_t kFastGroupTiles = 16;  // tiles per pruning group (256 rows)

struct FastSearchOptions {
  // true: visit groups in order of their lower bound and skip groups and
  // tiles whose bound exceeds the current k-th best cost; false: brute force
  // over every tile that holds a candidate row.
  bool prune = true;
  // Rows per cache block when queries are split over threads: every query of
  // a thread walks one block before the next, so the block stays in L2.
  // Rounded up to whole groups.
  std::uint32_t rows_per_block = 2048;
  // Which kernels to run: Widest picks the widest set this CPU runs;
  // Generic the x86-64 baseline (SSE2) ones, which tests use to hold every
  // kernel to the reference. create() refuses a set the CPU lacks.
  CpuKernels kernels = CpuKernels::Widest;
};

class FastSearch final : public SearchBackend {
 public:
  // Copies the features into the tiled layout. `database` and `pool` must
  // outlive the backend; the pool may be shared with other work but serves
  // one search() at a time. search() itself is not reentrant (it reuses
  // per-thread scratch): one call at a time.
  static Result<std::unique_ptr<FastSearch>> create(const Database& database, ThreadPool& pool,
                                                    FastSearchOptions options = {});
  ~FastSearch() override;

  std::string_view name() const override { return options_.prune ? "fast-box" : "fast-brute"; }
  std::string device() const override { return cpu_device_text(pool_->thread_count()); }
  const Database& database() const override { return *database_; }
  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  SearchStats stats() const override;
  void reset_stats() override;

  const FastSearchOptions& options() const { return options_; }
  // The instruction set the kernels use: "avx512f", "avx2" or "generic".
  std::string_view kernel_name() const;

  struct Layout;     // the tiled copy and the boxes (fast_search_layout.cpp)
  struct Workspace;  // per-thread scratch, allocated once (fast_search.cpp)

 private:
  FastSearch(const Database& database, ThreadPool& pool, FastSearchOptions options);
  void search_range(const QueryBatch& batch, std::uint32_t k, std::size_t first_query, std::size_t end_query,
                    std::uint32_t first_group, std::uint32_t end_group, std::span<Match> best, unsigned thread);

  const Database* database_;
  ThreadPool* pool_;
  FastSearchOptions options_;
  std::unique_ptr<Layout> layout_;
  std::unique_ptr<Workspace> workspace_;
  // Per pool thread: rows evaluated in the current call (summed after it).
  std::vector<std::uint64_t> thread_rows_;
  SearchStats stats_;
};

}  // namespace mmvk
