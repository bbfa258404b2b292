// VulkanSearch: the base of the SearchBackends whose costs are evaluated and
// reduced to the best k frames per query in Vulkan compute shaders,
// bit-identical to ReferenceSearch (same frames, same cost bits; see
// docs/search.md and mmvk/search/search.hpp for the semantics). Two searches derive
// from it, as FAISS's GpuIndexFlat and GpuIndexIVFFlat derive from GpuIndex:
// VulkanBruteForce (vulkan_brute_force.hpp: every row, exact) and
// VulkanClusterSearch (vulkan_cluster_search.hpp: rows pruned by a
// ClusterTable, exact or nprobe).
//
// The base owns what both run on: the uploaded database, the submission
// slots (mapped query/parameter/result buffers for `max_batch` queries,
// scratch, command buffers, descriptor sets, timestamp queries, all created
// up front so a search allocates nothing), the staging of queries into a
// slot, and one batch pager: any batch up to kMaxBatch is cut into pages of
// max_batch queries, as many in flight as there are free slots. search()
// and the AsyncSearch of make_async() (VulkanAsyncSearch: a crowd overlaps
// the search with its own work) both page through it.
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

#include "mmvk/search/async_search.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan {

// What every Vulkan search takes; the cluster search adds its own
// (VulkanClusterOptions).
struct VulkanSearchOptions {
  std::uint32_t max_batch = 1024;  // queries per page (a slot's buffers hold this many), >= 1
  std::uint32_t max_k = kMaxK;     // largest k a search may ask for, in [1, kMaxK]
  std::uint32_t slots = 2;         // pages in flight at a time, >= 1
  // Rows each brute-force scan invocation covers; 0 picks one from the
  // frame count. At most 32768, as llvmpipe stops loops at 65,535
  // iterations.
  std::uint32_t rows_per_invocation = 0;
  // Largest query tile held in registers (1, 4, 16 or 32; 16 and 32 only
  // for k = 1, 32 for batches of 512 or more). Bigger tiles are faster on
  // large batches and slower to compile (lavapipe compiles the 16-query
  // kernel for seconds at the first use).
  std::uint32_t max_tile = 16;
  // Per-slot scratch budget for the brute force's per-block best pairs,
  // bytes; pages whose scratch would not fit are processed in chunks
  // inside one submit.
  std::uint64_t scratch_bytes = std::uint64_t{32} << 20;
  // Runs warm_up() at creation: drivers such as lavapipe compile at the
  // first dispatch, which would otherwise land in a search.
  bool warm_up = true;
  // Uploads the database through a staging buffer and a copy even when the
  // device-local memory is host-visible (unified memory, lavapipe), so the
  // path discrete GPUs take can be tested anywhere.
  bool force_staging_upload = false;
};

class VulkanAsyncSearch;

class VulkanSearch : public SearchBackend {
 public:
  ~VulkanSearch() override;
  VulkanSearch(const VulkanSearch&) = delete;
  VulkanSearch& operator=(const VulkanSearch&) = delete;

  std::string device() const override;  // the Context's description()
  const Database& database() const override;
  // Blocking: any batch up to kMaxBatch, paged over the slots. Errors:
  // validate_search, k over max_k, every slot held by an asynchronous
  // batch, a failed submit (nothing is left in flight after an error).
  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  SearchStats stats() const override;
  void reset_stats() override;
  // A VulkanAsyncSearch: the search runs while the caller works.
  std::unique_ptr<AsyncSearch> make_async(std::uint32_t capacity) override;

  // Builds every kernel variant this search can run and dispatches each
  // once (a query per tile of row 0 of the database), so no later search
  // pays a compile: pipelines are created at create() (through the
  // Context's pipeline cache), and lavapipe compiles at the first dispatch
  // (its own Mesa shader cache makes that fast in later processes). Needs a
  // free slot; keeps stats() and last_kernel_seconds(). create() calls it
  // unless options.warm_up is false.
  Status warm_up();

  // The shaders (shaders/*.comp names) this search built pipelines for,
  // once per (K, tile) variant: only those it runs (the cluster search
  // builds no brute-force kernel), all of which warm_up() dispatches.
  std::vector<std::string_view> kernels() const;

  // Bytes of the buffers this search allocated through Vulkan: the database
  // (features, metadata, cost terms), the cluster search's table (its rows
  // again, in cluster order, with blocks and boxes) and, per slot, the
  // query, scratch and result buffers (the cluster search's scratch is
  // sized by VulkanClusterOptions::scratch_bytes for the worst case). The
  // driver's own memory (pipelines, descriptor pools, command buffers) is
  // not counted.
  std::uint64_t device_bytes() const;

  // GPU time of the last waited-for page from timestamp queries, seconds;
  // nullopt when the queue has no timestamps.
  std::optional<double> last_kernel_seconds() const;

  const VulkanSearchOptions& options() const;
  std::uint32_t rows_per_invocation() const;
  std::uint32_t workgroup_size() const;

  struct Impl;

 protected:
  explicit VulkanSearch(std::unique_ptr<Impl> impl);

 private:
  friend class VulkanAsyncSearch;  // pages through impl_'s asynchronous pager
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmvk::vulkan
