// The backend suite for the CPU backends: the reference itself (the suite's
// own sanity check) and FastSearch, brute force and pruned, with the query
// split (B >= threads) and the row split (B < threads) both exercised, and
// with the widest kernels this CPU has as well as the SSE2 baseline ones.
#include "support/backend_suite.hpp"
#include "support/cpu_backend_factories.hpp"

namespace mmvk::test {
namespace {

using CpuBackends = ::testing::Types<ReferenceFactory, FastFactory<false, 2>, FastFactory<true, 2>,
                                     FastFactory<false, 1>, FastFactory<true, 3>, FastFactory<false, 2, true>,
                                     FastFactory<true, 2, true>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Cpu, BackendSuite, CpuBackends);

}  // namespace
}  // namespace mmvk::test
