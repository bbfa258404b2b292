// A fixed-size worker pool owned by the caller (no global pool, no threads
// created per call). parallel_for splits [0, count) into contiguous chunks,
// runs them on the workers and the calling thread, and returns when all are
// done.
//
// Hand-over: a worker that finished a chunk, and a caller waiting for the
// workers, spin for a short while (spin_us) before they sleep on a condition
// variable. Waking a sleeping thread took 46-52 µs per parallel_for on the
// 2-vCPU test machine, longer than a whole query of the cluster search; a
// spinning one picks the next call up in 0.4 µs, 3-4 µs with more threads
// than cores (bench BM_ThreadPoolHandOver, bench/HISTORY.md, 2026-11-23 19:16). The cost is
// at most spin_us of each thread's core per call when no call follows.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "mmvk/common/status.hpp"

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
  // `spin_us`: how long an idle worker or a waiting caller polls before it
  // sleeps (0: sleep at once, for applications whose cores are all busy).
  static Result<std::unique_ptr<ThreadPool>> create(unsigned threads = 0, unsigned spin_us = kDefaultSpinMicroseconds);

  static constexpr unsigned kDefaultSpinMicroseconds = 50;

  // Best effort: clamps `threads` to kMaxThreads and, where the system
  // refuses a thread, works with the threads it did start (thread_count()
  // says how many). Use create() to have either case reported.
  explicit ThreadPool(unsigned threads = 0, unsigned spin_us = kDefaultSpinMicroseconds);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned thread_count() const { return static_cast<unsigned>(workers_.size()) + 1; }

  // A non-owning reference to parallel_for's body, callable as
  // body(begin, end, thread_index): a lambda converts to it without the
  // heap allocation std::function makes for one capturing more than two
  // references (each search call of a crowd tick passes one).
  class Body {
   public:
    template <class F>
      requires(!std::is_same_v<std::remove_cvref_t<F>, Body> &&
               std::is_invocable_v<F&, std::size_t, std::size_t, unsigned>)
    Body(F&& body) noexcept  // implicit, as std::function is
        : object_(const_cast<void*>(static_cast<const void*>(std::addressof(body)))),
          call_([](void* object, std::size_t begin, std::size_t end, unsigned thread) {
            (*static_cast<std::remove_reference_t<F>*>(object))(begin, end, thread);
          }) {}
    void operator()(std::size_t begin, std::size_t end, unsigned thread) const { call_(object_, begin, end, thread); }

   private:
    void* object_;
    void (*call_)(void*, std::size_t, std::size_t, unsigned);
  };

  // Calls body(begin, end, thread_index) over chunks of [0, count); at most
  // thread_count() chunks run at once, thread_index < thread_count(). The
  // body must live until the call returns (a temporary lambda does).
  // Not reentrant: one parallel_for at a time per pool.
  void parallel_for(std::size_t count, Body body);

 private:
  void worker_loop(unsigned index);
  // Polls `done` for up to spin_us_; returns whether it became true.
  template <class Done>
  bool spin_until(const Done& done) const;

  std::string start_error_;  // why a worker did not start, or empty
  unsigned spin_us_ = kDefaultSpinMicroseconds;

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  // Written under mutex_; generation_ and pending_ are also read without it
  // by the spinning threads, which then take mutex_ before they act.
  const Body* body_ = nullptr;
  std::size_t count_ = 0;
  std::atomic<std::size_t> generation_{0};
  std::atomic<unsigned> pending_{0};
  std::atomic<bool> stopping_{false};
};

}  // namespace mmvk
