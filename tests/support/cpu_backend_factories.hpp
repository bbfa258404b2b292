// Factories of the CPU backends for the typed backend suites
// (backend_suite.hpp, backend_data_suite.hpp).
#pragma once

#include <memory>

#include "mmvk/fast_search.hpp"
#include "mmvk/reference_search.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::test {

struct ReferenceFactory {
  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    return std::unique_ptr<SearchBackend>(std::make_unique<ReferenceSearch>(db));
  }
};

template <bool Prune, unsigned Threads, bool Baseline = false>
struct FastFactory {
  ThreadPool pool{Threads};
  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    FastSearchOptions options;
    options.prune = Prune;
    options.rows_per_block = 512;  // several cache blocks even on small test data
    options.baseline_kernels = Baseline;
    return std::unique_ptr<SearchBackend>(std::make_unique<FastSearch>(db, pool, options));
  }
};

}  // namespace mmvk::test
