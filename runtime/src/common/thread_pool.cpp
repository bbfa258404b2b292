#include "mmvk/thread_pool.hpp"

#include <system_error>

namespace mmvk {

namespace {
// Chunk `index` of `parts` equal slices of [0, count).
std::pair<std::size_t, std::size_t> chunk(std::size_t count, unsigned parts, unsigned index) {
  return {count * index / parts, count * (index + 1) / parts};
}
}  // namespace

Result<std::unique_ptr<ThreadPool>> ThreadPool::create(unsigned threads) {
  if (threads > kMaxThreads) {
    return make_error("thread pool: " + std::to_string(threads) + " threads is more than the maximum of " +
                      std::to_string(kMaxThreads));
  }
  auto pool = std::make_unique<ThreadPool>(threads);
  if (!pool->start_error_.empty()) return make_error(pool->start_error_);
  return pool;
}

ThreadPool::ThreadPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = std::min(threads, kMaxThreads);
  workers_.reserve(threads - 1);
  for (unsigned i = 1; i < threads; ++i) {
#if defined(__cpp_exceptions)
    // std::thread reports a refused start (EAGAIN: process or memory limits)
    // only by throwing; the pool turns it into fewer workers and a message.
    try {
      workers_.emplace_back([this, i] { worker_loop(i); });
    } catch (const std::system_error& error) {
      start_error_ = "thread pool: could not start thread " + std::to_string(i + 1) + " of " +
                     std::to_string(threads) + ": " + error.what();
      break;
    }
#else
    workers_.emplace_back([this, i] { worker_loop(i); });
#endif
  }
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void ThreadPool::parallel_for(std::size_t count, const std::function<void(std::size_t, std::size_t, unsigned)>& body) {
  if (count == 0) return;
  const unsigned parts = thread_count();
  if (parts == 1 || count == 1) {
    body(0, count, 0);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    body_ = &body;
    count_ = count;
    pending_ = parts - 1;
    ++generation_;
  }
  wake_.notify_all();
  const auto [begin, end] = chunk(count, parts, 0);
  if (begin < end) body(begin, end, 0);
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return pending_ == 0; });
  body_ = nullptr;
}

void ThreadPool::worker_loop(unsigned index) {
  std::size_t seen_generation = 0;
  for (;;) {
    const std::function<void(std::size_t, std::size_t, unsigned)>* body = nullptr;
    std::size_t count = 0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || generation_ != seen_generation; });
      if (stopping_) return;
      seen_generation = generation_;
      body = body_;
      count = count_;
    }
    const auto [begin, end] = chunk(count, thread_count(), index);
    if (begin < end) (*body)(begin, end, index);
    {
      std::lock_guard lock(mutex_);
      --pending_;
    }
    done_.notify_one();
  }
}

}  // namespace mmvk
