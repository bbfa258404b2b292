// ThreadPool::parallel_for: every index runs exactly once, on a valid
// thread index, whether the workers are spinning (calls back to back),
// asleep (calls further apart than the spin) or never spin (spin_us 0).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "mmvk/common/thread_pool.hpp"

namespace mmvk {
namespace {

// Runs parallel_for(count) and checks that each index ran once and that
// every chunk came with a thread index below thread_count().
void expect_each_index_once(ThreadPool& pool, std::size_t count) {
  std::vector<std::atomic<int>> runs(count);
  std::atomic<bool> bad_thread{false};
  pool.parallel_for(count, [&](std::size_t begin, std::size_t end, unsigned thread) {
    if (thread >= pool.thread_count()) bad_thread = true;
    for (std::size_t i = begin; i < end; ++i) runs[i].fetch_add(1);
  });
  EXPECT_FALSE(bad_thread);
  for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << "index " << i << " of " << count;
}

TEST(ThreadPool, EveryIndexRunsOnceForAnyCountThreadsAndSpin) {
  for (const unsigned threads : {1u, 2u, 3u, 5u}) {
    for (const unsigned spin_us : {0u, ThreadPool::kDefaultSpinMicroseconds, 1'000'000u}) {
      ThreadPool pool(threads, spin_us);
      ASSERT_EQ(pool.thread_count(), threads);
      for (const std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{7}, std::size_t{1000}}) {
        SCOPED_TRACE(testing::Message() << threads << " threads, spin " << spin_us << " us, count " << count);
        expect_each_index_once(pool, count);
      }
    }
  }
}

// Back to back: the workers pick each call up while still spinning.
TEST(ThreadPool, ManyCallsBackToBackAllComplete) {
  ThreadPool pool(3);
  std::atomic<std::uint64_t> sum{0};
  for (int call = 0; call < 20000; ++call) {
    pool.parallel_for(3, [&](std::size_t begin, std::size_t end, unsigned) {
      for (std::size_t i = begin; i < end; ++i) sum.fetch_add(i + 1);
    });
  }
  EXPECT_EQ(sum.load(), 20000u * 6u);
}

// Calls further apart than the spin: the workers have gone to sleep and are
// woken by the condition variable.
TEST(ThreadPool, CallsAfterTheWorkersSleptComplete) {
  ThreadPool pool(2, /*spin_us=*/20);
  for (int call = 0; call < 20; ++call) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    expect_each_index_once(pool, 64);
  }
}

// The caller's own chunk finishes first and the worker's takes long: the
// caller's spin runs out and it sleeps until the worker's notify.
TEST(ThreadPool, CallerWaitsForASlowWorkerPastItsSpin) {
  ThreadPool pool(2, /*spin_us=*/10);
  std::atomic<int> done{0};
  pool.parallel_for(2, [&](std::size_t begin, std::size_t, unsigned) {
    if (begin == 1) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    done.fetch_add(1);
  });
  EXPECT_EQ(done.load(), 2);
}

// Destroyed right after a call, while its workers still spin: joins, no hang.
TEST(ThreadPool, DestroyedWhileWorkersSpin) {
  for (int i = 0; i < 50; ++i) {
    ThreadPool pool(3, /*spin_us=*/1'000'000);
    expect_each_index_once(pool, 3);
  }
}

}  // namespace
}  // namespace mmvk
