// An AsyncSearch that forwards to another and observes it: how long the
// host is blocked in submit() and collect() (the search time a tick pays),
// the matches of each collected batch, in order (the chosen frames the run
// hashes and the viewer's search events come from), and the batch each tick
// submitted (the queries the viewer's "why this frame" explains).
#pragma once

#include <chrono>
#include <span>
#include <vector>

#include "mmvk/async_search.hpp"

namespace mmvk::crowd {

class ObservedSearch final : public AsyncSearch {
 public:
  ObservedSearch(AsyncSearch& inner, std::size_t capacity) : inner_(inner) { matches_.reserve(capacity); }

  const Database& database() const override { return inner_.database(); }
  Status submit(const QueryBatch& batch) override {
    const auto start = Clock::now();
    Status status = inner_.submit(batch);
    blocked_s_ += std::chrono::duration<double>(Clock::now() - start).count();
    submitted_ = batch.size;
    batch_ = batch;
    return status;
  }
  Status collect(std::span<Match> out) override {
    const auto start = Clock::now();
    Status status = inner_.collect(out);
    blocked_s_ += std::chrono::duration<double>(Clock::now() - start).count();
    matches_.assign(out.begin(), out.begin() + std::ptrdiff_t(std::min(out.size(), submitted_)));
    collected_ = true;
    return status;
  }

  // Per tick: clear, tick the controller, then read.
  void begin_tick() {
    blocked_s_ = 0.0;
    collected_ = false;
    matches_.clear();
    batch_ = {};
  }
  double blocked_seconds() const { return blocked_s_; }
  bool collected() const { return collected_; }
  std::span<const Match> collected_matches() const { return matches_; }
  // The batch submitted this tick (empty: none), a view of the submitter's
  // buffers, valid until its next tick.
  const QueryBatch& submitted_batch() const { return batch_; }

 private:
  using Clock = std::chrono::steady_clock;
  AsyncSearch& inner_;
  double blocked_s_ = 0.0;
  std::size_t submitted_ = 0;
  bool collected_ = false;
  std::vector<Match> matches_;
  QueryBatch batch_;
};

}  // namespace mmvk::crowd
