// The one batch pager of VulkanSearch, as FAISS writes its paging once in
// the GpuIndex base: a batch of any size up to kMaxBatch is cut into pages
// of one slot's capacity; as many pages go out as there are free slots,
// and finish() waits for them oldest first, submitting the rest as slots
// free up. search() and VulkanAsyncSearch both page through it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::vulkan::detail {

// A page handed to a slot; valid until waited for.
struct Ticket {
  std::uint32_t slot = 0;
  std::uint64_t serial = 0;
};

// What the pager pages onto: slots that run one page each.
class PageRunner {
 public:
  virtual std::size_t free_slots() const = 0;
  // Starts one page (at most a slot's capacity, validated by the pager).
  // Error when every slot is in flight.
  virtual Result<Ticket> submit_page(const QueryBatch& page, std::uint32_t k) = 0;
  // Blocks until the page is done and writes its count*k matches.
  virtual Status wait_page(const Ticket& ticket, std::span<Match> out) = 0;

 protected:
  ~PageRunner() = default;
};

class BatchPager {
 public:
  // `page` queries per page; `slots` pages at most in flight (the ticket
  // ring is sized here, so paging allocates nothing).
  BatchPager(std::size_t page, std::size_t slots);

  bool active() const { return active_; }
  // Checks the batch whole (validate_queries: an error names the query's
  // index in the batch) and submits its first pages, up to the free slots.
  // The spans stay valid until finish(). Nothing is left in flight after
  // an error.
  Status begin(PageRunner& runner, const Database& database, const QueryBatch& batch, std::uint32_t k);
  // Writes the batch's size*k matches to `out`, waiting for every page.
  Status finish(PageRunner& runner, std::span<Match> out);

 private:
  Status submit_next(PageRunner& runner);
  // Waits out the pages still in flight, their results dropped into `out`
  // where it has room for them.
  void drain(PageRunner& runner, std::span<Match> out);
  std::size_t page_count(std::size_t index) const;

  std::size_t page_;
  std::vector<Ticket> tickets_;  // a ring of one per slot
  QueryBatch batch_;
  std::size_t dims_ = 0;
  std::uint32_t k_ = 1;
  std::size_t pages_ = 0, submitted_ = 0, done_ = 0;
  bool active_ = false;
};

}  // namespace mmvk::vulkan::detail
