// VulkanAsyncSearch: the controller's deferred search overlapping the GPU
// with the caller's tick.
#include "mmvk/vulkan/vulkan_async_search.hpp"

#include <memory>
#include <string>

#include "vulkan_search_impl.hpp"

namespace mmvk::vulkan {

// Here rather than in vulkan_search.cpp: the search does not depend on its
// asynchronous interface's definition.
std::unique_ptr<AsyncSearch> VulkanSearch::make_async(std::uint32_t capacity) {
  return std::make_unique<VulkanAsyncSearch>(*this, capacity);
}

VulkanAsyncSearch::VulkanAsyncSearch(VulkanSearch& search, std::uint32_t capacity)
    : search_(search), capacity_(capacity) {}

Status VulkanAsyncSearch::submit(const QueryBatch& batch) {
  if (in_flight_) return make_error("vulkan async search: submit while a search is in flight (collect it first)");
  if (batch.size > capacity_) {
    return make_error("vulkan async search: batch of " + std::to_string(batch.size) + " queries, capacity " +
                      std::to_string(capacity_));
  }
  VulkanSearch::Impl& impl = *search_.impl_;
  if (impl.async.active()) {
    return make_error("vulkan async search: another asynchronous search of this VulkanSearch is in flight");
  }
  MMVK_TRY(impl.begin_batch(impl.async, batch, 1));
  in_flight_ = true;
  return {};
}

Status VulkanAsyncSearch::collect(std::span<Match> out) {
  if (!in_flight_) return make_error("vulkan async search: collect without a submitted search");
  in_flight_ = false;
  VulkanSearch::Impl& impl = *search_.impl_;
  return impl.async.finish(impl, out);
}

}  // namespace mmvk::vulkan
