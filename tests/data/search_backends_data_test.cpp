// The CPU backends against the reference on real features (Bandai
// locomotion, default schema): same frames, bit-identical costs.
#include "support/backend_data_suite.hpp"
#include "support/cpu_backend_factories.hpp"

namespace mmvk::test {
namespace {

using CpuBackends = ::testing::Types<FastFactory<false, 2>, FastFactory<true, 2>, FastFactory<true, 2, true>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Cpu, BackendDataSuite, CpuBackends);

}  // namespace
}  // namespace mmvk::test
