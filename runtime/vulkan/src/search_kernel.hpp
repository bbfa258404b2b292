// What a VulkanSearch subclass runs on the base's slots: the brute force's
// kernels or the cluster kernels, behind one interface, so the base
// (slots, staging, timestamps, paging) never asks which search it is.
#pragma once

#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

// One page's recording: set 0 (the slot's query and result buffers and the
// database) is bound on `commands` before record() is called.
struct PageCommands {
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;      // set 0's pipeline layout
  VkDescriptorSet descriptors = VK_NULL_HANDLE;  // the slot's set 0
  std::uint32_t slot = 0;
  std::uint32_t count = 0;  // queries of the page, >= 1
  std::uint32_t k = 1;
  std::uint32_t chunk = 1;  // queries per scan/merge pair, from set 0's scratch
  std::uint32_t tile = 0;   // brute force's forced query tile (warm-up); 0 picks one
};

class SearchKernel {
 public:
  virtual ~SearchKernel() = default;
  // Pairs of set 0's scratch one query needs for k (one keeps the binding
  // valid for kernels that keep their scratch elsewhere).
  virtual std::uint64_t scratch_pairs_per_query(std::uint32_t k) const = 0;
  virtual Status record(const Context& context, const PageCommands& page) const = 0;
  // Rows evaluated by the page last run on `slot` (read after its fence).
  virtual std::uint64_t rows_evaluated(std::uint32_t slot, std::uint32_t count) const = 0;
  // The (K class, tile) variants warm_up() dispatches once each.
  virtual std::vector<std::pair<std::uint32_t, std::uint32_t>> warm_up_variants() const = 0;
  virtual std::vector<std::string_view> kernel_names() const = 0;
  // Bytes of the buffers the kernel allocated beyond the base's.
  virtual std::uint64_t device_bytes() const = 0;
};

}  // namespace mmvk::vulkan::detail
