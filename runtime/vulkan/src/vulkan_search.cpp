#include "mmvk/vulkan/vulkan_search.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <vector>

#include "brute_force_kernel.hpp"
#include "check.hpp"
#include "cluster_kernel.hpp"
#include "commands.hpp"
#include "descriptors.hpp"
#include "device_database.hpp"
#include "kernel_shape.hpp"
#include "memory.hpp"
#include "pipeline.hpp"
#include "scan_rows.hpp"
#include "search_fit.hpp"
#include "search_layout.hpp"

namespace mmvk::vulkan {

using namespace detail;

namespace {

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

// Everything create() can check before touching the device. The cluster
// table is validated here, once, whatever the mode: a table from another
// database is an error even where it would go unused.
Status validate_options(const Database& database, const VulkanSearchOptions& options, const ClusterTable* clusters) {
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
  if (clusters != nullptr) {
    const Status valid = validate_cluster_table(*clusters, database);
    if (!valid) {
      return make_error("VulkanSearch: the cluster table does not belong to this database or is malformed: " +
                        valid.message());
    }
  }
  if (options.mode != SearchMode::BruteForce) {
    if (clusters == nullptr) return make_error("VulkanSearch: cluster modes need a ClusterTable");
    if (options.mode == SearchMode::NProbe && options.nprobe == 0) {
      return make_error("VulkanSearch: nprobe must be >= 1 in NProbe mode");
    }
  }
  return {};
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
  // Exactly one of the two: a backend builds only the kernels it runs.
  std::optional<BruteForceKernel> brute;  // BruteForce mode
  std::vector<Slot> slots;
  std::optional<ClusterKernel> clusters;  // ClustersExact and NProbe modes
  // A paged batch: pages of max_batch queries, pages [done, submitted) in
  // flight, their tickets in a ring of one entry per slot (sized at create,
  // so paging allocates nothing). `async` is the one between submit_batch()
  // and wait_batch(); search() pages through `blocking`, so that it runs on
  // the slots an async batch leaves free.
  struct Paged {
    QueryBatch batch;
    std::uint32_t k = 1;
    std::size_t pages = 0, submitted = 0, done = 0;
    bool active = false;
    std::vector<Ticket> tickets;
  };
  Paged async, blocking;

  ~Impl() {
    // Nothing may be destroyed while the GPU still uses it.
    for (Slot& slot : slots) {
      if (slot.in_flight) {
        const VkFence fence = slot.fence.get();
        vkWaitForFences(context->device(), 1, &fence, VK_TRUE, UINT64_MAX);
      }
    }
  }

  // The steps of create(), in order.
  Status create_layouts();
  Status upload(bool force_staging);
  Status create_slots();
  Status create_cluster_kernel(const ClusterTable& table);
  Status warm_up();
  // Set 0's scratch pairs one query needs: the brute force's per-block best
  // pairs; the cluster kernels keep theirs in set 1 (one pair keeps the
  // binding valid).
  std::uint64_t scratch_pairs_per_query(std::uint32_t k) const {
    return brute ? brute->scratch_pairs_per_query(k) : 1;
  }
  std::uint32_t chunk_for(std::uint32_t k) const {
    const std::uint64_t per_query = scratch_pairs_per_query(k);
    std::uint64_t chunk = std::min<std::uint64_t>(options.max_batch, scratch_pairs / per_query);
    if (chunk >= 16) chunk -= chunk % 16;  // whole query tiles per chunk
    return static_cast<std::uint32_t>(chunk);
  }
  // submit() in steps: a free slot for a valid batch, the queries written
  // into its mapped buffers, its commands recorded.
  Result<Ticket> submit(const QueryBatch& batch, std::uint32_t k, std::uint32_t forced_tile);
  Result<Slot*> slot_for(const QueryBatch& batch, std::uint32_t k);
  void stage_queries(Slot& slot, const QueryBatch& batch);
  Status record_search(Slot& slot, std::uint32_t count, std::uint32_t k, std::uint32_t chunk,
                       std::uint32_t forced_tile);
  Result<Slot*> find_ticket(const Ticket& ticket, const char* caller);
  Status wait(const Ticket& ticket, std::span<Match> out);
  // Starts paging `batch` (its first pages, up to the free slots).
  Status begin_pages(Paged& paged, const QueryBatch& batch, std::uint32_t k);
  // Waits for every page, oldest first, submitting the rest as slots free up.
  Status finish_pages(Paged& paged, std::span<Match> out);
  // Submits the paged batch's next page.
  Status submit_page(Paged& paged);
  // Waits out the pages still in flight, dropping their results into `out`.
  void drain(Paged& paged, std::span<Match> out);
};

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

Status VulkanSearch::Impl::create_slots() {
  const std::uint64_t max_batch = options.max_batch;
  const std::uint64_t storage_range = context->properties().limits.maxStorageBufferRange;
  const std::uint64_t per_query_max = scratch_pairs_per_query(options.max_k) * sizeof(std::uint32_t) * 2;
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
    Buffer Slot::*member;
    std::uint64_t bytes;
    VkBufferUsageFlags usage;
    const char* what;
  } buffers[] = {
      {&Slot::queries, sizes.queries, query_usage, "the query buffer"},
      {&Slot::params, sizes.params, query_usage, "the query parameter buffer"},
      {&Slot::weights, sizes.weights, query_usage, "the weight buffer"},
      {&Slot::scratch, scratch_bytes, storage, "the scratch buffer"},
      {&Slot::results, sizes.results, storage, "the result buffer"},
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
  async.tickets.resize(options.slots);
  blocking.tickets.resize(options.slots);
  for (std::uint32_t s = 0; s < options.slots; ++s) {
    Slot& slot = slots[s];
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
    slot.validation_out.resize(max_batch * options.max_k);
  }
  return {};
}

Status VulkanSearch::Impl::upload(bool force_staging) {
  MMVK_ASSIGN_OR_RETURN(device_database, upload_database(*context, command_pool.get(), *database,
                                                         options.mode == SearchMode::BruteForce, force_staging));
  return {};
}

Status VulkanSearch::Impl::create_cluster_kernel(const ClusterTable& table) {
  ClusterKernelOptions cluster_options;
  cluster_options.max_batch = options.max_batch;
  cluster_options.max_k = options.max_k;
  cluster_options.slots = options.slots;
  cluster_options.nprobe = options.mode == SearchMode::NProbe ? options.nprobe : 0;
  cluster_options.scratch_bytes = options.cluster_scratch_bytes;
  cluster_options.force_staging = options.force_staging_upload;
  for (const Slot& slot : slots) cluster_options.slot_queries.push_back({&slot.queries, &slot.params, &slot.weights});
  MMVK_ASSIGN_OR_RETURN(ClusterKernel created, ClusterKernel::create(*context, command_pool.get(), set_layout.get(),
                                                                     shape, *database, table, cluster_options));
  clusters.emplace(std::move(created));
  return {};
}

// One dispatch of every variant: lavapipe compiles at the first one. The
// caller's statistics and kernel time are kept.
Status VulkanSearch::Impl::warm_up() {
  const SearchStats kept_stats = stats;
  const std::optional<double> kept_seconds = last_kernel_seconds;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> variants;
  if (brute) variants = brute->variant_keys();
  if (clusters) {
    for (const std::uint32_t kc : clusters->k_classes()) variants.emplace_back(kc, 1);
  }
  const std::span<const float> first_row = database->row(0);
  for (const auto& [kc, tile] : variants) {
    std::vector<float> batch_features;
    for (std::uint32_t t = 0; t < tile; ++t) batch_features.insert(batch_features.end(), first_row.begin(), first_row.end());
    const QueryBatch batch{batch_features, {}, tile};
    const std::uint32_t k = std::min(kc, options.max_k);
    MMVK_ASSIGN_OR_RETURN(const Ticket ticket, submit(batch, k, tile));
    std::vector<Match> out(std::size_t{tile} * k);
    MMVK_TRY(wait(ticket, out));
  }
  stats = kept_stats;
  last_kernel_seconds = kept_seconds;
  return {};
}

Result<std::unique_ptr<VulkanSearch>> VulkanSearch::create(Context& context, const Database& database,
                                                           const VulkanSearchOptions& options,
                                                           const ClusterTable* clusters) {
  if (context.device_lost()) return context.device_lost_error();
  MMVK_TRY(validate_options(database, options, clusters));
  auto impl = std::make_unique<Impl>();
  impl->context = &context;
  impl->database = &database;
  impl->options = options;
  impl->channel_of_weight = weighted_channels(database.schema());
  MMVK_ASSIGN_OR_RETURN(impl->shape, make_kernel_shape(context, database, options));
  MMVK_TRY(check_search_fits(context, impl->shape, options));
  MMVK_TRY(impl->create_layouts());
  MMVK_TRY(impl->upload(options.force_staging_upload));
  if (options.mode == SearchMode::BruteForce) {
    MMVK_ASSIGN_OR_RETURN(impl->brute, BruteForceKernel::create(context, impl->pipeline_layout.get(), impl->shape,
                                                                options.max_batch, options.max_k, options.max_tile));
  }
  MMVK_TRY(impl->create_slots());
  if (options.mode != SearchMode::BruteForce) MMVK_TRY(impl->create_cluster_kernel(*clusters));
  if (options.warm_up) MMVK_TRY(impl->warm_up());
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
  return "vulkan-brute";
}
const Database& VulkanSearch::database() const { return *impl_->database; }
SearchStats VulkanSearch::stats() const { return impl_->stats; }
void VulkanSearch::reset_stats() { impl_->stats = {}; }
std::optional<double> VulkanSearch::last_kernel_seconds() const { return impl_->last_kernel_seconds; }
const VulkanSearchOptions& VulkanSearch::options() const { return impl_->options; }
std::uint32_t VulkanSearch::rows_per_invocation() const { return impl_->shape.rows_per_invocation; }
std::uint32_t VulkanSearch::workgroup_size() const { return impl_->shape.workgroup_size; }

Status VulkanSearch::warm_up() { return impl_->warm_up(); }

std::uint64_t VulkanSearch::device_bytes() const {
  const DeviceDatabase& db = impl_->device_database;
  std::uint64_t bytes = db.features.buffer.size + db.frame_meta.buffer.size + db.frame_cost.buffer.size +
                        db.scan_frames.buffer.size + db.scan_terms.buffer.size;
  for (const Slot& slot : impl_->slots) {
    bytes += slot.queries.size + slot.params.size + slot.weights.size + slot.scratch.size + slot.results.size;
  }
  if (impl_->clusters) bytes += impl_->clusters->device_bytes();
  return bytes;
}

std::vector<std::string_view> VulkanSearch::kernels() const {
  std::vector<std::string_view> names;
  if (impl_->brute) names = impl_->brute->kernel_names();
  if (impl_->clusters) names = impl_->clusters->kernel_names();
  return names;
}

Result<Ticket> VulkanSearch::submit(const QueryBatch& batch, std::uint32_t k) { return impl_->submit(batch, k, 0); }

Result<Slot*> VulkanSearch::Impl::slot_for(const QueryBatch& batch, std::uint32_t k) {
  if (context->device_lost()) return context->device_lost_error();
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
  const std::span<const Match> validation_out(free_slot->validation_out.data(), batch.size * std::size_t{k});
  MMVK_TRY(validate_search(*database, batch, k, validation_out));
  return &*free_slot;
}

void VulkanSearch::Impl::stage_queries(Slot& slot, const QueryBatch& batch) {
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

Status VulkanSearch::Impl::record_search(Slot& slot, std::uint32_t count, std::uint32_t k, std::uint32_t chunk,
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
  const Status recorded =
      clusters ? clusters->record(*context, commands, slot_index, slot.descriptors, count, k)
               : brute->record(*context, commands, pipeline_layout.get(), count, k, chunk, forced_tile);
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

Result<Ticket> VulkanSearch::Impl::submit(const QueryBatch& batch, std::uint32_t k, std::uint32_t forced_tile) {
  MMVK_ASSIGN_OR_RETURN(Slot* const found, slot_for(batch, k));
  Slot& slot = *found;
  stage_queries(slot, batch);
  const std::uint32_t count = static_cast<std::uint32_t>(batch.size);
  const std::uint32_t slot_index = static_cast<std::uint32_t>(&slot - slots.data());
  slot.serial = next_serial++;
  slot.batch = count;
  slot.k = k;
  if (count == 0) {
    slot.in_flight = true;  // nothing to run; wait() returns at once
    return Ticket{slot_index, slot.serial};
  }

  const std::uint32_t chunk = chunk_for(k);
  if (chunk == 0) return make_error("VulkanSearch: the scratch buffer cannot hold one query for k = " + std::to_string(k));
  MMVK_TRY(record_search(slot, count, k, chunk, forced_tile));
  const VkFence fence = slot.fence.get();
  MMVK_VK_CHECK(vkResetFences(context->device(), 1, &fence));
  MMVK_TRY(detail::submit(*context, slot.commands, fence));
  slot.in_flight = true;
  stats.queries += count;
  // Cluster modes count their rows on the GPU (added in wait()).
  if (!clusters) stats.rows_evaluated += std::uint64_t{count} * shape.scan_rows;
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
  const Context& context = *impl_->context;
  if (context.device_lost()) return context.device_lost_error();  // wait() then frees the slot
  const VkResult status =
      injected_or(context, "vkGetFenceStatus", vkGetFenceStatus(context.device(), (*slot)->fence.get()));
  if (status == VK_NOT_READY) return false;
  MMVK_TRY(watched(context, status, "vkGetFenceStatus", "vkGetFenceStatus(device, slot.fence)", __FILE__, __LINE__));
  return true;
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
  const VkResult waited =
      injected_or(*context, "vkWaitForFences", vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
  slot.in_flight = false;  // a lost device will not finish it either
  MMVK_TRY(watched(*context, waited, "vkWaitForFences", "vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX)",
                   __FILE__, __LINE__));
  // Lost while this ticket ran (reported by another ticket): its results
  // cannot be trusted either.
  if (context->device_lost()) return context->device_lost_error();

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
  if (batch.size <= impl_->options.max_batch) {
    Result<Ticket> ticket = submit(batch, k);
    if (!ticket) return ticket.error();
    return wait(*ticket, out);
  }
  // The result span is checked before any page runs, with every other check.
  if (out.size() != batch.size * k) return validate_search(*impl_->database, batch, k, out);
  MMVK_TRY(impl_->begin_pages(impl_->blocking, batch, k));
  return impl_->finish_pages(impl_->blocking, out);
}

Status VulkanSearch::submit_batch(const QueryBatch& batch, std::uint32_t k) {
  if (impl_->async.active) {
    return make_error("VulkanSearch: submit_batch() while a batch is in flight (wait_batch() first)");
  }
  return impl_->begin_pages(impl_->async, batch, k);
}

Status VulkanSearch::wait_batch(std::span<Match> out) {
  if (!impl_->async.active) return make_error("VulkanSearch: wait_batch() without a submitted batch");
  return impl_->finish_pages(impl_->async, out);
}

// A batch larger than a slot is paged, as FAISS's GPU indexes page a large
// batch through their fixed buffers: as many pages in flight as there are
// free slots, the next page submitted as soon as the oldest one finishes.
Status VulkanSearch::Impl::begin_pages(Paged& paged, const QueryBatch& batch, std::uint32_t k) {
  // A paged batch is checked whole up front: an error names the query's
  // index in the batch and leaves nothing in flight. One page is checked by
  // its submit().
  const std::size_t page = options.max_batch;
  if (batch.size > page) MMVK_TRY(validate_queries(*database, batch, k));
  paged.batch = batch;
  paged.k = k;
  paged.pages = std::max<std::size_t>((batch.size + page - 1) / page, 1);
  paged.submitted = paged.done = 0;
  paged.active = true;
  const auto free_slots =
      std::size_t(std::count_if(slots.begin(), slots.end(), [](const Slot& s) { return !s.in_flight; }));
  // With no free slot the first page's submit() returns the error.
  while (paged.submitted < paged.pages && paged.submitted < std::max<std::size_t>(free_slots, 1)) {
    if (Status status = submit_page(paged); !status.ok()) {
      std::vector<Match> dropped(page * k);
      drain(paged, dropped);
      return status;
    }
  }
  return {};
}

Status VulkanSearch::Impl::finish_pages(Paged& paged, std::span<Match> out) {
  const std::size_t page = options.max_batch;
  if (out.size() != paged.batch.size * paged.k) {
    const std::string message = "VulkanSearch: wait_batch() got " + std::to_string(out.size()) +
                                " result slots, expected " + std::to_string(paged.batch.size) +
                                " queries x k=" + std::to_string(paged.k);
    std::vector<Match> dropped(page * paged.k);
    drain(paged, dropped);
    return make_error(message);
  }
  while (paged.done < paged.submitted) {
    const std::size_t first = paged.done * page;
    const std::size_t count = std::min(page, paged.batch.size - first);
    const Ticket ticket = paged.tickets[paged.done % paged.tickets.size()];
    ++paged.done;
    Status status = wait(ticket, out.subspan(first * paged.k, count * paged.k));
    if (status.ok() && paged.submitted < paged.pages) status = submit_page(paged);
    if (!status.ok()) {
      drain(paged, out);
      return status;
    }
  }
  paged.active = false;
  return {};
}

Status VulkanSearch::Impl::submit_page(Paged& paged) {
  const std::size_t page = options.max_batch;
  const std::size_t dims = database->dims();
  const std::size_t first = paged.submitted * page;
  const std::size_t count = std::min(page, paged.batch.size - first);
  QueryBatch part;
  part.features = paged.batch.features.subspan(first * dims, count * dims);
  part.params = paged.batch.params.empty() ? paged.batch.params : paged.batch.params.subspan(first, count);
  part.size = count;
  Result<Ticket> ticket = submit(part, paged.k, 0);
  if (!ticket) return ticket.error();
  paged.tickets[paged.submitted % paged.tickets.size()] = *ticket;
  ++paged.submitted;
  return {};
}

void VulkanSearch::Impl::drain(Paged& paged, std::span<Match> out) {
  const std::size_t page = options.max_batch;
  for (; paged.done < paged.submitted; ++paged.done) {
    const std::size_t first = paged.done * page;
    const std::size_t count = std::min(page, paged.batch.size - first);
    // A page's own error (a lost device) says nothing the caller is not told.
    const std::span<Match> into = out.size() >= paged.batch.size * paged.k
                                      ? out.subspan(first * paged.k, count * paged.k)
                                      : out.first(count * paged.k);
    static_cast<void>(wait(paged.tickets[paged.done % paged.tickets.size()], into));
  }
  paged.active = false;
}

}  // namespace mmvk::vulkan
