// VulkanClusterSearch: the Vulkan search of the rows a ClusterTable's
// bounds cannot rule out (registry names vulkan-clusters and
// vulkan-nprobe), as ClusterSearch does on the CPU: exact with nprobe = 0
// (same answers as VulkanBruteForce), else the nprobe clusters with the
// nearest centroids searched exactly (same answers as ClusterSearch with
// that nprobe; nprobe >= cluster_count is exact). The kernels are
// shaders/cluster_*.comp (src/cluster_kernel.hpp has their passes); the
// slots, staging and paging are VulkanSearch's.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

struct VulkanClusterOptions {
  std::uint32_t nprobe = 0;  // 0 = exact; else clusters visited per query
  // Per-slot scratch (bound keys, per-block pairs, the work items and their
  // sort by block), sized for the worst case (every query of a chunk
  // visiting every block). Larger chunks share more blocks: the scan
  // evaluates a block once for a tile of up to 8 of the chunk's queries
  // that visit it. The whole budget is allocated at creation.
  std::uint64_t scratch_bytes = std::uint64_t{512} << 20;
};

class VulkanClusterSearch final : public VulkanSearch {
 public:
  // The table is uploaded; it need not outlive the search. Errors: those
  // of VulkanBruteForce::create, and a table from another database or
  // malformed (validate_cluster_table).
  static Result<std::unique_ptr<VulkanClusterSearch>> create(Context& context, const Database& database,
                                                             const ClusterTable& table,
                                                             const VulkanSearchOptions& options = {},
                                                             const VulkanClusterOptions& cluster_options = {});
  std::string_view name() const override { return exact_ ? "vulkan-clusters" : "vulkan-nprobe"; }

 private:
  VulkanClusterSearch(std::unique_ptr<Impl> impl, bool exact);
  bool exact_;
};

}  // namespace mmvk::vulkan
