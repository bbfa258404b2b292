// The crowd controller's deferred search on a VulkanSearch: submit() records
// the tick's batch on the GPU and returns at once, collect() (next tick)
// waits and copies the matches out, so the search overlaps the caller's
// simulation step. Batches larger than the search's max_batch are split into
// chunks; chunks beyond the free slots are submitted as earlier ones finish.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/crowd_controller.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

class VulkanAsyncSearch final : public AsyncSearch {
 public:
  // `search` must outlive this; `capacity` = the largest batch submitted
  // (the controller's character count); scratch is sized once here.
  VulkanAsyncSearch(VulkanSearch& search, std::uint32_t capacity);

  const Database& database() const override { return search_.database(); }
  Status submit(const QueryBatch& batch) override;
  Status collect(std::span<Match> out) override;

 private:
  // Submits the next chunk of batch_ (at most max_batch queries).
  Status submit_next_chunk();
  // After an error: waits out the tickets from `first` on, dropping their
  // results, so that no slot stays taken by a batch nobody collects.
  void abandon(std::size_t first);

  VulkanSearch& search_;
  QueryBatch batch_;                      // the batch in flight
  std::size_t next_chunk_ = 0;            // first query not yet submitted
  std::vector<Ticket> tickets_;           // chunks in flight, oldest first
  std::vector<std::size_t> chunk_begin_;  // first query of each ticket's chunk
  bool in_flight_ = false;
};

}  // namespace mmvk::vulkan
