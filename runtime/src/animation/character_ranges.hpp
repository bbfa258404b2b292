// How the controller's passes split characters over the caller's pool.
#pragma once

#include <cstddef>

#include "mmvk/common/thread_pool.hpp"

namespace mmvk::detail {

// Characters below this count run on the calling thread: waking the pool
// costs more than the work.
inline constexpr std::size_t kParallelMin = 128;

// body(begin, end, thread) over [0, count), on the pool when it is worth it.
template <class Body>
void for_characters(ThreadPool& pool, std::size_t count, const Body& body) {
  if (count < kParallelMin || pool.thread_count() == 1) {
    body(0, count, 0u);
  } else {
    pool.parallel_for(count, body);
  }
}

}  // namespace mmvk::detail
