// VulkanAsyncSearch: the controller's deferred search overlapping the GPU
// with the caller's tick.
#include "mmvk/vulkan/vulkan_async_search.hpp"

#include <memory>
#include <string>

namespace mmvk::vulkan {

// Here rather than in vulkan_search.cpp: the search does not depend on its
// deferred wrapper's definition.
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
  // The pages beyond the free slots go out in collect() as slots free up.
  MMVK_TRY(search_.submit_batch(batch, 1));
  in_flight_ = true;
  return {};
}

Status VulkanAsyncSearch::collect(std::span<Match> out) {
  if (!in_flight_) return make_error("vulkan async search: collect without a submitted search");
  in_flight_ = false;
  return search_.wait_batch(out);
}

}  // namespace mmvk::vulkan
