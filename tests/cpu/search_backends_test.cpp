// The backend suite for the CPU backends: the reference itself (the suite's
// own sanity check) and FastSearch, brute force and pruned, with the query
// split (B >= threads) and the row split (B < threads) both exercised, and
// with the widest kernels this CPU has as well as the SSE2 baseline ones.
#include <memory>

#include "mmvk/fast_search.hpp"
#include "mmvk/reference_search.hpp"
#include "mmvk/thread_pool.hpp"
#include "support/backend_suite.hpp"

namespace mmvk::test {
namespace {

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

using CpuBackends = ::testing::Types<ReferenceFactory, FastFactory<false, 2>, FastFactory<true, 2>,
                                     FastFactory<false, 1>, FastFactory<true, 3>, FastFactory<false, 2, true>,
                                     FastFactory<true, 2, true>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Cpu, BackendSuite, CpuBackends);

}  // namespace
}  // namespace mmvk::test
