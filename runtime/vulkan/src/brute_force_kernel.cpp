#include "brute_force_kernel.hpp"

#include <algorithm>
#include <vector>

#include "commands.hpp"
#include "pipeline.hpp"
#include "search_layout.hpp"

namespace mmvk::vulkan::detail {

namespace {

void compute_barrier(VkCommandBuffer commands) {
  memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace

// Query tiles held in registers (shared/LAVAPIPE.md: 1/4/16 by batch size;
// 16 and 32 only for k = 1, where the kept pairs are few). Every row's
// texel fetches are shared by the tile: on lavapipe (Zen 3, B = 1024,
// 417k x 27) 32 queries ran 1.13x the speed of 16, and 4 ran 0.6x.
std::uint32_t BruteForceKernel::pick_tile(std::uint32_t batch, std::uint32_t k) const {
  if (k == 1 && batch >= 512 && max_tile_ >= 32) return 32;
  if (k == 1 && batch >= 64 && max_tile_ >= 16) return 16;
  return batch >= 4 && max_tile_ >= 4 ? 4 : 1;
}

Result<BruteForceKernel> BruteForceKernel::create(const Context& context, VkPipelineLayout layout,
                                                  const KernelShape& shape, std::uint32_t max_batch,
                                                  std::uint32_t max_k, std::uint32_t max_tile) {
  BruteForceKernel kernel;
  kernel.shape_ = shape;
  kernel.max_tile_ = max_tile;
  const std::uint32_t largest_class = k_class(max_k);
  for (const std::uint32_t k : {1u, 4u, 16u}) {
    if (k > largest_class) break;
    for (const std::uint32_t tile : {1u, 4u, 16u, 32u}) {
      if (tile > max_batch || tile > max_tile || (tile >= 16 && k != 1)) continue;
      std::vector<SpecValue> spec = shape_spec(shape, k);
      spec.push_back({kSpecTile, tile});
      Result<UniquePipeline> scan = create_compute_pipeline(context, layout, "brute_force_scan", spec);
      if (!scan) return scan.error();
      kernel.variants_.push_back(Variant{k, tile, std::move(*scan)});
    }
    // The scan skips each query's continuing frame; the merge evaluates it.
    std::vector<SpecValue> merge_spec = shape_spec(shape, k);
    merge_spec.push_back({kSpecMergeContinuing, 1});  // a VkBool32
    Result<UniquePipeline> merge = create_compute_pipeline(context, layout, "topk_merge", merge_spec);
    if (!merge) return merge.error();
    kernel.merges_.emplace_back(k, std::move(*merge));
  }
  return kernel;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> BruteForceKernel::variant_keys() const {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keys;
  for (const Variant& v : variants_) keys.emplace_back(v.k_class, v.tile);
  return keys;
}

std::vector<std::string_view> BruteForceKernel::kernel_names() const {
  std::vector<std::string_view> names(variants_.size(), "brute_force_scan");
  names.insert(names.end(), merges_.size(), "topk_merge");
  return names;
}

const BruteForceKernel::Variant* BruteForceKernel::find(std::uint32_t k, std::uint32_t tile) const {
  for (const Variant& v : variants_) {
    if (v.k_class == k && v.tile == tile) return &v;
  }
  return nullptr;
}

Status BruteForceKernel::record(const Context& context, VkCommandBuffer commands, VkPipelineLayout layout,
                                std::uint32_t batch, std::uint32_t k, std::uint32_t chunk, std::uint32_t tile) const {
  const std::uint32_t kc = k_class(k);
  if (tile == 0) tile = pick_tile(std::min(batch, chunk), kc);
  const Variant* variant = find(kc, tile);
  VkPipeline merge = VK_NULL_HANDLE;
  for (const auto& [merge_k, pipeline] : merges_) {
    if (merge_k == kc) merge = pipeline.get();
  }
  if (variant == nullptr || merge == VK_NULL_HANDLE || chunk == 0) {
    return make_error("Vulkan: no brute-force kernel variant for k = " + std::to_string(k) + ", tile " +
                      std::to_string(tile));
  }
  const std::uint32_t wg = shape_.workgroup_size;
  for (std::uint32_t base = 0; base < batch; base += chunk) {
    const std::uint32_t count = std::min(chunk, batch - base);
    SearchPush push{};
    push.scan_rows = shape_.scan_rows;
    push.rows_per_invocation = shape_.rows_per_invocation;
    push.block_count = shape_.block_count;
    push.query_base = base;
    push.query_count = count;
    // The previous chunk's merge read the scratch this scan overwrites.
    if (base != 0) compute_barrier(commands);
    // Tiles along x, so that the workgroups that read the same rows run
    // one after another (brute_force_scan.comp).
    MMVK_TRY(dispatch(context, commands, variant->scan.get(), layout, push, (count + tile - 1) / tile,
                      shape_.block_count / wg, "brute_force_scan"));
    compute_barrier(commands);
    MMVK_TRY(dispatch(context, commands, merge, layout, push, (count + wg - 1) / wg, 1, "topk_merge"));
  }
  return {};
}

}  // namespace mmvk::vulkan::detail
