// VulkanAsyncSearch: the AsyncSearch (mmvk/search/async_search.hpp) of a
// VulkanSearch, its one asynchronous interface. submit() checks the
// batch, stages its first pages and starts them on the GPU, returning at
// once; collect() (the crowd's next tick) waits for them oldest first,
// submitting the rest as slots free up, and copies the matches out, so the
// search overlaps the caller's simulation step. Paged by the search's own
// pager (as search() is), so a batch may be larger than max_batch.
#pragma once

#include <cstdint>
#include <span>

#include "mmvk/search/async_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

class VulkanAsyncSearch final : public AsyncSearch {
 public:
  // `search` must outlive this; `capacity` = the largest batch submitted
  // (the controller's character count), at most kMaxBatch. One
  // asynchronous batch per search at a time; a blocking search() meanwhile
  // runs on the slots it leaves free.
  VulkanAsyncSearch(VulkanSearch& search, std::uint32_t capacity);

  const Database& database() const override { return search_.database(); }
  // Errors: a batch in flight (collect it first), over capacity,
  // validate_queries, a failed submit (nothing is left in flight).
  Status submit(const QueryBatch& batch) override;
  // Errors: nothing submitted, `out` not batch.size matches, a failed wait
  // or submit of a later page (every page is waited out first).
  Status collect(std::span<Match> out) override;

 private:
  VulkanSearch& search_;
  std::uint32_t capacity_;
  bool in_flight_ = false;
};

}  // namespace mmvk::vulkan
