// The shared backend suites (backend_suite.hpp on random data,
// backend_data_suite.hpp on the Bandai locomotion features) for the Vulkan
// cluster modes: ClustersExact and NProbe with nprobe = all clusters, both
// of which must give the reference's frames and cost bits. Plus: NProbe
// with few clusters equals the CPU ClusterSearch with the same nprobe and
// table, a run under the validation layer, and the creation errors.
#include <map>
#include <memory>
#include <string_view>

#include "mmvk/search/backends.hpp"
#include "mmvk/search/cluster_search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/vulkan/backends.hpp"
#include "mmvk/vulkan/vulkan_brute_force.hpp"
#include "mmvk/vulkan/vulkan_cluster_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/backend_data_suite.hpp"
#include "support/backend_suite.hpp"
#include "support/cluster_table_cache.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

// Made through the backend registry (mmvk::vulkan::add_backends); the
// cache keeps one table per database alive with the context.
template <bool Exact, std::uint32_t NProbe>
struct VulkanClusterFactory : VulkanRegistryFactory {
  ClusterTableCache tables;

  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    if (!context) return make_error(error);
    BackendSpec spec{.name = Exact ? "vulkan-clusters" : "vulkan-nprobe"};
    MMVK_ASSIGN_OR_RETURN(spec.clusters, tables.table_for(db));
    spec.nprobe = NProbe;
    return registry.make(spec, db);
  }
};

using VulkanClustersExact = VulkanClusterFactory<true, 0>;
using VulkanProbeAll = VulkanClusterFactory<false, 0xFFFFFFFFu>;
using VulkanClusterBackends = ::testing::Types<VulkanClustersExact, VulkanProbeAll>;
INSTANTIATE_TYPED_TEST_SUITE_P(VulkanClusters, BackendSuite, VulkanClusterBackends);
INSTANTIATE_TYPED_TEST_SUITE_P(VulkanClusters, BackendDataSuite, VulkanClusterBackends);

// The three Vulkan searches by their registry names, made directly.
constexpr std::string_view kVulkanSearches[] = {"vulkan-brute", "vulkan-clusters", "vulkan-nprobe"};

std::unique_ptr<vulkan::VulkanSearch> make_named(vulkan::Context& context, const Database& db, std::string_view name,
                                                 const vulkan::VulkanSearchOptions& options, const ClusterTable& table,
                                                 vulkan::VulkanClusterOptions cluster_options = {}) {
  if (name == "vulkan-brute") {
    auto made = vulkan::VulkanBruteForce::create(context, db, options);
    EXPECT_TRUE(made.ok()) << made.message();
    return made.ok() ? std::move(made).value() : nullptr;
  }
  if (name == "vulkan-nprobe") cluster_options.nprobe = 8;
  auto made = vulkan::VulkanClusterSearch::create(context, db, table, options, cluster_options);
  EXPECT_TRUE(made.ok()) << made.message();
  return made.ok() ? std::move(made).value() : nullptr;
}

// Approximate mode: the same clusters as the CPU nprobe (nearest centroids
// by channel-weighted squared distance, ties by cluster id), searched
// exactly, so the same answers; also with constraints and k > 1.
TEST(VulkanClusterSearch, NProbeEqualsCpuNProbe) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 3000, .seed = 51, .constraints = true});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  const std::vector<float> queries = synthetic_queries(db, 64, 52);
  const std::vector<QueryParams> params = random_params(db, 64, 53);
  for (const std::uint32_t nprobe : {1u, 3u, 10u}) {
    SCOPED_TRACE("nprobe " + std::to_string(nprobe));
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;
    vulkan::VulkanClusterOptions probe;
    probe.nprobe = nprobe;
    auto gpu = vulkan::VulkanClusterSearch::create(*context, db, **table, options, probe);
    ASSERT_TRUE(gpu.ok()) << gpu.message();
    ClusterSearchOptions cpu_options;
    cpu_options.nprobe = nprobe;
    auto cpu = ClusterSearch::create(db, **table, tables.pool, cpu_options);
    ASSERT_TRUE(cpu.ok()) << cpu.message();
    for (const std::uint32_t k : {1u, 4u}) {
      const std::vector<Match> expected = run_search(**cpu, queries, params, 64, k);
      const std::vector<Match> actual = run_search(**gpu, queries, params, 64, k);
      expect_identical(expected, actual, k, params, (*gpu)->name());
      const std::vector<Match> expected_plain = run_search(**cpu, queries, {}, 64, k);
      const std::vector<Match> actual_plain = run_search(**gpu, queries, {}, 64, k);
      expect_identical(expected_plain, actual_plain, k, {}, (*gpu)->name());
    }
    // Fewer rows than exhaustive.
    EXPECT_LT((*gpu)->stats().rows_fraction(db.frame_count()), 1.0);
  }
}

// Pruning visits fewer rows than brute force, and warm-up plus small
// scratch (several chunks per submit) keep the results exact.
TEST(VulkanClusterSearch, PrunesAndChunksUnderValidation) {
  vulkan::ContextOptions context_options;
  context_options.validation = true;
  MMVK_VULKAN_CONTEXT(context, context_options);
  const Database db = synthetic_database({.frames = 4000, .seed = 55, .constraints = true});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  vulkan::VulkanSearchOptions options;
  options.max_batch = 100;
  options.max_k = 4;
  options.scratch_bytes = 16 << 10;  // a few queries per chunk
  vulkan::VulkanClusterOptions cluster_options;
  cluster_options.scratch_bytes = 16 << 10;
  auto created = vulkan::VulkanClusterSearch::create(*context, db, **table, options, cluster_options);
  ASSERT_TRUE(created.ok()) << created.message();
  std::unique_ptr<vulkan::VulkanSearch> gpu = std::move(created).value();
  const std::vector<float> queries = synthetic_queries(db, 100, 56, 0.05f);
  std::vector<QueryParams> params = random_params(db, 100, 57);
  const std::vector<Match> expected = reference_results(db, queries, params, 100, 4);
  const std::vector<Match> actual = run_search(*gpu, queries, params, 100, 4);
  expect_identical(expected, actual, 4, params, gpu->name());
  EXPECT_LT(gpu->stats().rows_fraction(db.frame_count()), 0.9);
  gpu.reset();
  const std::vector<std::string> messages = context->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, the first: " << messages.front();
}

// A table of `clusters` clusters (fewer than ClusterTableCache's default,
// so that each holds many member blocks), trained briefly.
Result<ClusterTable> train_few_clusters(const Database& db, std::uint32_t clusters, std::uint32_t iterations) {
  ThreadPool pool(2);
  KMeansParams params;
  params.clusters = clusters;
  params.iterations = iterations;
  return train_cluster_table(db, params, pool);
}

// The cluster kernels' loops (the listing and merging of member blocks per
// query) stay within llvmpipe's 65,535 iterations at large N, where a loop
// cut short returns wrong answers silently (shared/LAVAPIPE.md): 300k
// frames in few clusters (thousands of member blocks), queries near the
// data and far from it (the far ones list most blocks), k = 1 and k = 16.
TEST(VulkanClusterSearch, LargeDatabaseStaysExact) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 300000, .clips = 64, .seed = 111, .channel_dims = {2, 2}});
  Result<ClusterTable> table = train_few_clusters(db, 48, 3);
  ASSERT_TRUE(table.ok()) << table.message();
  std::vector<float> queries = synthetic_queries(db, 48, 112);
  for (std::size_t i = 0; i < 16 * db.dims(); ++i) queries.push_back(queries[i] + (i % 2 == 0 ? 40.0f : -25.0f));
  for (const std::uint32_t k : {1u, 16u}) {
    SCOPED_TRACE("k " + std::to_string(k));
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;
    options.max_batch = 64;
    options.max_k = k;
    auto gpu = vulkan::VulkanClusterSearch::create(*context, db, *table, options);
    ASSERT_TRUE(gpu.ok()) << gpu.message();
    const std::vector<Match> expected = reference_results(db, queries, {}, 64, k);
    expect_identical(expected, run_search(**gpu, queries, {}, 64, k), k, {}, (*gpu)->name());
  }
}

// The scan evaluates a block once for a tile of the queries that visit it
// (cluster_sort.comp sorts the work items by block): many queries near the
// same few rows fill whole tiles and leave partial ones, and the queries of
// one tile differ in tags, exclusion windows and continuing frames. Exact
// for k = 1, 4 and 16, in one chunk and in chunks of a few queries, under
// the validation layer.
TEST(VulkanClusterSearch, TiledScanOverSharedBlocksStaysExact) {
  vulkan::ContextOptions context_options;
  context_options.validation = true;
  MMVK_VULKAN_CONTEXT(context, context_options);
  const Database db = synthetic_database({.frames = 5000, .seed = 121, .constraints = true});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  constexpr std::uint32_t kBatch = 203;  // 7 bases x 29: tiles of 8 full and partial
  const std::vector<float> bases = synthetic_queries(db, 7, 122, 0.05f);
  std::vector<float> queries;
  for (std::uint32_t i = 0; i < kBatch; ++i) {
    const std::size_t base = std::size_t{i % 7} * db.dims();
    for (std::uint32_t d = 0; d < db.dims(); ++d) {
      queries.push_back(bases[base + d] + 1e-3f * static_cast<float>((i * 7 + d * 3) % 11));
    }
  }
  const std::vector<QueryParams> params = random_params(db, kBatch, 123);
  for (const std::uint64_t cluster_scratch : {std::uint64_t{512} << 20, std::uint64_t{64} << 10}) {
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;
    options.max_batch = kBatch;
    options.max_k = 16;
    vulkan::VulkanClusterOptions cluster_options;
    cluster_options.scratch_bytes = cluster_scratch;
    auto gpu = vulkan::VulkanClusterSearch::create(*context, db, **table, options, cluster_options);
    ASSERT_TRUE(gpu.ok()) << gpu.message();
    for (const std::uint32_t k : {1u, 4u, 16u}) {
      SCOPED_TRACE("k " + std::to_string(k) + ", cluster scratch " + std::to_string(cluster_scratch));
      const std::vector<Match> expected = reference_results(db, queries, params, kBatch, k);
      expect_identical(expected, run_search(**gpu, queries, params, kBatch, k), k, params, (*gpu)->name());
      const std::vector<Match> expected_plain = reference_results(db, queries, {}, kBatch, k);
      expect_identical(expected_plain, run_search(**gpu, queries, {}, kBatch, k), k, {}, (*gpu)->name());
    }
    EXPECT_LT((*gpu)->stats().rows_fraction(db.frame_count()), 0.9);
  }
  const std::vector<std::string> messages = context->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, the first: " << messages.front();
}

// Clusters of about a thousand members, so that each holds several member
// blocks (256 rows and up: the other tests' tables give one block a
// cluster): the blocks of one cluster are culled one by one, and what is
// left stays exact for k = 1 and 4, with the candidate rules, under the
// validation layer.
TEST(VulkanClusterSearch, BlocksOfOneClusterAreCulledExactly) {
  vulkan::ContextOptions context_options;
  context_options.validation = true;
  MMVK_VULKAN_CONTEXT(context, context_options);
  const Database db = synthetic_database({.frames = 6000, .clips = 12, .seed = 131, .constraints = true});
  Result<ClusterTable> table = train_few_clusters(db, 6, 4);
  ASSERT_TRUE(table.ok()) << table.message();
  std::uint32_t largest = 0;
  for (std::uint32_t c = 0; c < table->cluster_count; ++c) {
    largest = std::max(largest, table->offsets[c + 1] - table->offsets[c]);
  }
  ASSERT_GT(largest, 3u * 256u) << "no cluster of four blocks or more";
  constexpr std::uint32_t kBatch = 64;
  const std::vector<float> queries = synthetic_queries(db, kBatch, 132, 0.05f);
  const std::vector<QueryParams> params = random_params(db, kBatch, 133);
  vulkan::VulkanSearchOptions options;
  options.warm_up = false;
  options.max_batch = kBatch;
  options.max_k = 4;
  auto gpu = vulkan::VulkanClusterSearch::create(*context, db, *table, options);
  ASSERT_TRUE(gpu.ok()) << gpu.message();
  for (const std::uint32_t k : {1u, 4u}) {
    SCOPED_TRACE("k " + std::to_string(k));
    expect_identical(reference_results(db, queries, params, kBatch, k), run_search(**gpu, queries, params, kBatch, k),
                     k, params, (*gpu)->name());
    expect_identical(reference_results(db, queries, {}, kBatch, k), run_search(**gpu, queries, {}, kBatch, k), k, {},
                     (*gpu)->name());
  }
  EXPECT_LT((*gpu)->stats().rows_fraction(db.frame_count()), 0.9);
  gpu->reset();
  const std::vector<std::string> messages = context->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, the first: " << messages.front();
}

// A backend builds the pipelines of its own mode only (warm_up() runs each):
// the cluster modes no brute-force kernel, brute force no cluster kernel.
TEST(VulkanClusterSearch, BuildsOnlyItsModesKernels) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 2000, .seed = 113});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  const auto has = [](const std::vector<std::string_view>& names, std::string_view prefix) {
    for (const std::string_view name : names) {
      if (name.starts_with(prefix)) return true;
    }
    return false;
  };
  for (const std::string_view name : kVulkanSearches) {
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;
    options.max_k = 4;
    std::unique_ptr<vulkan::VulkanSearch> gpu = make_named(*context, db, name, options, **table);
    ASSERT_NE(gpu, nullptr) << name;
    EXPECT_EQ(gpu->name(), name);
    const std::vector<std::string_view> kernels = gpu->kernels();
    const bool brute = name == "vulkan-brute";
    EXPECT_EQ(has(kernels, "brute_force_scan") || has(kernels, "topk_merge"), brute) << gpu->name();
    EXPECT_EQ(has(kernels, "cluster_"), !brute) << gpu->name();
    // K classes 1 and 4: a scan per round (their tiles differ) and a merge
    // each, plus bounds, select and the block sort's three steps.
    if (!brute) {
      EXPECT_EQ(kernels.size(), 11u);
    }
    EXPECT_TRUE(gpu->warm_up().ok());
  }
}

// device_bytes() counts what a search allocated: at least the database's
// features (dims padded to 4 floats), the cluster modes their second,
// cluster-ordered copy of the rows on top, and each slot the same amount
// (slots 1, 2 and 3 step by a constant that grows with the cluster
// scratch budget).
TEST(VulkanClusterSearch, DeviceBytesCountTheDatabaseTablesAndSlots) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 3000, .seed = 71});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  const std::uint64_t feature_bytes = std::uint64_t{db.frame_count()} * ((db.dims() + 3) / 4) * 16;
  const auto bytes_of = [&](std::string_view name, std::uint32_t slots, std::uint64_t cluster_scratch) {
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;
    options.slots = slots;
    options.max_batch = 64;
    vulkan::VulkanClusterOptions cluster_options;
    cluster_options.scratch_bytes = cluster_scratch;
    const std::unique_ptr<vulkan::VulkanSearch> gpu = make_named(*context, db, name, options, **table, cluster_options);
    return gpu != nullptr ? gpu->device_bytes() : 0;
  };
  // A budget below max_batch queries' scratch (small with 256-row blocks),
  // so that a roomier one holds more queries per chunk.
  constexpr std::uint64_t kSmallScratch = 16u << 10;
  const std::uint64_t brute = bytes_of("vulkan-brute", 1, kSmallScratch);
  const std::uint64_t clusters[] = {bytes_of("vulkan-clusters", 1, kSmallScratch),
                                    bytes_of("vulkan-clusters", 2, kSmallScratch),
                                    bytes_of("vulkan-clusters", 3, kSmallScratch)};
  // Metadata 16 and cost terms 8 bytes a frame; every frame is scanned here
  // (no flags), with 4 + 16 bytes for scan_frames and scan_terms.
  EXPECT_GE(brute, feature_bytes + std::uint64_t{db.frame_count()} * (16 + 8 + 4 + 16));
  EXPECT_GE(clusters[0], 2 * feature_bytes);
  const std::uint64_t per_slot = clusters[1] - clusters[0];
  EXPECT_GT(per_slot, 0u);
  EXPECT_EQ(clusters[2] - clusters[1], per_slot);
  // A larger scratch budget holds more queries per chunk: more per slot.
  const std::uint64_t roomy = bytes_of("vulkan-clusters", 1, 64u << 20);
  EXPECT_GT(roomy, clusters[0]);
}

TEST(VulkanClusterSearch, CreationErrors) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 1000, .seed = 59});
  const Database other = synthetic_database({.frames = 1000, .seed = 60});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  vulkan::VulkanSearchOptions options;
  options.warm_up = false;
  // A search without a table does not compile (create() takes one by
  // reference); nprobe 0 is the exact search, as in ClusterSearchOptions,
  // and the registry's vulkan-nprobe refuses it (VulkanBackendRegistry).
  auto mismatched = vulkan::VulkanClusterSearch::create(*context, other, **table, options);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.message().find("cluster table"), std::string::npos) << mismatched.message();
  auto zero = vulkan::VulkanClusterSearch::create(*context, db, **table, options);
  ASSERT_TRUE(zero.ok()) << zero.message();
  EXPECT_EQ((*zero)->name(), "vulkan-clusters");
}

}  // namespace
}  // namespace mmvk::test
