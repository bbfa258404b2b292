// Factories of the CPU backends for the typed backend suites
// (backend_suite.hpp, backend_data_suite.hpp), made through the backend
// registry (mmvk/search/backends.hpp) like every other user makes them.
#pragma once

#include <memory>

#include "mmvk/search/backends.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::test {

struct ReferenceFactory {
  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    return cpu_backends().make(BackendSpec{.name = "reference"}, db);
  }
};

// Generic: the x86-64 baseline kernels instead of the widest this CPU runs.
template <bool Prune, unsigned Threads, bool Generic = false>
struct FastFactory {
  ThreadPool pool{Threads};
  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    BackendSpec spec{.name = Prune ? "fast-box" : "fast-brute", .pool = &pool};
    spec.fast.rows_per_block = 512;  // several cache blocks even on small test data
    spec.fast.kernels = Generic ? CpuKernels::Generic : CpuKernels::Widest;
    return cpu_backends().make(spec, db);
  }
};

}  // namespace mmvk::test
