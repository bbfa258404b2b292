// VulkanBruteForce: the Vulkan search of every row, exact (registry name
// vulkan-brute). Register-tiled scans of the feature matrix and a top-k
// merge (shaders/brute_force_scan.comp, topk_merge.comp); the slots,
// staging and paging are VulkanSearch's.
#pragma once

#include <memory>
#include <string_view>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

class VulkanBruteForce final : public VulkanSearch {
 public:
  // Errors: database too large for the device (texel buffer elements,
  // allocation size), dims over 128, options out of range, out of device
  // memory, missing format support.
  static Result<std::unique_ptr<VulkanBruteForce>> create(Context& context, const Database& database,
                                                          const VulkanSearchOptions& options = {});
  std::string_view name() const override { return "vulkan-brute"; }

 private:
  explicit VulkanBruteForce(std::unique_ptr<Impl> impl);
};

}  // namespace mmvk::vulkan
