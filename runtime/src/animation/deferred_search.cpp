// DeferredSearch (crowd_controller.hpp): the deferred tick on any backend.
#include <algorithm>

#include "mmvk/crowd_controller.hpp"

namespace mmvk {

DeferredSearch::DeferredSearch(SearchBackend& backend, std::uint32_t max_batch, std::uint32_t capacity)
    : backend_(backend), max_batch_(std::max<std::uint32_t>(max_batch, 1)), matches_(capacity) {}

Status DeferredSearch::submit(const QueryBatch& batch) {
  if (in_flight_) return make_error("deferred search: submit while a search is in flight (collect it first)");
  if (batch.size > matches_.size()) {
    return make_error("deferred search: batch of " + std::to_string(batch.size) + " queries, capacity " +
                      std::to_string(matches_.size()));
  }
  const std::size_t dims = backend_.database().dims();
  for (std::size_t first = 0; first < batch.size; first += max_batch_) {
    const std::size_t count = std::min<std::size_t>(max_batch_, batch.size - first);
    QueryBatch chunk;
    chunk.features = batch.features.subspan(first * dims, count * dims);
    chunk.params = batch.params.empty() ? batch.params : batch.params.subspan(first, count);
    chunk.size = count;
    MMVK_TRY(backend_.search(chunk, 1, std::span(matches_).subspan(first, count)));
  }
  pending_ = batch.size;
  in_flight_ = true;
  return {};
}

Status DeferredSearch::collect(std::span<Match> out) {
  if (!in_flight_) return make_error("deferred search: collect without a submitted search");
  if (out.size() != pending_) {
    return make_error("deferred search: collect into " + std::to_string(out.size()) + " matches, " +
                      std::to_string(pending_) + " were submitted");
  }
  std::copy_n(matches_.begin(), pending_, out.begin());
  in_flight_ = false;
  return {};
}

}  // namespace mmvk
