// VulkanSearch: what both Vulkan searches run on (slots, staging,
// timestamps, paging); VulkanBruteForce and VulkanClusterSearch add their
// kernels (vulkan_brute_force.cpp, vulkan_cluster_search.cpp).
#include "mmvk/vulkan/vulkan_search.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "check.hpp"
#include "commands.hpp"
#include "descriptors.hpp"
#include "pipeline.hpp"
#include "scan_rows.hpp"
#include "search_fit.hpp"
#include "search_layout.hpp"
#include "vulkan_search_impl.hpp"

namespace mmvk::vulkan {

using namespace detail;

namespace {

float decode_cost(std::uint32_t key) {
  const std::uint32_t bits = (key & 0x80000000u) != 0 ? key & 0x7FFFFFFFu : ~key;
  return std::bit_cast<float>(bits);
}

// Everything create() can check before touching the device.
Status validate_options(const Database& database, const VulkanSearchOptions& options) {
  if (options.max_batch == 0 || options.max_batch > kMaxBatch) {
    return make_error("VulkanSearch: max_batch = " + std::to_string(options.max_batch) + " is out of range [1, " +
                      std::to_string(kMaxBatch) + "] (kMaxBatch)");
  }
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
  return {};
}

}  // namespace

VulkanSearch::Impl::~Impl() {
  // Nothing may be destroyed while the GPU still uses it.
  for (SearchSlot& slot : slots) {
    if (slot.in_flight) {
      const VkFence fence = slot.fence.get();
      vkWaitForFences(context->device(), 1, &fence, VK_TRUE, UINT64_MAX);
    }
  }
}

Result<std::unique_ptr<VulkanSearch::Impl>> VulkanSearch::Impl::begin(Context& context, const Database& database,
                                                                      const VulkanSearchOptions& options,
                                                                      bool brute_force) {
  if (context.device_lost()) return context.device_lost_error();
  MMVK_TRY(validate_options(database, options));
  auto impl = std::make_unique<Impl>();
  impl->context = &context;
  impl->database = &database;
  impl->options = options;
  impl->channel_of_weight = weighted_channels(database.schema());
  MMVK_ASSIGN_OR_RETURN(impl->shape, make_kernel_shape(context, database, options, brute_force));
  MMVK_TRY(check_search_fits(context, impl->shape, options));
  MMVK_TRY(impl->create_layouts());
  MMVK_ASSIGN_OR_RETURN(impl->device_database, upload_database(context, impl->command_pool.get(), database,
                                                               brute_force, options.force_staging_upload));
  return impl;
}

Status VulkanSearch::Impl::finish() {
  if (options.warm_up) MMVK_TRY(warm_up());
  return {};
}

Status VulkanSearch::Impl::create_layouts() {
  const std::array<SetShape, 1> sets = {kSearchSet};
  MMVK_TRY(check_binding_limits(*context, sets, "search kernels"));
  const VkDevice device = context->device();
  MMVK_ASSIGN_OR_RETURN(set_layout, create_set_layout(*context, kSearchSet));
  const VkDescriptorSetLayout set_layout_handle = set_layout.get();
  MMVK_ASSIGN_OR_RETURN(pipeline_layout, create_pipeline_layout(*context, std::span(&set_layout_handle, 1),
                                                                sizeof(SearchPush), "search kernels"));
  const std::uint32_t slot_count = options.slots;
  MMVK_ASSIGN_OR_RETURN(descriptor_pool, create_descriptor_pool(*context, kSearchSet, slot_count));

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

Status VulkanSearch::Impl::create_slots(std::uint64_t scratch_pairs_per_query_max_k) {
  const std::uint64_t max_batch = options.max_batch;
  const std::uint64_t storage_range = context->properties().limits.maxStorageBufferRange;
  const std::uint64_t per_query_max = scratch_pairs_per_query_max_k * sizeof(std::uint32_t) * 2;
  // Larger batches run in chunks, so the scratch never needs more than the
  // storage range; only one query's scratch beyond it is an error.
  std::uint64_t scratch_bytes = std::min({options.scratch_bytes, max_batch * per_query_max, storage_range});
  scratch_bytes = std::max(scratch_bytes, per_query_max);  // at least one query per chunk
  if (scratch_bytes > storage_range) {
    return make_error("Vulkan: one query's scratch (" + std::to_string(per_query_max) +
                      " bytes) exceeds maxStorageBufferRange (" + std::to_string(storage_range) +
                      "); lower max_k or raise rows_per_invocation");
  }
  scratch_pairs = scratch_bytes / 8;

  const SlotBufferBytes sizes = slot_buffer_bytes(shape, options);
  // The cluster kernels read the query buffers through texel views too.
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const VkBufferUsageFlags query_usage = storage | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  const struct {
    Buffer SearchSlot::*member;
    std::uint64_t bytes;
    VkBufferUsageFlags usage;
    const char* what;
  } buffers[] = {
      {&SearchSlot::queries, sizes.queries, query_usage, "the query buffer"},
      {&SearchSlot::params, sizes.params, query_usage, "the query parameter buffer"},
      {&SearchSlot::weights, sizes.weights, query_usage, "the weight buffer"},
      {&SearchSlot::scratch, scratch_bytes, storage, "the scratch buffer"},
      {&SearchSlot::results, sizes.results, storage, "the result buffer"},
  };
  static_assert(std::size(buffers) == kSearchSet.storage);
  const std::array<VkBufferView, kSearchSet.texel> views = {
      device_database.features.view.get(), device_database.frame_meta.view.get(), device_database.frame_cost.view.get(),
      device_database.scan_frames.view.get(), device_database.scan_terms.view.get()};
  std::vector<VkCommandBuffer> commands(options.slots);
  VkCommandBufferAllocateInfo command_info{};
  command_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  command_info.commandPool = command_pool.get();
  command_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  command_info.commandBufferCount = options.slots;
  MMVK_VK_CHECK(vkAllocateCommandBuffers(context->device(), &command_info, commands.data()));

  slots.resize(options.slots);
  async = BatchPager(options.max_batch, options.slots);
  blocking = BatchPager(options.max_batch, options.slots);
  for (std::uint32_t s = 0; s < options.slots; ++s) {
    SearchSlot& slot = slots[s];
    std::array<VkBuffer, kSearchSet.storage> handles{};
    for (std::size_t b = 0; b < std::size(buffers); ++b) {
      MMVK_ASSIGN_OR_RETURN(slot.*(buffers[b].member),
                            create_buffer(*context, buffers[b].bytes, buffers[b].usage, MemoryUse::HostMapped,
                                          buffers[b].what));
      handles[b] = (slot.*(buffers[b].member)).buffer.get();
    }
    // Padding lanes of the query vectors stay zero from here on.
    std::memset(slot.queries.mapped, 0, slot.queries.size);
    MMVK_ASSIGN_OR_RETURN(slot.fence, create_fence(*context));
    MMVK_ASSIGN_OR_RETURN(slot.descriptors,
                          allocate_set(*context, descriptor_pool.get(), set_layout.get(), views, handles));
    slot.commands = commands[s];
  }
  return {};
}

// One dispatch of every variant: lavapipe compiles at the first one. The
// caller's statistics and kernel time are kept.
Status VulkanSearch::Impl::warm_up() {
  const SearchStats kept_stats = stats;
  const std::optional<double> kept_seconds = last_kernel_seconds;
  const std::span<const float> first_row = database->row(0);
  for (const auto& [kc, tile] : kernel->warm_up_variants()) {
    std::vector<float> batch_features;
    for (std::uint32_t t = 0; t < tile; ++t) batch_features.insert(batch_features.end(), first_row.begin(), first_row.end());
    const QueryBatch batch{batch_features, {}, tile};
    const std::uint32_t k = std::min(kc, options.max_k);
    Ticket ticket;
    MMVK_TRY(submit(batch, k, tile, ticket));
    std::vector<Match> out(std::size_t{tile} * k);
    MMVK_TRY(wait_page(ticket, out));
  }
  stats = kept_stats;
  last_kernel_seconds = kept_seconds;
  return {};
}

std::uint32_t VulkanSearch::Impl::chunk_for(std::uint32_t k) const {
  const std::uint64_t per_query = kernel->scratch_pairs_per_query(k);
  std::uint64_t chunk = std::min<std::uint64_t>(options.max_batch, scratch_pairs / per_query);
  if (chunk >= 16) chunk -= chunk % 16;  // whole query tiles per chunk
  return static_cast<std::uint32_t>(chunk);
}

void VulkanSearch::Impl::stage_queries(SearchSlot& slot, const QueryBatch& batch) {
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
    gpu.continuing_multiplier = p.continuing_multiplier;
    const std::span<const std::uint32_t> scan = device_database.scan_rows_before;
    gpu.continuing_row = p.continuing_frame == kNoFrame ? kNoFrame : feature_row(scan, p.continuing_frame);
    const std::array<std::uint32_t, 4> skipped = skipped_scan_rows(scan, gpu);
    gpu.skip_first_a = skipped[0];
    gpu.skip_span_a = skipped[1];
    gpu.skip_first_b = skipped[2];
    gpu.skip_span_b = skipped[3];
    params[q] = gpu;
    for (std::uint32_t c = 0; c < shape.channels; ++c) {
      weights[std::size_t{q} * shape.channels + c] = p.channel_weights[channel_of_weight[c]];
    }
  }
}

Status VulkanSearch::Impl::record_search(SearchSlot& slot, std::uint32_t count, std::uint32_t k, std::uint32_t chunk,
                                         std::uint32_t forced_tile) {
  const VkCommandBuffer commands = slot.commands;
  const std::uint32_t slot_index = static_cast<std::uint32_t>(&slot - slots.data());
  MMVK_VK_CHECK(vkResetCommandBuffer(commands, 0));
  MMVK_TRY(begin_one_time(commands));
  if (timestamps) {
    vkCmdResetQueryPool(commands, timestamps.get(), 2 * slot_index, 2);
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps.get(), 2 * slot_index);
  }
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.get(), 0, 1, &slot.descriptors, 0,
                          nullptr);
  const PageCommands page{commands, pipeline_layout.get(), slot.descriptors, slot_index, count, k, chunk, forced_tile};
  const Status recorded = kernel->record(*context, page);
  if (!recorded) {
    vkEndCommandBuffer(commands);
    return recorded.error();
  }
  // Results become visible to the host once the fence signals.
  memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                 VK_ACCESS_HOST_READ_BIT);
  if (timestamps) {
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps.get(), 2 * slot_index + 1);
  }
  MMVK_VK_CHECK(vkEndCommandBuffer(commands));
  return {};
}

std::size_t VulkanSearch::Impl::free_slots() const {
  return std::size_t(std::count_if(slots.begin(), slots.end(), [](const SearchSlot& s) { return !s.in_flight; }));
}

Result<Ticket> VulkanSearch::Impl::submit_page(const QueryBatch& page, std::uint32_t k) {
  Ticket ticket;
  MMVK_TRY(submit(page, k, 0, ticket));
  return ticket;
}

// The page was validated whole by the pager (or is warm_up()'s row 0).
Status VulkanSearch::Impl::submit(const QueryBatch& page, std::uint32_t k, std::uint32_t forced_tile,
                                  Ticket& ticket) {
  if (context->device_lost()) return context->device_lost_error();
  auto free_slot = std::find_if(slots.begin(), slots.end(), [](const SearchSlot& s) { return !s.in_flight; });
  if (free_slot == slots.end()) {
    return make_error("VulkanSearch: all " + std::to_string(slots.size()) +
                      " submission slots are in flight (an asynchronous search holds them; collect it first)");
  }
  SearchSlot& slot = *free_slot;
  stage_queries(slot, page);
  const std::uint32_t count = static_cast<std::uint32_t>(page.size);
  const std::uint32_t slot_index = static_cast<std::uint32_t>(&slot - slots.data());
  slot.serial = next_serial++;
  slot.batch = count;
  slot.k = k;
  ticket = Ticket{slot_index, slot.serial};
  if (count == 0) {
    slot.in_flight = true;  // nothing to run; its wait returns at once
    return {};
  }
  const std::uint32_t chunk = chunk_for(k);
  if (chunk == 0) return make_error("VulkanSearch: the scratch buffer cannot hold one query for k = " + std::to_string(k));
  MMVK_TRY(record_search(slot, count, k, chunk, forced_tile));
  const VkFence fence = slot.fence.get();
  MMVK_VK_CHECK(vkResetFences(context->device(), 1, &fence));
  MMVK_TRY(detail::submit(*context, slot.commands, fence));
  slot.in_flight = true;
  stats.queries += count;
  return {};
}

Status VulkanSearch::Impl::read_timestamps(std::uint32_t slot) {
  if (!timestamps) return {};
  const VkDevice device = context->device();
  std::array<std::uint64_t, 2> ticks{};
  MMVK_VK_CHECK(vkGetQueryPoolResults(device, timestamps.get(), 2 * slot, 2, sizeof(ticks), ticks.data(),
                                      sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const std::uint32_t bits = context->timestamp_valid_bits();
  const std::uint64_t mask = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  const std::uint64_t elapsed = ((ticks[1] & mask) - (ticks[0] & mask)) & mask;
  last_kernel_seconds = double(elapsed) * context->properties().limits.timestampPeriod * 1e-9;
  return {};
}

Status VulkanSearch::Impl::wait_page(const Ticket& ticket, std::span<Match> out) {
  if (ticket.slot >= slots.size() || !slots[ticket.slot].in_flight || slots[ticket.slot].serial != ticket.serial) {
    return make_error("VulkanSearch: wait of an unknown or already waited-for page");
  }
  SearchSlot& slot = slots[ticket.slot];
  const std::size_t expected = std::size_t{slot.batch} * slot.k;
  if (out.size() != expected) {
    return make_error("VulkanSearch: a page got " + std::to_string(out.size()) + " result slots, expected " +
                      std::to_string(slot.batch) + " queries x k=" + std::to_string(slot.k));
  }
  if (slot.batch == 0) {
    slot.in_flight = false;
    return {};
  }
  const VkDevice device = context->device();
  const VkFence fence = slot.fence.get();
  const VkResult waited =
      injected_or(*context, "vkWaitForFences", vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
  slot.in_flight = false;  // a lost device will not finish it either
  MMVK_TRY(watched(*context, waited, "vkWaitForFences", "vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX)",
                   __FILE__, __LINE__));
  // Lost while this ticket ran (reported by another ticket): its results
  // cannot be trusted either.
  if (context->device_lost()) return context->device_lost_error();

  MMVK_TRY(read_timestamps(ticket.slot));
  stats.rows_evaluated += kernel->rows_evaluated(ticket.slot, slot.batch);
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

Status VulkanSearch::Impl::begin_batch(BatchPager& pager, const QueryBatch& batch, std::uint32_t k) {
  if (context->device_lost()) return context->device_lost_error();
  if (k > options.max_k && k <= kMaxK) {
    return make_error("VulkanSearch: k = " + std::to_string(k) + " is over max_k = " + std::to_string(options.max_k));
  }
  return pager.begin(*this, *database, batch, k);
}

VulkanSearch::VulkanSearch(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanSearch::~VulkanSearch() = default;

const Database& VulkanSearch::database() const { return *impl_->database; }

std::string VulkanSearch::device() const { return impl_->context->description(); }
SearchStats VulkanSearch::stats() const { return impl_->stats; }
void VulkanSearch::reset_stats() { impl_->stats = {}; }
std::optional<double> VulkanSearch::last_kernel_seconds() const { return impl_->last_kernel_seconds; }
const VulkanSearchOptions& VulkanSearch::options() const { return impl_->options; }
std::uint32_t VulkanSearch::rows_per_invocation() const { return impl_->shape.rows_per_invocation; }
std::uint32_t VulkanSearch::workgroup_size() const { return impl_->shape.workgroup_size; }
Status VulkanSearch::warm_up() { return impl_->warm_up(); }
std::vector<std::string_view> VulkanSearch::kernels() const { return impl_->kernel->kernel_names(); }

std::uint64_t VulkanSearch::device_bytes() const {
  const DeviceDatabase& db = impl_->device_database;
  std::uint64_t bytes = db.features.buffer.size + db.frame_meta.buffer.size + db.frame_cost.buffer.size +
                        db.scan_frames.buffer.size + db.scan_terms.buffer.size;
  for (const SearchSlot& slot : impl_->slots) {
    bytes += slot.queries.size + slot.params.size + slot.weights.size + slot.scratch.size + slot.results.size;
  }
  return bytes + impl_->kernel->device_bytes();
}

Status VulkanSearch::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  // The result span is checked before any page runs, with every other check.
  if (out.size() != batch.size * k) return validate_search(*impl_->database, batch, k, out);
  MMVK_TRY(impl_->begin_batch(impl_->blocking, batch, k));
  return impl_->blocking.finish(*impl_, out);
}

}  // namespace mmvk::vulkan
