// ThreadPool hand-over: the wall time of one parallel_for whose chunks do
// nothing (the Time column), called back to back, so the figure is the pool's own cost of
// waking its workers and waiting for them. Rows by total threads (the
// caller's included; above the core count the pool is oversubscribed) and
// spin_us (0: the workers sleep on the condition variable at once, as the
// pool did before it spun).
//
//   build/bench/mmvk_bench --benchmark_filter=BM_ThreadPoolHandOver
#include <benchmark/benchmark.h>

#include <atomic>

#include "mmvk/common/thread_pool.hpp"

namespace mmvk::bench {
namespace {

void BM_ThreadPoolHandOver(benchmark::State& state) {
  const unsigned threads = static_cast<unsigned>(state.range(0));
  const unsigned spin_us = static_cast<unsigned>(state.range(1));
  ThreadPool pool(threads, spin_us);
  std::atomic<std::size_t> chunks{0};
  for (auto _ : state) {
    pool.parallel_for(threads, [&](std::size_t, std::size_t, unsigned) { chunks.fetch_add(1); });
  }
  benchmark::DoNotOptimize(chunks.load());
}

BENCHMARK(BM_ThreadPoolHandOver)
    ->ArgNames({"threads", "spin_us"})
    ->ArgsProduct({{2, 3, 4}, {0, ThreadPool::kDefaultSpinMicroseconds}})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mmvk::bench
