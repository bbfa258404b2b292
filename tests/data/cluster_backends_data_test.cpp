// The cluster-pruned CPU backend against the reference on real features
// (Bandai locomotion, default schema): same frames, bit-identical costs.
#include "support/backend_data_suite.hpp"
#include "support/cluster_backend_factories.hpp"

namespace mmvk::test {
namespace {

using ClusterBackends = ::testing::Types<ClusterExactFactory, ClusterProbeAllFactory>;
INSTANTIATE_TYPED_TEST_SUITE_P(Clusters, BackendDataSuite, ClusterBackends);

}  // namespace
}  // namespace mmvk::test
