// The crowd controller's deferred search on a VulkanSearch: submit() records
// the tick's batch on the GPU and returns at once, collect() (next tick)
// waits and copies the matches out, so the search overlaps the caller's
// simulation step. A batch larger than the search's max_batch is paged by
// the search itself (VulkanSearch::submit_batch).
#pragma once

#include <cstdint>
#include <span>

#include "mmvk/async_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

class VulkanAsyncSearch final : public AsyncSearch {
 public:
  // `search` must outlive this; `capacity` = the largest batch submitted
  // (the controller's character count), at most kMaxBatch.
  VulkanAsyncSearch(VulkanSearch& search, std::uint32_t capacity);

  const Database& database() const override { return search_.database(); }
  Status submit(const QueryBatch& batch) override;
  Status collect(std::span<Match> out) override;

 private:
  VulkanSearch& search_;
  std::uint32_t capacity_;
  bool in_flight_ = false;
};

}  // namespace mmvk::vulkan
