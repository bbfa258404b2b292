// A fixed-size worker pool owned by the caller (no global pool, no threads
// created per call). parallel_for splits [0, count) into contiguous chunks,
// runs them on the workers and the calling thread, and returns when all are
// done.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "mmvk/status.hpp"

namespace mmvk {

class ThreadPool {
 public:
  // The most threads a pool runs: far above any core count this library is
  // meant for, low enough that a typo (--threads 100000) is an error rather
  // than an attempt to start a hundred thousand threads.
  static constexpr unsigned kMaxThreads = 1024;

  // `threads` = total threads working on a parallel_for, the caller's
  // included; 0 = std::thread::hardware_concurrency(). Errors: threads >
  // kMaxThreads, or the system refusing to start a thread (the message
  // names which one and why); no thread is left running.
  static Result<std::unique_ptr<ThreadPool>> create(unsigned threads = 0);

  // Best effort: clamps `threads` to kMaxThreads and, where the system
  // refuses a thread, works with the threads it did start (thread_count()
  // says how many). Use create() to have either case reported.
  explicit ThreadPool(unsigned threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned thread_count() const { return static_cast<unsigned>(workers_.size()) + 1; }

  // Calls body(begin, end, thread_index) over chunks of [0, count); at most
  // thread_count() chunks run at once, thread_index < thread_count().
  // Not reentrant: one parallel_for at a time per pool.
  void parallel_for(std::size_t count, const std::function<void(std::size_t, std::size_t, unsigned)>& body);

 private:
  void worker_loop(unsigned index);

  std::string start_error_;  // why a worker did not start, or empty

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t, std::size_t, unsigned)>* body_ = nullptr;
  std::size_t count_ = 0;
  std::size_t generation_ = 0;
  unsigned pending_ = 0;
  bool stopping_ = false;
};

}  // namespace mmvk
