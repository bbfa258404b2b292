// BatchPager: every Vulkan search entry point's paging.
#include "batch_pager.hpp"

#include <algorithm>
#include <string>

namespace mmvk::vulkan::detail {

BatchPager::BatchPager(std::size_t page, std::size_t slots) : page_(page), tickets_(std::max<std::size_t>(slots, 1)) {}

std::size_t BatchPager::page_count(std::size_t index) const {
  return std::min(page_, batch_.size - index * page_);
}

Status BatchPager::begin(PageRunner& runner, const Database& database, const QueryBatch& batch, std::uint32_t k) {
  MMVK_TRY(validate_queries(database, batch, k));
  batch_ = batch;
  dims_ = database.dims();
  k_ = k;
  pages_ = (batch.size + page_ - 1) / page_;
  submitted_ = done_ = 0;
  active_ = true;
  // With no free slot the first page's submit returns the error.
  const std::size_t free = std::max<std::size_t>(runner.free_slots(), 1);
  while (submitted_ < pages_ && submitted_ < free) {
    if (Status status = submit_next(runner); !status.ok()) {
      std::vector<Match> dropped(page_ * k);  // the error path only
      drain(runner, dropped);
      return status;
    }
  }
  return {};
}

Status BatchPager::finish(PageRunner& runner, std::span<Match> out) {
  if (out.size() != batch_.size * k_) {
    const std::string message = "VulkanSearch: got " + std::to_string(out.size()) + " result slots, expected " +
                                std::to_string(batch_.size) + " queries x k=" + std::to_string(k_);
    std::vector<Match> dropped(page_ * k_);
    drain(runner, dropped);
    return make_error(message);
  }
  while (done_ < submitted_) {
    const std::size_t first = done_ * page_;
    const std::size_t count = page_count(done_);
    const Ticket ticket = tickets_[done_ % tickets_.size()];
    ++done_;
    Status status = runner.wait_page(ticket, out.subspan(first * k_, count * k_));
    if (status.ok() && submitted_ < pages_) status = submit_next(runner);
    if (!status.ok()) {
      drain(runner, out);
      return status;
    }
  }
  active_ = false;
  return {};
}

Status BatchPager::submit_next(PageRunner& runner) {
  const std::size_t dims = dims_;
  const std::size_t first = submitted_ * page_;
  const std::size_t count = page_count(submitted_);
  QueryBatch part;
  part.features = batch_.features.subspan(first * dims, count * dims);
  part.params = batch_.params.empty() ? batch_.params : batch_.params.subspan(first, count);
  part.size = count;
  MMVK_ASSIGN_OR_RETURN(tickets_[submitted_ % tickets_.size()], runner.submit_page(part, k_));
  ++submitted_;
  return {};
}

void BatchPager::drain(PageRunner& runner, std::span<Match> out) {
  for (; done_ < submitted_; ++done_) {
    const std::size_t first = done_ * page_;
    const std::size_t count = page_count(done_);
    // A page's own error (a lost device) says nothing the caller is not told.
    const std::span<Match> into =
        out.size() >= batch_.size * k_ ? out.subspan(first * k_, count * k_) : out.first(count * k_);
    static_cast<void>(runner.wait_page(tickets_[done_ % tickets_.size()], into));
  }
  active_ = false;
}

}  // namespace mmvk::vulkan::detail
