#include "kernel_shape.hpp"

#include <algorithm>
#include <string>

#include "device_database.hpp"

namespace mmvk::vulkan::detail {

std::uint32_t k_class(std::uint32_t k) { return k <= 1 ? 1 : k <= 4 ? 4 : 16; }

std::vector<std::uint32_t> weighted_channels(const FeatureSchema& schema) {
  std::vector<std::uint32_t> channels;
  for (std::uint32_t c = 0; c < schema.channels.size(); ++c) {
    if (schema.channels[c].dims() != 0) channels.push_back(c);
  }
  return channels;
}

namespace {

// One subgroup per workgroup on CPU drivers (LAVAPIPE.md: 8 invocations);
// at least 64 invocations on GPUs.
std::uint32_t workgroup_size(const Context& context) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  std::uint32_t wg = context.subgroup_size();
  if (context.properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) wg = std::max(wg, 64u);
  wg = std::min({wg, limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]});
  return std::max(wg, 1u);
}

// Rows per invocation: about 1k (LAVAPIPE.md), fewer when a full batch has
// too few query tiles to give every core many invocations (measured on 22k
// frames, B = 1024: 64 rows ran at 60% of the speed of 1024, the
// per-invocation query loads dominating), and at most kMaxScanBlocks blocks.
Result<std::uint32_t> rows_per_invocation(std::uint32_t frames, const VulkanSearchOptions& options) {
  if (options.rows_per_invocation != 0) return options.rows_per_invocation;
  const std::uint32_t full_tiles = (options.max_batch + options.max_tile - 1) / options.max_tile;
  const std::uint32_t blocks_wanted = std::max(8u, 512u / full_tiles);
  std::uint32_t rows = std::clamp<std::uint32_t>((frames / blocks_wanted + 63) / 64 * 64, 64, 1024);
  rows = std::max(rows, (frames + kMaxScanBlocks - 1) / kMaxScanBlocks);
  if (rows > kMaxRowsPerInvocation) {
    return make_error("VulkanSearch: " + std::to_string(frames) + " frames are more than the kernels can scan");
  }
  return rows;
}

// The 32-bit words of the tag masks that some frame uses: a query's tag
// rules on the other words are decided without reading any row.
std::uint32_t tag_words(const Database& database) {
  TagMask used = 0;
  for (const TagMask tags : database.frame_tags()) used |= tags;
  return (used >> 32) != 0 ? 2 : used != 0 ? 1 : 0;
}

// Whether every frame's cost is its weighted sum: multiplier 1, bias 0.
bool unit_cost_terms(const Database& database) {
  const auto one = [](float m) { return m == 1.0f; };
  const auto zero = [](float b) { return b == 0.0f; };
  return std::all_of(database.frame_multiplier().begin(), database.frame_multiplier().end(), one) &&
         std::all_of(database.frame_bias().begin(), database.frame_bias().end(), zero);
}

}  // namespace

Result<KernelShape> make_kernel_shape(const Context& context, const Database& database,
                                      const VulkanSearchOptions& options, bool brute_force) {
  KernelShape shape;
  shape.frame_count = database.frame_count();
  // Only the brute force scans scan_frames; the cluster search uploads none.
  shape.scan_rows = brute_force ? scan_row_count(database) : 0;
  shape.dims = database.dims();
  shape.dim_vec4s = (shape.dims + 3) / 4;
  // Channel ends as a bit mask over dims.
  const FeatureSchema& schema = database.schema();
  const std::vector<std::uint32_t> channels = weighted_channels(schema);
  std::uint32_t end = 0;
  for (const std::uint32_t c : channels) {
    end += schema.channels[c].dims();
    shape.end_mask[(end - 1) / 32] |= 1u << ((end - 1) % 32);
  }
  shape.channels = static_cast<std::uint32_t>(channels.size());
  shape.tag_words = tag_words(database);
  shape.unit_cost_terms = unit_cost_terms(database) ? 1 : 0;
  shape.workgroup_size = workgroup_size(context);
  MMVK_ASSIGN_OR_RETURN(shape.rows_per_invocation, rows_per_invocation(shape.scan_rows, options));
  // The scan's invocations are its blocks; a workgroup's lanes take its
  // rows in turn (brute_force_scan.comp), so blocks come in whole workgroups
  // (at least one, so that the scratch is never empty).
  const std::uint64_t group_rows = std::uint64_t{shape.rows_per_invocation} * shape.workgroup_size;
  const std::uint64_t groups = std::max<std::uint64_t>(1, (shape.scan_rows + group_rows - 1) / group_rows);
  shape.block_count = static_cast<std::uint32_t>(std::min<std::uint64_t>(groups * shape.workgroup_size, UINT32_MAX));
  if (shape.block_count > kMaxScanBlocks) {
    return make_error("VulkanSearch: rows_per_invocation " + std::to_string(shape.rows_per_invocation) + " gives " +
                      std::to_string(shape.block_count) + " blocks, over " + std::to_string(kMaxScanBlocks));
  }
  return shape;
}

std::vector<SpecValue> shape_spec(const KernelShape& shape, std::uint32_t k) {
  return {
      {kSpecWorkgroupSize, shape.workgroup_size},
      {kSpecDimVec4s, shape.dim_vec4s},
      {kSpecDims, shape.dims},
      {kSpecK, k},
      {kSpecChannels, shape.channels},
      {kSpecEndMask0 + 0, shape.end_mask[0]},
      {kSpecEndMask0 + 1, shape.end_mask[1]},
      {kSpecEndMask0 + 2, shape.end_mask[2]},
      {kSpecEndMask0 + 3, shape.end_mask[3]},
      {kSpecTagWords, shape.tag_words},
      {kSpecUnitCostTerms, shape.unit_cost_terms},
  };
}

}  // namespace mmvk::vulkan::detail
