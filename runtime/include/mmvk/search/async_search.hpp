// AsyncSearch: a search started now and collected later, so that a caller
// (the crowd controller's deferred tick) can overlap it with its own work.
// DeferredSearch gives that interface to any SearchBackend by searching at
// submit(); a device backend (VulkanAsyncSearch) runs it in the background.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

class AsyncSearch {
 public:
  virtual ~AsyncSearch() = default;
  virtual const Database& database() const = 0;
  // Starts searching `batch` (k = 1), up to the implementation's capacity
  // (at most kMaxBatch queries). The spans stay valid until collect(). At
  // most one search in flight.
  virtual Status submit(const QueryBatch& batch) = 0;
  // Waits for the submitted search and writes its matches [batch.size].
  virtual Status collect(std::span<Match> out) = 0;
};

// The deferred path on any SearchBackend: searches the whole batch at
// submit, hands the matches out at collect. Gives the same chosen frames as
// an asynchronous GPU search of the same backend semantics.
class DeferredSearch final : public AsyncSearch {
 public:
  // `backend` must outlive this; `capacity` = the largest batch submitted,
  // at most kMaxBatch (the matches are held for it, allocated once here).
  DeferredSearch(SearchBackend& backend, std::uint32_t capacity);
  const Database& database() const override { return backend_.database(); }
  Status submit(const QueryBatch& batch) override;
  Status collect(std::span<Match> out) override;

 private:
  SearchBackend& backend_;
  std::vector<Match> matches_;
  std::size_t pending_ = 0;
  bool in_flight_ = false;
};

}  // namespace mmvk
