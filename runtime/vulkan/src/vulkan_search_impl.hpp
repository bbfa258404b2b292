// VulkanSearch's state: what the base owns (slots, staging, timestamps, the
// pagers) and the kernel a subclass hands it. Shared by the base
// (vulkan_search.cpp), its two searches' create() and VulkanAsyncSearch.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "batch_pager.hpp"
#include "device_database.hpp"
#include "handles.hpp"
#include "kernel_shape.hpp"
#include "memory.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "search_kernel.hpp"

namespace mmvk::vulkan {

// Per-page resources: a submit fills a free slot, its wait frees it.
struct SearchSlot {
  detail::Buffer queries;  // [max_batch x dim_vec4s] vec4
  detail::Buffer params;   // [max_batch] QueryGpu
  detail::Buffer weights;  // [max_batch x channels] float
  detail::Buffer scratch;  // [chunk x blocks x K] uvec2
  detail::Buffer results;  // [max_batch x K] uvec2
  detail::UniqueFence fence;
  VkDescriptorSet descriptors = VK_NULL_HANDLE;  // freed with the pool
  VkCommandBuffer commands = VK_NULL_HANDLE;     // freed with the pool
  bool in_flight = false;
  std::uint64_t serial = 0;
  std::uint32_t batch = 0;
  std::uint32_t k = 0;
};

struct VulkanSearch::Impl final : detail::PageRunner {
  Context* context = nullptr;
  const Database* database = nullptr;
  VulkanSearchOptions options;
  detail::KernelShape shape;
  std::vector<std::uint32_t> channel_of_weight;  // schema channel of each kernel weight (non-empty channels)
  std::uint64_t scratch_pairs = 0;               // per slot
  SearchStats stats;
  std::optional<double> last_kernel_seconds;
  std::uint64_t next_serial = 1;

  // Declaration order = dependency order (destroyed in reverse).
  detail::UniqueDescriptorSetLayout set_layout;
  detail::UniquePipelineLayout pipeline_layout;
  detail::UniqueDescriptorPool descriptor_pool;
  detail::UniqueCommandPool command_pool;
  detail::UniqueQueryPool timestamps;  // 2 per slot; empty without timestamp support
  detail::DeviceDatabase device_database;
  std::vector<SearchSlot> slots;
  // After the slots: the cluster kernel holds views of their buffers.
  std::unique_ptr<detail::SearchKernel> kernel;
  // `async` pages VulkanAsyncSearch's batch between its submit() and
  // collect(); search() pages through `blocking`, so that it runs on the
  // slots an asynchronous batch leaves free.
  detail::BatchPager async{1, 1}, blocking{1, 1};

  ~Impl();

  // create() in steps, in order: begin() (options checked, layouts, the
  // database uploaded), the subclass's kernel (the brute force's before
  // the slots, whose scratch it sizes; the cluster kernel after, as it
  // reads their buffers), create_slots(), finish() (warm-up).
  static Result<std::unique_ptr<Impl>> begin(Context& context, const Database& database,
                                             const VulkanSearchOptions& options, bool brute_force);
  Status create_slots(std::uint64_t scratch_pairs_per_query_max_k);
  Status finish();
  Status warm_up();

  // detail::PageRunner: one page on one slot.
  std::size_t free_slots() const override;
  Result<detail::Ticket> submit_page(const QueryBatch& page, std::uint32_t k) override;
  Status wait_page(const detail::Ticket& ticket, std::span<Match> out) override;

  // Checks what only a Vulkan search limits (max_k), then pages.
  Status begin_batch(detail::BatchPager& pager, const QueryBatch& batch, std::uint32_t k);

 private:
  Status create_layouts();
  Status submit(const QueryBatch& page, std::uint32_t k, std::uint32_t forced_tile, detail::Ticket& ticket);
  std::uint32_t chunk_for(std::uint32_t k) const;
  void stage_queries(SearchSlot& slot, const QueryBatch& batch);
  Status record_search(SearchSlot& slot, std::uint32_t count, std::uint32_t k, std::uint32_t chunk,
                       std::uint32_t forced_tile);
  Status read_timestamps(std::uint32_t slot);
};

}  // namespace mmvk::vulkan
