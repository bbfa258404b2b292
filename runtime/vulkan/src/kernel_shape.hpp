// What the search kernels are specialized for: the database's shape
// (padded dims, channel ends), the workgroup size and the rows each scan
// invocation covers, chosen once per VulkanSearch. The GLSL side of the
// specialization constants is shaders/kernel_shape.glsl; change both
// together.
#pragma once

#include <cstdint>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "pipeline.hpp"

namespace mmvk::vulkan::detail {

// Specialization constant ids (kernel_shape.glsl).
enum SpecId : std::uint32_t {
  kSpecWorkgroupSize = 0,
  kSpecDimVec4s = 1,
  kSpecDims = 2,
  kSpecTile = 3,   // brute_force_scan, cluster_scan
  kSpecK = 4,
  kSpecChannels = 5,
  kSpecEndMask0 = 6,  // .. kSpecEndMask0 + 3
  kSpecMergeContinuing = 10,  // topk_merge only: evaluate the continuing frame
  kSpecSortStep = 11,         // cluster_sort only: which of its steps
  kSpecTagWords = 12,
  kSpecUnitCostTerms = 13,
};
inline constexpr std::uint32_t kMaxKernelDims = 128;            // four 32-bit end masks
inline constexpr std::uint32_t kMaxRowsPerInvocation = 32768;  // llvmpipe's loop limit is 65,535
inline constexpr std::uint32_t kMaxScanBlocks = 16384;         // topk_merge loop iterations per query

struct KernelShape {
  std::uint32_t frame_count = 0;
  std::uint32_t scan_rows = 0;       // frames the brute-force scan visits (device_database.hpp); 0 for the cluster search
  std::uint32_t dims = 0;
  std::uint32_t dim_vec4s = 0;
  std::uint32_t channels = 0;        // non-empty schema channels
  std::uint32_t end_mask[4] = {};    // bit d: dim d ends a channel
  std::uint32_t tag_words = 2;       // 32-bit tag words any frame uses: 0, 1 (tags 0-31 only) or 2
  std::uint32_t unit_cost_terms = 0; // 1: every frame's cost multiplier is 1 and its bias 0
  std::uint32_t workgroup_size = 1;
  std::uint32_t rows_per_invocation = 1;
  std::uint32_t block_count = 1;     // scan invocations: ceil(scan_rows / (rows_per_invocation x workgroup)) x workgroup, >= 1 workgroup
};

// Kept pairs per query: 1, 4 or 16 (the smallest class >= k).
std::uint32_t k_class(std::uint32_t k);

// The schema channel of each kernel weight: the non-empty channels, in
// order (empty ones add nothing to a cost, so the kernels skip them).
std::vector<std::uint32_t> weighted_channels(const FeatureSchema& schema);

// The shape of `database`'s kernels on this device with these options
// (options already checked by the search's create()); `brute_force`: the
// search scans scan_frames (VulkanBruteForce), else it scans none.
Result<KernelShape> make_kernel_shape(const Context& context, const Database& database,
                                      const VulkanSearchOptions& options, bool brute_force);

// The specialization constants every kernel declares (kernel_shape.glsl)
// for kept-pairs class `k`; kernels with more append theirs.
std::vector<SpecValue> shape_spec(const KernelShape& shape, std::uint32_t k);

}  // namespace mmvk::vulkan::detail
