// VulkanAsyncSearch: the controller's deferred search overlapping the GPU
// with the caller's tick.
#include "mmvk/vulkan/vulkan_async_search.hpp"

#include <algorithm>

namespace mmvk::vulkan {

VulkanAsyncSearch::VulkanAsyncSearch(VulkanSearch& search, std::uint32_t capacity) : search_(search) {
  const std::uint32_t max_batch = std::max<std::uint32_t>(search.options().max_batch, 1);
  const std::size_t chunks = (std::size_t{capacity} + max_batch - 1) / max_batch;
  tickets_.reserve(chunks);
  chunk_begin_.reserve(chunks);
}

Status VulkanAsyncSearch::submit_next_chunk() {
  const std::size_t max_batch = search_.options().max_batch;
  const std::size_t dims = search_.database().dims();
  const std::size_t count = std::min(max_batch, batch_.size - next_chunk_);
  QueryBatch chunk;
  chunk.features = batch_.features.subspan(next_chunk_ * dims, count * dims);
  chunk.params = batch_.params.empty() ? batch_.params : batch_.params.subspan(next_chunk_, count);
  chunk.size = count;
  Result<Ticket> ticket = search_.submit(chunk, 1);
  if (!ticket.ok()) return ticket.status();
  tickets_.push_back(*ticket);
  chunk_begin_.push_back(next_chunk_);
  next_chunk_ += count;
  return {};
}

Status VulkanAsyncSearch::submit(const QueryBatch& batch) {
  if (in_flight_) return make_error("vulkan async search: submit while a search is in flight (collect it first)");
  batch_ = batch;
  next_chunk_ = 0;
  tickets_.clear();
  chunk_begin_.clear();
  // As many chunks as there are slots now; the rest go out in collect() as
  // slots free up.
  while (next_chunk_ < batch_.size && tickets_.size() < search_.options().slots) {
    if (Status status = submit_next_chunk(); !status.ok()) {
      abandon(0);
      return status;
    }
  }
  in_flight_ = true;
  return {};
}

Status VulkanAsyncSearch::collect(std::span<Match> out) {
  if (!in_flight_) return make_error("vulkan async search: collect without a submitted search");
  if (out.size() != batch_.size) {
    return make_error("vulkan async search: collect into " + std::to_string(out.size()) + " matches, " +
                      std::to_string(batch_.size) + " were submitted");
  }
  in_flight_ = false;
  const std::size_t max_batch = search_.options().max_batch;
  // Oldest chunk first; each finished one frees a slot for the next chunk.
  for (std::size_t i = 0; i < tickets_.size(); ++i) {
    const std::size_t first = chunk_begin_[i];
    Status status = search_.wait(tickets_[i], out.subspan(first, std::min(max_batch, batch_.size - first)));
    if (status.ok() && next_chunk_ < batch_.size) status = submit_next_chunk();
    if (!status.ok()) {
      abandon(i + 1);
      return status;
    }
  }
  return {};
}

void VulkanAsyncSearch::abandon(std::size_t first) {
  const std::size_t max_batch = search_.options().max_batch;
  std::vector<Match> dropped;
  for (std::size_t i = first; i < tickets_.size(); ++i) {
    dropped.resize(std::min(max_batch, batch_.size - chunk_begin_[i]));
    // Its own error (a lost device) says nothing the caller is not told.
    static_cast<void>(search_.wait(tickets_[i], dropped));
  }
  tickets_.clear();
  chunk_begin_.clear();
}

}  // namespace mmvk::vulkan
