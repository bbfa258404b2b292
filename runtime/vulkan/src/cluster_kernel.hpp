// The cluster-pruned kernels (shaders/cluster_*.comp) of
// VulkanClusterSearch, exact and nprobe: the ClusterTable uploaded once (set 1 of
// the cluster pipelines), per-slot scratch, and the recording of a batch.
//
// Per chunk of queries, twelve dispatches (eight indirect):
//   cluster_bounds  (cluster, query): lower bound key per cluster, kSkip for
//                   clusters without candidates; centroid distance (nprobe)
//   cluster_select  (query): nprobe selection, the continuing frame's
//                   pair, the 4 blocks of least bound among the blocks
//                   of the 3 nearest clusters (by centroid)
//   cluster_sort    per round, 3 steps: the listed work items sorted by
//                   block (a counting sort), tiles of up to scan_tile(K,
//                   round) items of one block
//   cluster_scan    round 0 (one invocation per tile, indirect): those
//                   blocks (listed by cluster_select)
//   cluster_merge   round 0 (query): the k-th best so far = upper bound;
//                   lists the other blocks with bound <= upper bound, of
//                   the clusters with bound <= upper bound
//   cluster_scan    round 1: the listed blocks
//   cluster_merge   round 1: final best K, rows evaluated
// Exactness: round 0's k-th best is >= the true k-th best, and a cluster
// or block whose bound is strictly above it holds no member that can enter
// the best k (ClusterSearch's argument, mmvk/search/cluster_search.hpp); the rows are
// evaluated with the brute-force arithmetic, so costs are the reference's.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "device_database.hpp"
#include "handles.hpp"
#include "kernel_shape.hpp"
#include "memory.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

// One submission slot's query buffers (VulkanSearch's, set 0), which the
// cluster kernels read through texel views of their own (set 1); the
// buffers need VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT and must outlive the
// kernel.
struct SlotQueryBuffers {
  const Buffer* features = nullptr;  // [max_batch x dim_vec4s] vec4
  const Buffer* params = nullptr;    // [max_batch] QueryGpu
  const Buffer* weights = nullptr;   // [max_batch x channels] float
};

struct ClusterKernelOptions {
  std::uint32_t max_batch = 1;
  std::uint32_t max_k = 1;
  std::uint32_t slots = 1;
  std::uint32_t nprobe = 0;               // 0 = exact; >= cluster_count is exact too
  std::uint64_t scratch_bytes = std::uint64_t{512} << 20;  // per slot: VulkanClusterOptions::scratch_bytes
  bool force_staging = false;
  std::vector<SlotQueryBuffers> slot_queries;  // one per slot
};

class ClusterKernel {
 public:
  // `table` must have been validated against the database of `shape`
  // (validate_cluster_table; VulkanClusterSearch::create does it once).
  static Result<ClusterKernel> create(const Context& context, VkCommandPool pool, VkDescriptorSetLayout search_layout,
                                      const KernelShape& shape, const Database& database, const ClusterTable& table,
                                      const ClusterKernelOptions& options);

  // K classes (1, 4, 16) the kernel has pipelines for.
  std::vector<std::uint32_t> k_classes() const;
  // The shader of each pipeline built (VulkanSearch::kernels()).
  std::vector<std::string_view> kernel_names() const;
  std::uint32_t cluster_count() const { return cluster_count_; }
  std::uint32_t block_count() const { return block_count_; }
  std::uint32_t block_rows() const { return block_rows_; }

  // Records the search of queries [0, batch) into `commands` with the
  // slot's scratch; `search_set` is the slot's set 0 (query buffers,
  // results).
  Status record(const Context& context, VkCommandBuffer commands, std::uint32_t slot, VkDescriptorSet search_set,
                std::uint32_t batch, std::uint32_t k) const;

  // Bytes of the buffers it allocated: the uploaded table (member rows in
  // cluster order, blocks, boxes) and every slot's scratch.
  std::uint64_t device_bytes() const;

  // Rows evaluated by the last search recorded into `slot` (read after its
  // fence signalled).
  std::uint64_t rows_evaluated(std::uint32_t slot, std::uint32_t batch) const;

 private:
  struct SlotScratch {
    Buffer bound_keys;   // [chunk x clusters] uvec2
    UniqueBufferView bound_key_view;  // after bound_keys: destroyed first
    // Views of the slot's query buffers (SlotQueryBuffers).
    UniqueBufferView query_feature_view;
    UniqueBufferView query_param_view;
    UniqueBufferView query_weight_view;
    Buffer states;       // [max_batch] ClusterQueryState, host-mapped
    Buffer block_pairs;  // [chunk x blocks x K] uvec2, by work item
    Buffer scan_dispatch;  // 2 x (groups x, 1, 1, items): indirect args of the scans
    Buffer work_items;     // [chunk x blocks] (local query, block)
    Buffer listed;         // [chunk x blocks] blocks listed per query
    Buffer block_sort;     // the work items sorted by block (cluster_layout.glsl: BlockSort)
    VkDescriptorSet set = VK_NULL_HANDLE;  // freed with the pool
  };
  struct Variant {
    std::uint32_t k_class = 1;
    UniquePipeline scan[2];  // per round: its tile size (scan_tile)
    UniquePipeline merge;
  };
  // The steps of create(), in order.
  Status upload_table(const Context& context, VkCommandPool pool, const Database& database, const ClusterTable& table,
                      std::uint32_t largest_k_class, bool force_staging);
  Status create_layouts(const Context& context, VkDescriptorSetLayout search_layout, std::uint32_t slots);
  Result<std::uint64_t> size_scratch(const Context& context, const ClusterKernelOptions& options);
  Status create_slots(const Context& context, const ClusterKernelOptions& options, std::uint64_t chunk);
  Status create_pipelines(const Context& context, std::uint32_t max_k);

  std::uint32_t chunk_for(std::uint32_t k_class) const;

  KernelShape shape_;
  std::uint32_t cluster_count_ = 0;
  std::uint32_t block_count_ = 0;
  std::uint32_t block_rows_ = 0;  // rows per member block
  std::uint32_t nprobe_ = 0;
  std::uint32_t max_batch_ = 1;
  std::uint64_t bound_capacity_ = 0;  // uvec2 per slot
  std::uint64_t pair_capacity_ = 0;   // uvec2 per slot
  std::uint64_t item_chunk_ = 0;      // queries the work items and listed blocks hold
  // Declaration order = dependency order (destroyed in reverse).
  UniqueDescriptorSetLayout set_layout_;
  UniquePipelineLayout pipeline_layout_;
  UniqueDescriptorPool descriptor_pool_;
  TexelBuffer member_meta_;
  TexelBuffer member_rows_;
  TexelBuffer member_cost_;
  TexelBuffer block_info_;
  TexelBuffer cluster_info_;
  TexelBuffer cluster_vectors_;
  TexelBuffer block_vectors_;
  std::vector<SlotScratch> slots_;
  UniquePipeline bounds_;
  UniquePipeline select_;
  UniquePipeline sort_[3];  // cluster_sort steps: rank, prefix sums, scatter
  std::vector<Variant> variants_;
};

}  // namespace mmvk::vulkan::detail
