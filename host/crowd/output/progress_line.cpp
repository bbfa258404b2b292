#include "output/progress_line.hpp"

#include <algorithm>
#include <numeric>

namespace mmvk::crowd {

namespace {
constexpr auto kRedraw = std::chrono::milliseconds(250);
}

ProgressLine::ProgressLine(std::FILE* out, double total_seconds, std::size_t window_ticks)
    : out_(out),
      total_seconds_(total_seconds),
      window_(std::max<std::size_t>(1, window_ticks)),
      search_ms_(window_, 0.0),
      queries_(window_, 0.0),
      last_draw_(Clock::now()) {
  sorted_.reserve(window_);
}

void ProgressLine::tick(double simulated_seconds, std::size_t queries, double search_ms) {
  if (!out_) return;
  search_ms_[count_ % window_] = search_ms;
  queries_[count_ % window_] = double(queries);
  ++count_;
  ++ticks_since_draw_;
  if (Clock::now() - last_draw_ >= kRedraw) draw(simulated_seconds);
}

void ProgressLine::draw(double simulated_seconds) {
  const auto now = Clock::now();
  const double wall = std::chrono::duration<double>(now - last_draw_).count();
  const double ticks_per_s = wall > 0.0 ? double(ticks_since_draw_) / wall : 0.0;
  const std::size_t n = std::min(count_, window_);
  sorted_.assign(search_ms_.begin(), search_ms_.begin() + std::ptrdiff_t(n));
  std::sort(sorted_.begin(), sorted_.end());
  const double p50 = n ? sorted_[(n - 1) / 2] : 0.0;
  const double p99 = n ? sorted_[std::min(n - 1, std::size_t(0.99 * double(n)))] : 0.0;
  const double queries = n ? std::accumulate(queries_.begin(), queries_.begin() + std::ptrdiff_t(n), 0.0) / double(n) : 0.0;
  std::fprintf(out_, "\r  t %6.1f / %.1f s | %6.1f ticks/s | %6.1f queries/tick | search %.2f / %.2f ms (p50/p99) ",
               simulated_seconds, total_seconds_, ticks_per_s, queries, p50, p99);
  std::fflush(out_);
  drawn_ = true;
  ticks_since_draw_ = 0;
  last_draw_ = now;
}

void ProgressLine::finish() {
  if (!out_ || !drawn_) return;
  std::fputc('\n', out_);
  std::fflush(out_);
}

}  // namespace mmvk::crowd
