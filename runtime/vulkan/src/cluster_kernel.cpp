#include "cluster_kernel.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <string>

#include "check.hpp"
#include "pipeline.hpp"

namespace mmvk::vulkan::detail {

namespace {

// shaders/cluster_layout.glsl: ClusterPush.
struct ClusterPush {
  std::uint32_t query_base;
  std::uint32_t query_count;
  std::uint32_t k;
  std::uint32_t round;
  std::uint32_t cluster_count;
  std::uint32_t block_count;
  std::uint32_t nprobe;
  std::uint32_t pad0;
};
static_assert(sizeof(ClusterPush) == 32);

// shaders/cluster_layout.glsl: ClusterQueryState (std430).
struct ClusterQueryState {
  std::uint32_t seed;
  std::uint32_t upper_key;
  std::uint32_t rows;
  std::uint32_t pad0;
  std::uint32_t continuing_pair[2];
  std::uint32_t pad1[2];
};
static_assert(sizeof(ClusterQueryState) == 32);

// Set 1 bindings (cluster_layout.glsl).
enum ClusterBinding : std::uint32_t {
  kBindingMembers = 0,         // uniform texel, R32UI
  kBindingBlockInfo = 1,       // uniform texel, RGBA32UI
  kBindingClusterInfo = 2,     // uniform texel, RGBA32UI
  kBindingClusterVectors = 3,  // uniform texel, RGBA32F
  kBindingBoundKeys = 4,       // storage
  kBindingStates = 5,          // storage
  kBindingBlockPairs = 6,      // storage
  kBindingScanDispatch = 7,    // storage + indirect
  kBindingWorkItems = 8,       // storage
};
constexpr std::uint32_t kClusterBindingCount = 9;
constexpr std::uint32_t kClusterTexelBindings = 4;
constexpr std::uint32_t kClusterStorageBindings = 5;
// The reset value of ScanDispatch: per round (groups x, 1, 1, items).
constexpr std::array<std::uint32_t, 8> kScanDispatchReset = {0, 1, 1, 0, 0, 1, 1, 0};

// Rows per member block, evaluated by kRowLanes invocations (64 rows each
// at most): big clusters split over several workgroups (B = 1 latency).
constexpr std::uint32_t kRowsPerBlock = 512;
constexpr std::uint32_t kRowLanes = 8;  // cluster_layout.glsl
// Loop limits of one invocation (llvmpipe stops loops at 65,535 iterations
// in total): the final merge walks every block and the lanes of the visited
// ones, the nprobe selection walks the clusters 35 times.
constexpr std::uint32_t kMaxBlocks = 7000;
constexpr std::uint32_t kMaxProbeClusters = 1800;

// Between any two steps of a chunk: shader writes, the dispatch-argument
// reset (a transfer) and indirect reads are all ordered.
void full_barrier(VkCommandBuffer commands) {
  constexpr VkPipelineStageFlags stages =
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                          VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  vkCmdPipelineBarrier(commands, stages, stages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace

Result<ClusterKernel> ClusterKernel::create(const Context& context, VkCommandPool pool,
                                            VkDescriptorSetLayout search_layout, const KernelShape& shape,
                                            const Database& database, const ClusterTable& table,
                                            const ClusterKernelOptions& options) {
  const VkDevice device = context.device();
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (limits.maxBoundDescriptorSets < 2 ||
      limits.maxPerStageDescriptorStorageBuffers < kStorageBindings + kClusterStorageBindings ||
      limits.maxPerStageDescriptorSampledImages < kTexelBindings + kClusterTexelBindings ||
      limits.maxPerStageResources < kBindingCount + kClusterBindingCount) {
    return make_error("Vulkan: the device allows too few descriptors per stage for the cluster kernels (2 sets, " +
                      std::to_string(kStorageBindings + kClusterStorageBindings) + " storage buffers and " +
                      std::to_string(kTexelBindings + kClusterTexelBindings) + " texel buffers needed)");
  }
  if (sizeof(ClusterPush) > limits.maxPushConstantsSize) {
    return make_error("Vulkan: the cluster kernels need " + std::to_string(sizeof(ClusterPush)) +
                      " bytes of push constants");
  }
  ClusterKernel kernel;
  kernel.shape_ = shape;
  // 64 invocations per workgroup, also on CPU drivers: most cluster
  // invocations exit at once (pruned blocks), and lavapipe's cost per
  // workgroup added up with 8.
  kernel.shape_.workgroup_size =
      std::min({64u, limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]});
  kernel.max_batch_ = options.max_batch;
  const std::uint32_t clusters = table.cluster_count;
  kernel.cluster_count_ = clusters;
  kernel.nprobe_ = options.nprobe < clusters ? options.nprobe : 0;
  if (clusters == 0) return make_error("Vulkan: the cluster table has no clusters");
  if (kernel.nprobe_ != 0 && clusters > kMaxProbeClusters) {
    return make_error("Vulkan: nprobe search supports at most " + std::to_string(kMaxProbeClusters) +
                      " clusters, the table has " + std::to_string(clusters));
  }

  // Host copies in the kernels' layouts (creation only).
  const std::uint32_t dv = shape.dim_vec4s;
  const std::uint32_t dims = shape.dims;
  std::vector<std::array<std::uint32_t, 4>> block_info;
  std::vector<std::array<std::uint32_t, 4>> cluster_info(std::size_t{clusters} * 3);
  std::vector<float> vectors(std::size_t{clusters} * 3 * dv * 4, 0.0f);
  for (std::uint32_t c = 0; c < clusters; ++c) {
    const std::uint32_t first = table.offsets[c];
    const std::uint32_t end = table.offsets[c + 1];
    const auto first_block = static_cast<std::uint32_t>(block_info.size());
    for (std::uint32_t m = first; m < end; m += kRowsPerBlock) {
      block_info.push_back({c, m, std::min(end, m + kRowsPerBlock), 0});
    }
    const TagMask tag_union = table.tag_union[c];
    const TagMask tag_intersection = table.tag_intersection[c];
    cluster_info[std::size_t{c} * 3] = {table.flags_intersection[c], first, end, first_block};
    cluster_info[std::size_t{c} * 3 + 1] = {static_cast<std::uint32_t>(tag_union),
                                            static_cast<std::uint32_t>(tag_union >> 32),
                                            static_cast<std::uint32_t>(tag_intersection),
                                            static_cast<std::uint32_t>(tag_intersection >> 32)};
    cluster_info[std::size_t{c} * 3 + 2] = {std::bit_cast<std::uint32_t>(table.min_multiplier[c]),
                                            std::bit_cast<std::uint32_t>(table.min_bias[c]),
                                            static_cast<std::uint32_t>(block_info.size()), 0};
    for (std::uint32_t d = 0; d < dims; ++d) {
      const std::size_t at = std::size_t{c} * dims + d;
      vectors[(std::size_t{c} * 3 * dv) * 4 + d] = table.box_min[at];
      vectors[(std::size_t{c} * 3 * dv + dv) * 4 + d] = table.box_max[at];
      vectors[(std::size_t{c} * 3 * dv + 2 * dv) * 4 + d] = table.centroids[at];
    }
  }
  if (block_info.size() > kMaxBlocks) {
    return make_error("Vulkan: the cluster table splits into " + std::to_string(block_info.size()) +
                      " member blocks, over the kernels' " + std::to_string(kMaxBlocks));
  }
  kernel.block_count_ = static_cast<std::uint32_t>(block_info.size());
  if (database.frame_count() != table.members.size()) return make_error("Vulkan: cluster table size mismatch");

  Result<TexelBuffer> members = make_texel_buffer(context, pool, VK_FORMAT_R32_UINT, 4, bytes_of(table.members),
                                             "the cluster members", options.force_staging);
  if (!members) return members.error();
  kernel.members_ = std::move(*members);
  Result<TexelBuffer> blocks = make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(block_info),
                                            "the member blocks", options.force_staging);
  if (!blocks) return blocks.error();
  kernel.block_info_ = std::move(*blocks);
  Result<TexelBuffer> info = make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(cluster_info),
                                          "the cluster info", options.force_staging);
  if (!info) return info.error();
  kernel.cluster_info_ = std::move(*info);
  Result<TexelBuffer> boxes = make_texel_buffer(context, pool, VK_FORMAT_R32G32B32A32_SFLOAT, 16, bytes_of(vectors),
                                           "the cluster boxes and centroids", options.force_staging);
  if (!boxes) return boxes.error();
  kernel.cluster_vectors_ = std::move(*boxes);

  // Set 1 layout and the pipeline layout (set 0 = the search layout).
  Result<UniqueDescriptorSetLayout> set_layout =
      create_set_layout(context, kClusterBindingCount, kClusterTexelBindings);
  if (!set_layout) return set_layout.error();
  kernel.set_layout_ = std::move(*set_layout);
  const std::array<VkDescriptorSetLayout, 2> set_layouts = {search_layout, kernel.set_layout_.get()};
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(ClusterPush)};
  VkPipelineLayoutCreateInfo layout_info{};
  layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout_info.setLayoutCount = 2;
  layout_info.pSetLayouts = set_layouts.data();
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &pipeline_layout));
  kernel.pipeline_layout_ = UniquePipelineLayout(device, pipeline_layout);

  const std::array<VkDescriptorPoolSize, 2> sizes = {{
      {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, kClusterTexelBindings * options.slots},
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kClusterStorageBindings * options.slots},
  }};
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.maxSets = options.slots;
  pool_info.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  pool_info.pPoolSizes = sizes.data();
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &descriptor_pool));
  kernel.descriptor_pool_ = UniqueDescriptorPool(device, descriptor_pool);

  // Per-slot scratch: at least one query, at most max_batch, within the
  // budget and maxStorageBufferRange.
  const std::uint64_t range = limits.maxStorageBufferRange;
  const std::uint64_t pairs_per_query = std::uint64_t{kernel.block_count_} * kRowLanes * k_class(options.max_k);
  const std::uint64_t per_query_bytes = (pairs_per_query + clusters) * 8;
  std::uint64_t chunk = std::clamp<std::uint64_t>(options.scratch_bytes / per_query_bytes, 1, options.max_batch);
  // The indirect scans: every block of the chunk visited must stay within
  // maxComputeWorkGroupCount[0] workgroups.
  const std::uint64_t items_per_group = kernel.shape_.workgroup_size / kRowLanes;
  chunk = std::min({chunk, range / (pairs_per_query * 8), range / (std::uint64_t{clusters} * 8),
                    std::uint64_t{limits.maxComputeWorkGroupCount[1]},
                    std::uint64_t{limits.maxComputeWorkGroupCount[0]} * items_per_group / kernel.block_count_});
  if (chunk == 0) return make_error("Vulkan: one query's cluster scratch exceeds maxStorageBufferRange");
  kernel.bound_capacity_ = chunk * clusters;
  kernel.pair_capacity_ = chunk * pairs_per_query;

  std::vector<VkDescriptorSetLayout> layouts(options.slots, kernel.set_layout_.get());
  std::vector<VkDescriptorSet> sets(options.slots);
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = descriptor_pool;
  allocate.descriptorSetCount = options.slots;
  allocate.pSetLayouts = layouts.data();
  MMVK_VK_CHECK(vkAllocateDescriptorSets(device, &allocate, sets.data()));
  kernel.slots_.resize(options.slots);
  for (std::uint32_t s = 0; s < options.slots; ++s) {
    SlotScratch& slot = kernel.slots_[s];
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    Result<Buffer> bound_keys =
        create_buffer(context, kernel.bound_capacity_ * 8, storage, MemoryUse::DeviceLocal, "the cluster bound keys");
    if (!bound_keys) return bound_keys.error();
    slot.bound_keys = std::move(*bound_keys);
    Result<Buffer> states = create_buffer(context, std::uint64_t{options.max_batch} * sizeof(ClusterQueryState), storage,
                                          MemoryUse::HostMapped, "the cluster query states");
    if (!states) return states.error();
    slot.states = std::move(*states);
    Result<Buffer> pairs =
        create_buffer(context, kernel.pair_capacity_ * 8, storage, MemoryUse::DeviceLocal, "the cluster block pairs");
    if (!pairs) return pairs.error();
    slot.block_pairs = std::move(*pairs);
    Result<Buffer> scan_dispatch =
        create_buffer(context, sizeof(kScanDispatchReset),
                      storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      MemoryUse::DeviceLocal, "the cluster scan dispatch arguments");
    if (!scan_dispatch) return scan_dispatch.error();
    slot.scan_dispatch = std::move(*scan_dispatch);
    Result<Buffer> work_items = create_buffer(context, chunk * kernel.block_count_ * 8, storage, MemoryUse::DeviceLocal,
                                              "the cluster work items");
    if (!work_items) return work_items.error();
    slot.work_items = std::move(*work_items);
    slot.set = sets[s];

    const std::array<VkBufferView, kClusterTexelBindings> views = {
        kernel.members_.view.get(), kernel.block_info_.view.get(), kernel.cluster_info_.view.get(),
        kernel.cluster_vectors_.view.get()};
    const std::array<const Buffer*, kClusterStorageBindings> buffers = {
        &slot.bound_keys, &slot.states, &slot.block_pairs, &slot.scan_dispatch, &slot.work_items};
    std::array<VkDescriptorBufferInfo, kClusterStorageBindings> buffer_infos{};
    std::array<VkWriteDescriptorSet, kClusterBindingCount> writes{};
    for (std::uint32_t b = 0; b < kClusterBindingCount; ++b) {
      writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[b].dstSet = slot.set;
      writes[b].dstBinding = b;
      writes[b].descriptorCount = 1;
      if (b < kClusterTexelBindings) {
        writes[b].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        writes[b].pTexelBufferView = &views[b];
      } else {
        const std::uint32_t i = b - kClusterTexelBindings;
        buffer_infos[i] = {buffers[i]->buffer.get(), 0, VK_WHOLE_SIZE};
        writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[b].pBufferInfo = &buffer_infos[i];
      }
    }
    vkUpdateDescriptorSets(device, kClusterBindingCount, writes.data(), 0, nullptr);
  }

  // Pipelines: bounds and select once, scan and merge per K class.
  const auto spec_for = [&](std::uint32_t k) {
    return std::array<SpecValue, 9>{{
        {kSpecWorkgroupSize, kernel.shape_.workgroup_size},
        {kSpecDimVec4s, shape.dim_vec4s},
        {kSpecDims, shape.dims},
        {kSpecK, k},
        {kSpecChannels, shape.channels},
        {kSpecEndMask0 + 0, shape.end_mask[0]},
        {kSpecEndMask0 + 1, shape.end_mask[1]},
        {kSpecEndMask0 + 2, shape.end_mask[2]},
        {kSpecEndMask0 + 3, shape.end_mask[3]},
    }};
  };
  const auto base_spec = spec_for(1);
  Result<UniquePipeline> bounds = create_compute_pipeline(context, pipeline_layout, "cluster_bounds", base_spec);
  if (!bounds) return bounds.error();
  kernel.bounds_ = std::move(*bounds);
  Result<UniquePipeline> select = create_compute_pipeline(context, pipeline_layout, "cluster_select", base_spec);
  if (!select) return select.error();
  kernel.select_ = std::move(*select);
  for (const std::uint32_t k : {1u, 4u, 16u}) {
    if (k > k_class(options.max_k)) break;
    const auto spec = spec_for(k);
    Result<UniquePipeline> scan = create_compute_pipeline(context, pipeline_layout, "cluster_scan", spec);
    if (!scan) return scan.error();
    Result<UniquePipeline> merge = create_compute_pipeline(context, pipeline_layout, "cluster_merge", spec);
    if (!merge) return merge.error();
    kernel.variants_.push_back(Variant{k, std::move(*scan), std::move(*merge)});
  }
  return kernel;
}

std::vector<std::uint32_t> ClusterKernel::k_classes() const {
  std::vector<std::uint32_t> classes;
  for (const Variant& v : variants_) classes.push_back(v.k_class);
  return classes;
}

std::uint32_t ClusterKernel::chunk_for(std::uint32_t kc) const {
  const std::uint64_t chunk =
      std::min(bound_capacity_ / cluster_count_, pair_capacity_ / (std::uint64_t{block_count_} * kRowLanes * kc));
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(chunk, max_batch_));
}

Status ClusterKernel::record(const Context& context, VkCommandBuffer commands, std::uint32_t slot,
                             VkDescriptorSet search_set, std::uint32_t batch, std::uint32_t k) const {
  const std::uint32_t kc = k_class(k);
  const Variant* variant = nullptr;
  for (const Variant& v : variants_) {
    if (v.k_class == kc) variant = &v;
  }
  if (variant == nullptr || slot >= slots_.size()) {
    return make_error("Vulkan: no cluster kernel variant for k = " + std::to_string(k));
  }
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  const std::uint32_t wg = shape_.workgroup_size;
  const std::uint32_t chunk = chunk_for(kc);
  const std::array<VkDescriptorSet, 2> sets = {search_set, slots_[slot].set};
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_.get(), 0, 2, sets.data(), 0,
                          nullptr);
  const VkBuffer scan_dispatch = slots_[slot].scan_dispatch.buffer.get();
  const auto dispatch = [&](VkPipeline pipeline, const ClusterPush& push, std::uint32_t groups_x,
                            std::uint32_t groups_y, const char* name) -> Status {
    if (groups_x == 0 || groups_y == 0 || groups_x > limits.maxComputeWorkGroupCount[0] ||
        groups_y > limits.maxComputeWorkGroupCount[1]) {
      return make_error(std::string("Vulkan: dispatch of ") + name + " with " + std::to_string(groups_x) + " x " +
                        std::to_string(groups_y) + " workgroups is empty or exceeds maxComputeWorkGroupCount");
    }
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdPushConstants(commands, pipeline_layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(ClusterPush), &push);
    vkCmdDispatch(commands, groups_x, groups_y, 1);
    return {};
  };
  for (std::uint32_t base = 0; base < batch; base += chunk) {
    const std::uint32_t count = std::min(chunk, batch - base);
    ClusterPush push{base, count, k, 0, cluster_count_, block_count_, nprobe_, 0};
    const std::uint32_t query_groups = (count + wg - 1) / wg;
    // The previous chunk's last merge read the scratch this chunk rewrites.
    if (base != 0) full_barrier(commands);
    vkCmdUpdateBuffer(commands, scan_dispatch, 0, sizeof(kScanDispatchReset), kScanDispatchReset.data());
    MMVK_TRY(dispatch(bounds_.get(), push, (cluster_count_ + wg - 1) / wg, count, "cluster_bounds"));
    full_barrier(commands);
    MMVK_TRY(dispatch(select_.get(), push, query_groups, 1, "cluster_select"));
    for (std::uint32_t round = 0; round < 2; ++round) {
      push.round = round;
      full_barrier(commands);
      // The work items (and so the group count) were listed on the GPU;
      // the chunk cap above keeps the count within the device's limit.
      vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, variant->scan.get());
      vkCmdPushConstants(commands, pipeline_layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(ClusterPush), &push);
      vkCmdDispatchIndirect(commands, scan_dispatch, std::uint64_t{round} * 16);
      full_barrier(commands);
      MMVK_TRY(dispatch(variant->merge.get(), push, query_groups, 1, "cluster_merge"));
    }
  }
  return {};
}

std::uint64_t ClusterKernel::rows_evaluated(std::uint32_t slot, std::uint32_t batch) const {
  const auto* states = static_cast<const ClusterQueryState*>(slots_[slot].states.mapped);
  std::uint64_t rows = 0;
  for (std::uint32_t q = 0; q < batch; ++q) rows += states[q].rows;
  return rows;
}

}  // namespace mmvk::vulkan::detail
