// The exact brute-force kernels (shaders/brute_force_scan.comp +
// shaders/topk_merge.comp): one pipeline per (K, query tile) variant, and
// the recording of a batch as scan/merge pairs over chunks of queries.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "handles.hpp"
#include "kernel_shape.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

class BruteForceKernel {
 public:
  struct Variant {
    std::uint32_t k_class;
    std::uint32_t tile;  // queries per scan invocation
    UniquePipeline scan;
  };

  static Result<BruteForceKernel> create(const Context& context, VkPipelineLayout layout, const KernelShape& shape,
                                         std::uint32_t max_batch, std::uint32_t max_k, std::uint32_t max_tile);

  const KernelShape& shape() const { return shape_; }
  // (K, tile) pairs this kernel can run, for warm-up.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> variant_keys() const;
  // The shader of each pipeline built (VulkanSearch::kernels()).
  std::vector<std::string_view> kernel_names() const;

  // Scratch pairs one query needs for k.
  std::uint64_t scratch_pairs_per_query(std::uint32_t k) const {
    return std::uint64_t{shape_.block_count} * k_class(k);
  }

  // Records the search of queries [0, batch) with `k`, `chunk` queries per
  // scan/merge pair (the scratch holds chunk x blocks x K pairs). The
  // descriptor set must be bound. `tile` 0 picks the tile from the batch.
  Status record(const Context& context, VkCommandBuffer commands, VkPipelineLayout layout, std::uint32_t batch,
                std::uint32_t k, std::uint32_t chunk, std::uint32_t tile = 0) const;

 private:
  const Variant* find(std::uint32_t k_class, std::uint32_t tile) const;
  std::uint32_t pick_tile(std::uint32_t batch, std::uint32_t k_class) const;

  KernelShape shape_;
  std::uint32_t max_tile_ = 1;
  std::vector<Variant> variants_;
  std::vector<std::pair<std::uint32_t, UniquePipeline>> merges_;  // by K
};

}  // namespace mmvk::vulkan::detail
