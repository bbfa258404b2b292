// The typed backend suite for the cluster-pruned CPU backend: exact and
// nprobe = all (which must equal exact). Each bound alone is covered by
// cluster_search_test.cpp.
#include "support/backend_suite.hpp"
#include "support/cluster_backend_factories.hpp"

namespace mmvk::test {
namespace {

using ClusterBackends = ::testing::Types<ClusterExactFactory, ClusterProbeAllFactory>;
INSTANTIATE_TYPED_TEST_SUITE_P(Clusters, BackendSuite, ClusterBackends);

}  // namespace
}  // namespace mmvk::test
