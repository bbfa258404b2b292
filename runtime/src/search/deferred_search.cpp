// DeferredSearch (async_search.hpp): a deferred search on any backend.
#include <algorithm>
#include <memory>
#include <string>

#include "mmvk/search/async_search.hpp"

namespace mmvk {

std::unique_ptr<AsyncSearch> SearchBackend::make_async(std::uint32_t capacity) {
  return std::make_unique<DeferredSearch>(*this, capacity);
}

DeferredSearch::DeferredSearch(SearchBackend& backend, std::uint32_t capacity)
    : backend_(backend), matches_(capacity) {}

Status DeferredSearch::submit(const QueryBatch& batch) {
  if (in_flight_) return make_error("deferred search: submit while a search is in flight (collect it first)");
  if (batch.size > matches_.size()) {
    return make_error("deferred search: batch of " + std::to_string(batch.size) + " queries, capacity " +
                      std::to_string(matches_.size()));
  }
  // Every backend takes any batch up to kMaxBatch (a device backend pages it).
  MMVK_TRY(backend_.search(batch, 1, std::span(matches_).first(batch.size)));
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
