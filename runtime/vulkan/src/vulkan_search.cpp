#include "mmvk/vulkan/vulkan_search.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <vector>

#include "brute_force_kernel.hpp"
#include "check.hpp"
#include "cluster_kernel.hpp"
#include "device_database.hpp"
#include "gpu_layout.hpp"
#include "memory.hpp"
#include "pipeline.hpp"

namespace mmvk::vulkan {

using namespace detail;

namespace {

constexpr std::uint32_t kMaxRowsPerInvocation = 32768;  // llvmpipe's loop limit is 65,535
constexpr std::uint32_t kMaxBlocks = 16384;             // merge loop iterations per query

// Per-submission resources: a submit fills a free slot, wait() frees it.
struct Slot {
  Buffer queries;  // [max_batch x dim_vec4s] vec4
  Buffer params;   // [max_batch] QueryGpu
  Buffer weights;  // [max_batch x channels] float
  Buffer scratch;  // [chunk x blocks x K] uvec2
  Buffer results;  // [max_batch x K] uvec2
  UniqueFence fence;
  VkDescriptorSet descriptors = VK_NULL_HANDLE;  // freed with the pool
  VkCommandBuffer commands = VK_NULL_HANDLE;     // freed with the pool
  std::vector<Match> validation_out;             // [max_batch x max_k], a span for validate_search
  bool in_flight = false;
  std::uint64_t serial = 0;
  std::uint32_t batch = 0;
  std::uint32_t k = 0;
};

float decode_cost(std::uint32_t key) {
  const std::uint32_t bits = (key & 0x80000000u) != 0 ? key & 0x7FFFFFFFu : ~key;
  return std::bit_cast<float>(bits);
}

}  // namespace

struct VulkanSearch::Impl {
  Context* context = nullptr;
  const Database* database = nullptr;
  VulkanSearchOptions options;
  KernelShape shape;
  std::vector<std::uint32_t> channel_of_weight;  // schema channel of each kernel weight (non-empty channels)
  std::uint64_t scratch_pairs = 0;               // per slot
  SearchStats stats;
  std::optional<double> last_kernel_seconds;
  std::uint64_t next_serial = 1;

  // Declaration order = dependency order (destroyed in reverse).
  UniqueDescriptorSetLayout set_layout;
  UniquePipelineLayout pipeline_layout;
  UniqueDescriptorPool descriptor_pool;
  UniqueCommandPool command_pool;
  UniqueQueryPool timestamps;  // 2 per slot; empty without timestamp support
  DeviceDatabase device_database;
  BruteForceKernel kernel;
  std::vector<Slot> slots;
  std::optional<ClusterKernel> clusters;  // ClustersExact and NProbe modes

  ~Impl() {
    // Nothing may be destroyed while the GPU still uses it.
    for (Slot& slot : slots) {
      if (slot.in_flight) {
        const VkFence fence = slot.fence.get();
        vkWaitForFences(context->device(), 1, &fence, VK_TRUE, UINT64_MAX);
      }
    }
  }

  Status create_layouts();
  Status create_slots();
  Status write_descriptors(Slot& slot);
  std::uint32_t chunk_for(std::uint32_t k) const {
    const std::uint64_t per_query = kernel.scratch_pairs_per_query(k);
    std::uint64_t chunk = std::min<std::uint64_t>(options.max_batch, scratch_pairs / per_query);
    if (chunk >= 16) chunk -= chunk % 16;  // whole query tiles per chunk
    return static_cast<std::uint32_t>(chunk);
  }
  Result<Ticket> submit(const QueryBatch& batch, std::uint32_t k, std::uint32_t forced_tile);
  Result<Slot*> find_ticket(const Ticket& ticket, const char* caller);
  Status wait(const Ticket& ticket, std::span<Match> out);
};

Status VulkanSearch::Impl::create_layouts() {
  MMVK_TRY(check_binding_limits(*context));
  const VkDevice device = context->device();
  Result<UniqueDescriptorSetLayout> created = create_set_layout(*context, kBindingCount, kTexelBindings);
  if (!created) return created.error();
  set_layout = std::move(*created);

  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(SearchPush)};
  VkPipelineLayoutCreateInfo layout_info{};
  layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout_info.setLayoutCount = 1;
  const VkDescriptorSetLayout set_layout_handle = set_layout.get();
  layout_info.pSetLayouts = &set_layout_handle;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  VkPipelineLayout pipeline_layout_handle = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &pipeline_layout_handle));
  pipeline_layout = UniquePipelineLayout(device, pipeline_layout_handle);

  const std::uint32_t slot_count = options.slots;
  const std::array<VkDescriptorPoolSize, 2> sizes = {{
      {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, kTexelBindings * slot_count},
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kStorageBindings * slot_count},
  }};
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.maxSets = slot_count;
  pool_info.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  pool_info.pPoolSizes = sizes.data();
  VkDescriptorPool pool_handle = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &pool_handle));
  descriptor_pool = UniqueDescriptorPool(device, pool_handle);

  VkCommandPoolCreateInfo command_info{};
  command_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  command_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  command_info.queueFamilyIndex = context->queue_family();
  VkCommandPool command_handle = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateCommandPool(device, &command_info, nullptr, &command_handle));
  command_pool = UniqueCommandPool(device, command_handle);

  if (context->timestamp_valid_bits() != 0) {
    VkQueryPoolCreateInfo query_info{};
    query_info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = 2 * slot_count;
    VkQueryPool query_handle = VK_NULL_HANDLE;
    MMVK_VK_CHECK(vkCreateQueryPool(device, &query_info, nullptr, &query_handle));
    timestamps = UniqueQueryPool(device, query_handle);
  }
  return {};
}

Status VulkanSearch::Impl::create_slots() {
  const VkDevice device = context->device();
  const std::uint64_t max_batch = options.max_batch;
  const std::uint32_t largest_k = k_class(options.max_k);
  const std::uint64_t storage_range = context->properties().limits.maxStorageBufferRange;
  const std::uint64_t per_query_max = kernel.scratch_pairs_per_query(options.max_k) * sizeof(std::uint32_t) * 2;
  std::uint64_t scratch_bytes = std::min(options.scratch_bytes, max_batch * per_query_max);
  scratch_bytes = std::max(scratch_bytes, per_query_max);  // at least one query per chunk
  if (scratch_bytes > storage_range) {
    return make_error("Vulkan: one query's scratch (" + std::to_string(per_query_max) +
                      " bytes) exceeds maxStorageBufferRange (" + std::to_string(storage_range) +
                      "); lower max_k or raise rows_per_invocation");
  }
  scratch_pairs = scratch_bytes / 8;

  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const struct {
    Buffer Slot::*member;
    std::uint64_t bytes;
    const char* what;
  } buffers[] = {
      {&Slot::queries, max_batch * shape.dim_vec4s * 16, "the query buffer"},
      {&Slot::params, max_batch * sizeof(QueryGpu), "the query parameter buffer"},
      {&Slot::weights, max_batch * std::max(shape.channels, 1u) * sizeof(float), "the weight buffer"},
      {&Slot::scratch, scratch_bytes, "the scratch buffer"},
      {&Slot::results, max_batch * largest_k * 8, "the result buffer"},
  };
  slots.resize(options.slots);
  std::vector<VkDescriptorSetLayout> layouts(options.slots, set_layout.get());
  std::vector<VkDescriptorSet> sets(options.slots);
  VkDescriptorSetAllocateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  set_info.descriptorPool = descriptor_pool.get();
  set_info.descriptorSetCount = options.slots;
  set_info.pSetLayouts = layouts.data();
  MMVK_VK_CHECK(vkAllocateDescriptorSets(device, &set_info, sets.data()));
  std::vector<VkCommandBuffer> commands(options.slots);
  VkCommandBufferAllocateInfo command_info{};
  command_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  command_info.commandPool = command_pool.get();
  command_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  command_info.commandBufferCount = options.slots;
  MMVK_VK_CHECK(vkAllocateCommandBuffers(device, &command_info, commands.data()));

  for (std::uint32_t s = 0; s < options.slots; ++s) {
    Slot& slot = slots[s];
    for (const auto& b : buffers) {
      Result<Buffer> buffer = create_buffer(*context, b.bytes, storage, MemoryUse::HostMapped, b.what);
      if (!buffer) return buffer.error();
      slot.*(b.member) = std::move(*buffer);
    }
    // Padding lanes of the query vectors stay zero from here on.
    std::memset(slot.queries.mapped, 0, slot.queries.size);
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence fence = VK_NULL_HANDLE;
    MMVK_VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &fence));
    slot.fence = UniqueFence(device, fence);
    slot.descriptors = sets[s];
    slot.commands = commands[s];
    slot.validation_out.resize(max_batch * options.max_k);
    MMVK_TRY(write_descriptors(slot));
  }
  return {};
}

Status VulkanSearch::Impl::write_descriptors(Slot& slot) {
  const std::array<VkBufferView, kTexelBindings> views = {
      device_database.features.view.get(), device_database.frame_meta.view.get(), device_database.frame_cost.view.get()};
  const std::array<const Buffer*, kStorageBindings> storage = {&slot.queries, &slot.params, &slot.weights,
                                                               &slot.scratch, &slot.results};
  std::array<VkDescriptorBufferInfo, kStorageBindings> infos{};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (std::uint32_t b = 0; b < kBindingCount; ++b) {
    VkWriteDescriptorSet& w = writes[b];
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = slot.descriptors;
    w.dstBinding = b;
    w.descriptorCount = 1;
    if (b < kTexelBindings) {
      w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
      w.pTexelBufferView = &views[b];
    } else {
      const Buffer* buffer = storage[b - kTexelBindings];
      infos[b - kTexelBindings] = {buffer->buffer.get(), 0, VK_WHOLE_SIZE};
      w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w.pBufferInfo = &infos[b - kTexelBindings];
    }
  }
  vkUpdateDescriptorSets(context->device(), kBindingCount, writes.data(), 0, nullptr);
  return {};
}

Result<std::unique_ptr<VulkanSearch>> VulkanSearch::create(Context& context, const Database& database,
                                                           const VulkanSearchOptions& options,
                                                           const ClusterTable* clusters) {
  if (options.max_batch == 0) return make_error("VulkanSearch: max_batch must be >= 1");
  if (options.max_k < 1 || options.max_k > kMaxK) {
    return make_error("VulkanSearch: max_k = " + std::to_string(options.max_k) + " is out of range [1, " +
                      std::to_string(kMaxK) + "]");
  }
  if (options.slots == 0) return make_error("VulkanSearch: slots must be >= 1");
  if (options.max_tile != 1 && options.max_tile != 4 && options.max_tile != 16 && options.max_tile != 32) {
    return make_error("VulkanSearch: max_tile must be 1, 4, 16 or 32, got " + std::to_string(options.max_tile));
  }
  if (options.rows_per_invocation > kMaxRowsPerInvocation) {
    return make_error("VulkanSearch: rows_per_invocation " + std::to_string(options.rows_per_invocation) +
                      " is over " + std::to_string(kMaxRowsPerInvocation));
  }
  if (database.frame_count() == 0) return make_error("VulkanSearch: the database is empty");
  if (database.dims() > kMaxKernelDims) {
    return make_error("VulkanSearch: the database has " + std::to_string(database.dims()) +
                      " dims; the Vulkan kernels support at most " + std::to_string(kMaxKernelDims));
  }
  if (clusters != nullptr) {
    if (clusters->database_hash != database.content_hash() || clusters->dims != database.dims() ||
        clusters->members.size() != database.frame_count() || clusters->offsets.size() != clusters->cluster_count + 1u) {
      return make_error("VulkanSearch: the cluster table does not belong to this database (hash, dims or frame count differ)");
    }
  }
  if (options.mode != SearchMode::BruteForce) {
    if (clusters == nullptr) return make_error("VulkanSearch: cluster modes need a ClusterTable");
    MMVK_TRY(validate_cluster_table(*clusters, database));
    if (options.mode == SearchMode::NProbe && options.nprobe == 0) {
      return make_error("VulkanSearch: nprobe must be >= 1 in NProbe mode");
    }
  }

  auto impl = std::make_unique<Impl>();
  impl->context = &context;
  impl->database = &database;
  impl->options = options;

  // Kernel shape: channel ends as a bit mask over dims (empty channels add
  // nothing to the total, so they are skipped).
  KernelShape& shape = impl->shape;
  shape.frame_count = database.frame_count();
  shape.dims = database.dims();
  shape.dim_vec4s = (shape.dims + 3) / 4;
  std::uint32_t end = 0;
  const FeatureSchema& schema = database.schema();
  for (std::uint32_t c = 0; c < schema.channels.size(); ++c) {
    const std::uint32_t dims = schema.channels[c].dims();
    if (dims == 0) continue;
    end += dims;
    shape.end_mask[(end - 1) / 32] |= 1u << ((end - 1) % 32);
    impl->channel_of_weight.push_back(c);
  }
  shape.channels = static_cast<std::uint32_t>(impl->channel_of_weight.size());
  // One subgroup per workgroup on CPU drivers (LAVAPIPE.md: 8 invocations);
  // at least 64 invocations on GPUs.
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  std::uint32_t wg = context.subgroup_size();
  if (context.properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) wg = std::max(wg, 64u);
  wg = std::min({wg, limits.maxComputeWorkGroupInvocations, limits.maxComputeWorkGroupSize[0]});
  shape.workgroup_size = std::max(wg, 1u);
  // Rows per invocation: about 1k (LAVAPIPE.md), fewer when a full batch
  // has too few query tiles to give every core many invocations (measured
  // on 22k frames, B = 1024: 64 rows ran at 60% of the speed of 1024, the
  // per-invocation query loads dominating), and at most kMaxBlocks blocks.
  const std::uint32_t frames = shape.frame_count;
  std::uint32_t rows = options.rows_per_invocation;
  if (rows == 0) {
    const std::uint32_t full_tiles = (options.max_batch + options.max_tile - 1) / options.max_tile;
    const std::uint32_t blocks_wanted = std::max(8u, 512u / full_tiles);
    rows = std::clamp<std::uint32_t>((frames / blocks_wanted + 63) / 64 * 64, 64, 1024);
    rows = std::max(rows, (frames + kMaxBlocks - 1) / kMaxBlocks);
    if (rows > kMaxRowsPerInvocation) {
      return make_error("VulkanSearch: " + std::to_string(frames) + " frames are more than the kernels can scan");
    }
  }
  shape.rows_per_invocation = rows;
  shape.block_count = (frames + rows - 1) / rows;
  if (shape.block_count > kMaxBlocks) {
    return make_error("VulkanSearch: rows_per_invocation " + std::to_string(rows) + " gives " +
                      std::to_string(shape.block_count) + " blocks, over " + std::to_string(kMaxBlocks));
  }

  MMVK_TRY(impl->create_layouts());
  Result<DeviceDatabase> device_database =
      upload_database(context, impl->command_pool.get(), database, options.force_staging_upload);
  if (!device_database) return device_database.error();
  impl->device_database = std::move(*device_database);
  Result<BruteForceKernel> kernel =
      BruteForceKernel::create(context, impl->pipeline_layout.get(), shape, options.max_batch, options.max_k,
                               options.max_tile);
  if (!kernel) return kernel.error();
  impl->kernel = std::move(*kernel);
  MMVK_TRY(impl->create_slots());
  if (options.mode != SearchMode::BruteForce) {
    ClusterKernelOptions cluster_options;
    cluster_options.max_batch = options.max_batch;
    cluster_options.max_k = options.max_k;
    cluster_options.slots = options.slots;
    cluster_options.nprobe = options.mode == SearchMode::NProbe ? options.nprobe : 0;
    cluster_options.scratch_bytes = options.scratch_bytes;
    cluster_options.force_staging = options.force_staging_upload;
    Result<ClusterKernel> cluster_kernel = ClusterKernel::create(
        context, impl->command_pool.get(), impl->set_layout.get(), shape, database, *clusters, cluster_options);
    if (!cluster_kernel) return cluster_kernel.error();
    impl->clusters.emplace(std::move(*cluster_kernel));
  }

  if (options.warm_up) {
    // One dispatch of every variant: lavapipe compiles at the first one.
    std::vector<float> queries;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> variants = impl->kernel.variant_keys();
    if (impl->clusters) {
      variants.clear();
      for (const std::uint32_t kc : impl->clusters->k_classes()) variants.emplace_back(kc, 1);
    }
    for (const auto& [kc, tile] : variants) {
      queries.assign(database.features().begin(), database.features().begin() + database.dims());
      std::vector<float> batch_features;
      for (std::uint32_t t = 0; t < tile; ++t) batch_features.insert(batch_features.end(), queries.begin(), queries.end());
      const QueryBatch batch{batch_features, {}, tile};
      const std::uint32_t k = std::min(kc, options.max_k);
      Result<Ticket> ticket = impl->submit(batch, k, tile);
      if (!ticket) return ticket.error();
      std::vector<Match> out(std::size_t{tile} * k);
      MMVK_TRY(impl->wait(*ticket, out));
    }
    impl->stats = {};
  }
  return std::unique_ptr<VulkanSearch>(new VulkanSearch(std::move(impl)));
}

VulkanSearch::VulkanSearch(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanSearch::~VulkanSearch() = default;

std::string_view VulkanSearch::name() const {
  switch (impl_->options.mode) {
    case SearchMode::ClustersExact: return "vulkan-clusters";
    case SearchMode::NProbe: return "vulkan-nprobe";
    case SearchMode::BruteForce: break;
  }
  return "vulkan-brute-force";
}
const Database& VulkanSearch::database() const { return *impl_->database; }
SearchStats VulkanSearch::stats() const { return impl_->stats; }
void VulkanSearch::reset_stats() { impl_->stats = {}; }
std::optional<double> VulkanSearch::last_kernel_seconds() const { return impl_->last_kernel_seconds; }
const VulkanSearchOptions& VulkanSearch::options() const { return impl_->options; }
std::uint32_t VulkanSearch::rows_per_invocation() const { return impl_->shape.rows_per_invocation; }
std::uint32_t VulkanSearch::workgroup_size() const { return impl_->shape.workgroup_size; }

Result<Ticket> VulkanSearch::submit(const QueryBatch& batch, std::uint32_t k) { return impl_->submit(batch, k, 0); }

Result<Ticket> VulkanSearch::Impl::submit(const QueryBatch& batch, std::uint32_t k, std::uint32_t forced_tile) {
  if (batch.size > options.max_batch) {
    return make_error("VulkanSearch: batch of " + std::to_string(batch.size) + " queries is over max_batch = " +
                      std::to_string(options.max_batch));
  }
  if (k > options.max_k && k <= kMaxK) {
    return make_error("VulkanSearch: k = " + std::to_string(k) + " is over max_k = " + std::to_string(options.max_k));
  }
  auto free_slot = std::find_if(slots.begin(), slots.end(), [](const Slot& s) { return !s.in_flight; });
  if (free_slot == slots.end()) {
    return make_error("VulkanSearch: all " + std::to_string(slots.size()) +
                      " submission slots are in flight; wait() for a ticket first");
  }
  Slot& slot = *free_slot;
  const std::span<const Match> validation_out(slot.validation_out.data(), batch.size * std::size_t{k});
  MMVK_TRY(validate_search(*database, batch, k, validation_out));

  const std::uint32_t count = static_cast<std::uint32_t>(batch.size);
  const std::uint32_t dims = shape.dims;
  const std::uint32_t padded = shape.dim_vec4s * 4;
  auto* queries = static_cast<float*>(slot.queries.mapped);
  auto* params = static_cast<QueryGpu*>(slot.params.mapped);
  auto* weights = static_cast<float*>(slot.weights.mapped);
  const QueryParams default_params;
  for (std::uint32_t q = 0; q < count; ++q) {
    std::memcpy(queries + std::size_t{q} * padded, batch.features.data() + std::size_t{q} * dims, dims * sizeof(float));
    const QueryParams& p = batch.params.empty() ? default_params : batch.params[q];
    QueryGpu gpu{};
    gpu.continuing_frame = p.continuing_frame;
    gpu.exclusion_window = p.exclusion_window;
    gpu.require_lo = static_cast<std::uint32_t>(p.require_all);
    gpu.require_hi = static_cast<std::uint32_t>(p.require_all >> 32);
    gpu.exclude_lo = static_cast<std::uint32_t>(p.exclude_any);
    gpu.exclude_hi = static_cast<std::uint32_t>(p.exclude_any >> 32);
    gpu.window_clip = kNoFrame;
    if (p.continuing_frame != kNoFrame && p.exclusion_window > 0) {
      const std::uint32_t clip_index = database->frame_clip()[p.continuing_frame];
      const Clip& clip = database->clips()[clip_index];
      gpu.window_clip = clip_index;
      gpu.clip_first = clip.first_frame;
      gpu.clip_count = clip.frame_count;
      gpu.clip_loop = clip.loop ? 1u : 0u;
    }
    gpu.continuing_bias = p.continuing_bias;
    params[q] = gpu;
    for (std::uint32_t c = 0; c < shape.channels; ++c) {
      weights[std::size_t{q} * shape.channels + c] = p.channel_weights[channel_of_weight[c]];
    }
  }

  slot.serial = next_serial++;
  slot.batch = count;
  slot.k = k;
  if (count == 0) {
    slot.in_flight = true;  // nothing to run; wait() returns at once
    return Ticket{static_cast<std::uint32_t>(&slot - slots.data()), slot.serial};
  }

  const std::uint32_t chunk = chunk_for(k);
  if (chunk == 0) return make_error("VulkanSearch: the scratch buffer cannot hold one query for k = " + std::to_string(k));
  const VkCommandBuffer commands = slot.commands;
  const std::uint32_t slot_index = static_cast<std::uint32_t>(&slot - slots.data());
  MMVK_VK_CHECK(vkResetCommandBuffer(commands, 0));
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  MMVK_VK_CHECK(vkBeginCommandBuffer(commands, &begin));
  if (timestamps) {
    vkCmdResetQueryPool(commands, timestamps.get(), 2 * slot_index, 2);
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps.get(), 2 * slot_index);
  }
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.get(), 0, 1, &slot.descriptors, 0,
                          nullptr);
  const Status recorded =
      clusters ? clusters->record(*context, commands, slot_index, slot.descriptors, count, k)
               : kernel.record(*context, commands, pipeline_layout.get(), count, k, chunk, forced_tile);
  if (!recorded) {
    vkEndCommandBuffer(commands);
    return recorded.error();
  }
  // Results become visible to the host once the fence signals.
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                       nullptr, 0, nullptr);
  if (timestamps) {
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps.get(), 2 * slot_index + 1);
  }
  MMVK_VK_CHECK(vkEndCommandBuffer(commands));

  const VkFence fence = slot.fence.get();
  MMVK_VK_CHECK(vkResetFences(context->device(), 1, &fence));
  VkSubmitInfo submit_info{};
  submit_info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit_info.commandBufferCount = 1;
  submit_info.pCommandBuffers = &commands;
  MMVK_VK_CHECK(vkQueueSubmit(context->queue(), 1, &submit_info, fence));
  slot.in_flight = true;
  stats.queries += count;
  // Cluster modes count their rows on the GPU (added in wait()).
  if (!clusters) stats.rows_evaluated += std::uint64_t{count} * shape.frame_count;
  return Ticket{slot_index, slot.serial};
}

Result<Slot*> VulkanSearch::Impl::find_ticket(const Ticket& ticket, const char* caller) {
  if (ticket.slot >= slots.size() || !slots[ticket.slot].in_flight || slots[ticket.slot].serial != ticket.serial) {
    return make_error(std::string("VulkanSearch: ") + caller + " of an unknown or already waited-for ticket");
  }
  return &slots[ticket.slot];
}

Result<bool> VulkanSearch::poll(const Ticket& ticket) const {
  Result<Slot*> slot = impl_->find_ticket(ticket, "poll()");
  if (!slot) return slot.error();
  if ((*slot)->batch == 0) return true;
  const VkResult status = vkGetFenceStatus(impl_->context->device(), (*slot)->fence.get());
  if (status == VK_SUCCESS) return true;
  if (status == VK_NOT_READY) return false;
  return vk_error(status, "vkGetFenceStatus(device, slot.fence)", __FILE__, __LINE__);
}

Status VulkanSearch::wait(const Ticket& ticket, std::span<Match> out) { return impl_->wait(ticket, out); }

Status VulkanSearch::Impl::wait(const Ticket& ticket, std::span<Match> out) {
  Result<Slot*> found = find_ticket(ticket, "wait()");
  if (!found) return found.error();
  Slot& slot = **found;
  const std::size_t expected = std::size_t{slot.batch} * slot.k;
  if (out.size() != expected) {
    return make_error("VulkanSearch: wait() got " + std::to_string(out.size()) + " result slots, expected " +
                      std::to_string(slot.batch) + " queries x k=" + std::to_string(slot.k));
  }
  if (slot.batch == 0) {
    slot.in_flight = false;
    return {};
  }
  const VkDevice device = context->device();
  const VkFence fence = slot.fence.get();
  const VkResult waited = vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX);
  slot.in_flight = false;  // a lost device will not finish it either
  if (waited != VK_SUCCESS) {
    return vk_error(waited, "vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX)", __FILE__, __LINE__);
  }

  if (timestamps) {
    std::array<std::uint64_t, 2> ticks{};
    MMVK_VK_CHECK(vkGetQueryPoolResults(device, timestamps.get(), 2 * ticket.slot, 2, sizeof(ticks), ticks.data(),
                                        sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const std::uint32_t bits = context->timestamp_valid_bits();
    const std::uint64_t mask = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    const std::uint64_t elapsed = ((ticks[1] & mask) - (ticks[0] & mask)) & mask;
    last_kernel_seconds = double(elapsed) * context->properties().limits.timestampPeriod * 1e-9;
  }

  if (clusters) stats.rows_evaluated += clusters->rows_evaluated(ticket.slot, slot.batch);
  const std::uint32_t kc = k_class(slot.k);
  const auto* pairs = static_cast<const std::uint32_t*>(slot.results.mapped);
  for (std::uint32_t q = 0; q < slot.batch; ++q) {
    for (std::uint32_t j = 0; j < slot.k; ++j) {
      const std::size_t at = (std::size_t{q} * kc + j) * 2;
      const std::uint32_t frame = pairs[at + 1];
      out[std::size_t{q} * slot.k + j] = frame == kNoFrame ? Match{} : Match{frame, decode_cost(pairs[at])};
    }
  }
  return {};
}

Status VulkanSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  Result<Ticket> ticket = submit(batch, k);
  if (!ticket) return ticket.error();
  return wait(*ticket, out);
}

}  // namespace mmvk::vulkan
