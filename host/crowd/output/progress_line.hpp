// The live progress line of `mmvk crowd` on a terminal: simulated time,
// ticks per second, queries per tick and the search time p50/p99 over the
// last second of ticks, redrawn in place a few times a second.
#pragma once

#include <chrono>
#include <cstdio>
#include <vector>

namespace mmvk::crowd {

class ProgressLine {
 public:
  // `out` null: draws nothing.
  ProgressLine(std::FILE* out, double total_seconds, std::size_t window_ticks);

  void tick(double simulated_seconds, std::size_t queries, double search_ms);
  // Ends the line (a newline after the last draw), if anything was drawn.
  void finish();

 private:
  void draw(double simulated_seconds);

  using Clock = std::chrono::steady_clock;
  std::FILE* out_;
  double total_seconds_;
  std::size_t window_;
  std::vector<double> search_ms_;   // ring of the last `window_` ticks
  std::vector<double> queries_;
  std::vector<double> sorted_;
  std::size_t count_ = 0;
  std::size_t ticks_since_draw_ = 0;
  Clock::time_point last_draw_;
  bool drawn_ = false;
};

}  // namespace mmvk::crowd
