// VulkanSearch: the SearchBackend whose costs are evaluated and reduced to
// the best k frames per query in Vulkan compute shaders, bit-identical to
// ReferenceSearch (same frames, same cost bits; see docs/search.md and
// mmvk/search.hpp for the semantics).
//
// Created once per (Context, Database): the feature matrix and per-frame
// metadata are uploaded into device-local buffers, and every per-search
// resource (mapped query/parameter/result buffers for `max_batch` queries,
// scratch, command buffers, descriptor sets, timestamp queries) is created
// up front, so submit() allocates nothing. A larger batch is paged through
// those buffers (submit_batch), so search() takes any batch up to kMaxBatch.
//
// Asynchronous use (a crowd simulation overlapping the search with its own
// work): submit() returns a Ticket at once; poll() says whether it is done;
// wait() blocks and copies the matches out. `slots` submissions can be in
// flight at a time. submit_batch() and wait_batch() do the same for a batch
// of any size, paged over the slots.
//
// Not thread-safe; the Context and the Database must outlive the search.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/cluster_table.hpp"
#include "mmvk/database.hpp"
#include "mmvk/search.hpp"
#include "mmvk/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan {

enum class SearchMode {
  BruteForce,     // every row, exact
  ClustersExact,  // cluster-pruned, exact (needs a ClusterTable; same answers as BruteForce)
  // The nprobe clusters with the nearest centroids, searched exactly
  // (needs a ClusterTable; same answers as ClusterSearch with that nprobe;
  // nprobe >= cluster_count is exact).
  NProbe,
};

struct VulkanSearchOptions {
  std::uint32_t max_batch = 1024;  // queries per submit (a page of a larger batch), >= 1
  std::uint32_t max_k = kMaxK;     // largest k a submit may ask for, in [1, kMaxK]
  std::uint32_t slots = 2;         // submissions in flight at a time, >= 1
  SearchMode mode = SearchMode::BruteForce;
  std::uint32_t nprobe = 8;        // NProbe: clusters visited per query
  // Rows each scan invocation covers; 0 picks one from the frame count.
  // At most 32768, as llvmpipe stops loops at 65,535 iterations.
  std::uint32_t rows_per_invocation = 0;
  // Largest query tile held in registers (1, 4, 16 or 32; 16 and 32 only
  // for k = 1, 32 for batches of 512 or more). Bigger tiles are faster on
  // large batches and slower to compile (lavapipe compiles the 16-query
  // kernel for seconds at the first use).
  std::uint32_t max_tile = 16;
  // Per-slot scratch budget for the per-block best pairs, bytes; batches
  // whose scratch would not fit are processed in chunks inside one submit.
  std::uint64_t scratch_bytes = std::uint64_t{32} << 20;
  // The same for the cluster modes (bound keys, per-block pairs, the work
  // items and their sort by block), sized for the worst case (every query
  // of a chunk visiting every block). Larger chunks share more blocks: the
  // scan evaluates a block once for a tile of up to 8 of the chunk's
  // queries that visit it. The whole budget is allocated at creation.
  std::uint64_t cluster_scratch_bytes = std::uint64_t{512} << 20;
  // Runs warm_up() at creation: drivers such as lavapipe compile at the
  // first dispatch, which would otherwise land in a search.
  bool warm_up = true;
  // Uploads the database through a staging buffer and a copy even when the
  // device-local memory is host-visible (unified memory, lavapipe), so the
  // path discrete GPUs take can be tested anywhere.
  bool force_staging_upload = false;
};

// A submitted batch; valid until wait() consumed it.
struct Ticket {
  std::uint32_t slot = 0;
  std::uint64_t serial = 0;
};

class VulkanSearch final : public SearchBackend {
 public:
  // Errors: database too large for the device (texel buffer elements,
  // allocation size), dims over 128, options out of range, a cluster table
  // from another database or malformed (validate_cluster_table, in every
  // mode), out of device memory, missing format support.
  static Result<std::unique_ptr<VulkanSearch>> create(Context& context, const Database& database,
                                                      const VulkanSearchOptions& options = {},
                                                      const ClusterTable* clusters = nullptr);
  ~VulkanSearch() override;
  VulkanSearch(const VulkanSearch&) = delete;
  VulkanSearch& operator=(const VulkanSearch&) = delete;

  std::string_view name() const override;
  const Database& database() const override;
  // Blocking: any batch up to kMaxBatch, paged as submit_batch() +
  // wait_batch() (one page: submit() + wait()).
  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  SearchStats stats() const override;
  void reset_stats() override;
  // A VulkanAsyncSearch: the search runs while the caller works.
  std::unique_ptr<AsyncSearch> make_async(std::uint32_t capacity) override;

  // Any batch up to kMaxBatch, paged over the slots: the batch is cut into
  // pages of max_batch queries; as many pages are submitted as there are
  // free slots, and wait_batch() waits for them oldest first, submitting the
  // rest as slots free up. One submitted batch at a time (search() pages on
  // the slots it leaves free); its spans stay valid until wait_batch(). Errors: validate_queries, no free slot, a failed
  // submit (nothing is left in flight after an error).
  Status submit_batch(const QueryBatch& batch, std::uint32_t k);
  // Writes the paged batch's B*k matches to `out` (layout as search()).
  Status wait_batch(std::span<Match> out);

  // One page: validates the batch (validate_search, batch <= max_batch,
  // k <= max_k), copies it into a free slot's mapped buffers and submits
  // the kernels. Error when every slot is in flight: wait() for one first.
  Result<Ticket> submit(const QueryBatch& batch, std::uint32_t k);
  // True once the ticket's results are ready (wait() then returns at once).
  Result<bool> poll(const Ticket& ticket) const;
  // Blocks until the ticket is done and writes its B*k matches to `out`
  // (layout as SearchBackend::search). Consumes the ticket.
  Status wait(const Ticket& ticket, std::span<Match> out);

  // Builds every kernel variant this search can run and dispatches each
  // once (a query per tile of row 0 of the database), so no later search
  // pays a compile: pipelines are created at create() (through the
  // Context's pipeline cache), and lavapipe compiles at the first dispatch
  // (its own Mesa shader cache makes that fast in later processes). Needs a
  // free slot; keeps stats() and last_kernel_seconds(). create() calls it
  // unless options.warm_up is false.
  Status warm_up();

  // The shaders (shaders/*.comp names) this search built pipelines for,
  // once per (K, tile) variant: only those its mode runs (a cluster mode
  // builds no brute-force kernel), all of which warm_up() dispatches.
  std::vector<std::string_view> kernels() const;

  // Bytes of the buffers this search allocated through Vulkan: the database
  // (features, metadata, cost terms), a cluster mode's table (its rows again,
  // in cluster order, with blocks and boxes) and, per slot, the query,
  // scratch and result buffers (the cluster modes' scratch is sized by
  // cluster_scratch_bytes for the worst case). The driver's own memory
  // (pipelines, descriptor pools, command buffers) is not counted.
  std::uint64_t device_bytes() const;

  // GPU time of the last waited-for submit from timestamp queries, seconds;
  // nullopt when the queue has no timestamps.
  std::optional<double> last_kernel_seconds() const;

  const VulkanSearchOptions& options() const;
  std::uint32_t rows_per_invocation() const;
  std::uint32_t workgroup_size() const;

  struct Impl;

 private:
  explicit VulkanSearch(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmvk::vulkan
