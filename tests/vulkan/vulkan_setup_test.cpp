// The Vulkan backend's setup helpers (runtime/vulkan/src: descriptors.hpp,
// pipeline.hpp, scan_rows.hpp; white-box, through the private headers): what
// they refuse before anything reaches the driver, and the brute force's
// frame-to-row maps. And VulkanClusterSearch::create validating its cluster
// table, exact or nprobe.
#include <array>
#include <cstdint>
#include <utility>

#include "descriptors.hpp"
#include "memory.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/vulkan/vulkan_cluster_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "pipeline.hpp"
#include "scan_rows.hpp"
#include "support/search_test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

using namespace vulkan::detail;

struct TestPush {
  std::uint32_t words[4];
};

bool mentions(const Status& status, const char* text) {
  return !status.ok() && status.message().find(text) != std::string::npos;
}

TEST(VulkanSetup, BindingLimitsNameTheKernels) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const std::array<SetShape, 2> fits = {SetShape{3, 5}, SetShape{4, 5}};
  EXPECT_TRUE(check_binding_limits(*context, fits, "search kernels").ok());
  const std::array<SetShape, 1> huge = {SetShape{1u << 24, 1u << 24}};
  const Status refused = check_binding_limits(*context, huge, "huge kernels");
  EXPECT_TRUE(mentions(refused, "huge kernels")) << refused.message();
}

// Every check fails before recording, so no command buffer or pipeline is
// needed (null handles would crash any recording that slipped through).
TEST(VulkanSetup, DispatchChecksBeforeRecording) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const VkPhysicalDeviceLimits& limits = context->properties().limits;
  Result<UniquePipelineLayout> layout = create_pipeline_layout(*context, {}, sizeof(TestPush), "test kernels");
  ASSERT_TRUE(layout.ok()) << layout.message();
  const TestPush push{};

  const Status empty = dispatch(*context, VK_NULL_HANDLE, VK_NULL_HANDLE, layout->get(), push, 0, 1, "test_kernel");
  EXPECT_TRUE(mentions(empty, "empty dispatch of test_kernel")) << empty.message();
  if (limits.maxComputeWorkGroupCount[1] < UINT32_MAX) {
    const Status too_many = dispatch(*context, VK_NULL_HANDLE, VK_NULL_HANDLE, layout->get(), push, 1,
                                     limits.maxComputeWorkGroupCount[1] + 1, "test_kernel");
    EXPECT_TRUE(mentions(too_many, "maxComputeWorkGroupCount")) << too_many.message();
    EXPECT_TRUE(mentions(too_many, "test_kernel")) << too_many.message();
  }

  Result<Buffer> arguments =
      create_buffer(*context, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                    MemoryUse::DeviceLocal, "the test arguments");
  ASSERT_TRUE(arguments.ok()) << arguments.message();
  const Status past_end = dispatch_indirect(*context, VK_NULL_HANDLE, VK_NULL_HANDLE, layout->get(), push, *arguments,
                                            8, 1, "test_scan");
  EXPECT_TRUE(mentions(past_end, "test_scan")) << past_end.message();
  const Status unaligned = dispatch_indirect(*context, VK_NULL_HANDLE, VK_NULL_HANDLE, layout->get(), push,
                                             *arguments, 2, 1, "test_scan");
  EXPECT_TRUE(mentions(unaligned, "aligned")) << unaligned.message();
  const Status too_many_indirect =
      dispatch_indirect(*context, VK_NULL_HANDLE, VK_NULL_HANDLE, layout->get(), push, *arguments, 0,
                        std::uint64_t{limits.maxComputeWorkGroupCount[0]} + 1, "test_scan");
  EXPECT_TRUE(mentions(too_many_indirect, "maxComputeWorkGroupCount")) << too_many_indirect.message();
}

TEST(VulkanSetup, PipelineLayoutChecksPushConstantSize) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const std::uint32_t allowed = context->properties().limits.maxPushConstantsSize;
  EXPECT_TRUE(create_pipeline_layout(*context, {}, allowed, "test kernels").ok());
  Result<UniquePipelineLayout> too_big = create_pipeline_layout(*context, {}, allowed + 4, "big kernels");
  ASSERT_FALSE(too_big.ok());
  EXPECT_NE(too_big.message().find("big kernels"), std::string::npos) << too_big.message();
}

TEST(VulkanSetup, AllocatesAndWritesSets) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const SetShape shape{0, 2};
  Result<UniqueDescriptorSetLayout> set_layout = create_set_layout(*context, shape);
  ASSERT_TRUE(set_layout.ok()) << set_layout.message();
  Result<UniqueDescriptorPool> pool = create_descriptor_pool(*context, shape, 2);
  ASSERT_TRUE(pool.ok()) << pool.message();
  std::array<Buffer, 2> buffers;
  for (Buffer& buffer : buffers) {
    Result<Buffer> created =
        create_buffer(*context, 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::HostMapped, "a test buffer");
    ASSERT_TRUE(created.ok()) << created.message();
    buffer = std::move(*created);
  }
  const std::array<VkBuffer, 2> handles = {buffers[0].buffer.get(), buffers[1].buffer.get()};
  for (int s = 0; s < 2; ++s) {
    Result<VkDescriptorSet> set = allocate_set(*context, pool->get(), set_layout->get(), {}, handles);
    ASSERT_TRUE(set.ok()) << set.message();
    EXPECT_NE(*set, VK_NULL_HANDLE);
  }
}

// Scan rows {1, 2, 5} of 7 frames (rows_before, scan_rows.hpp): the
// features hold frames 1, 2, 5, then 0, 3, 4, 6; no table (the cluster
// modes) leaves every frame in place.
TEST(VulkanSetup, FeatureRowsPutTheScanRowsFirst) {
  const std::array<std::uint32_t, 8> scan = {0, 0, 1, 2, 2, 2, 3, 3};
  const std::array<std::uint32_t, 7> rows = {3, 0, 1, 4, 5, 2, 6};
  for (std::uint32_t f = 0; f < rows.size(); ++f) {
    EXPECT_EQ(feature_row(scan, f), rows[f]) << "frame " << f;
    EXPECT_EQ(feature_row({}, f), f);
  }
}

// A query's skipped frames as scan rows (first, last - first), (kNoFrame, 0)
// when no scan row is among them; as frames when there is no table.
TEST(VulkanSetup, SkippedFramesBecomeScanRows) {
  const std::array<std::uint32_t, 8> scan = {0, 0, 1, 2, 2, 2, 3, 4};  // rows_before of frames 1, 2, 5, 6 of 7
  using Ranges = std::array<std::uint32_t, 4>;
  QueryGpu p{};
  p.continuing_frame = kNoFrame;
  p.window_clip = kNoFrame;
  EXPECT_EQ(skipped_scan_rows(scan, p), (Ranges{kNoFrame, 0, kNoFrame, 0}));
  p.continuing_frame = 5;  // no window: only itself
  EXPECT_EQ(skipped_scan_rows(scan, p), (Ranges{2, 0, kNoFrame, 0}));
  p.continuing_frame = 3;  // not a scan row
  EXPECT_EQ(skipped_scan_rows(scan, p), (Ranges{kNoFrame, 0, kNoFrame, 0}));
  p.window_clip = 0;
  p.clip_first = 0;
  p.clip_count = 7;
  p.exclusion_window = 2;  // frames 1..5: rows 0..2
  EXPECT_EQ(skipped_scan_rows(scan, p), (Ranges{0, 2, kNoFrame, 0}));
  p.continuing_frame = 0;  // frames 0..2, and through the loop 5..6: rows 0..1 and 2..3
  p.clip_loop = 1;
  EXPECT_EQ(skipped_scan_rows(scan, p), (Ranges{0, 1, 2, 1}));
  // No table (the cluster modes): the frame ranges themselves.
  EXPECT_EQ(skipped_scan_rows({}, p), (Ranges{0, 2, 5, 1}));
}

// The cluster search checks its table in full (validate_cluster_table).
// (The brute force takes no table.)
TEST(VulkanSetup, CreateValidatesTheClusterTable) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 1000, .seed = 71});
  ThreadPool pool{2};
  KMeansParams params;
  params.iterations = 5;
  Result<ClusterTable> trained = train_cluster_table(db, params, pool);
  ASSERT_TRUE(trained.ok()) << trained.message();
  ClusterTable table = std::move(trained).value();
  vulkan::VulkanSearchOptions options;
  options.warm_up = false;
  options.max_batch = 4;
  ASSERT_TRUE(vulkan::VulkanClusterSearch::create(*context, db, table, options).ok());

  // Same database, malformed: two members of one cluster swapped (members
  // must ascend within a cluster).
  std::uint32_t c = 0;
  while (table.offsets[c + 1] - table.offsets[c] < 2) ++c;
  std::swap(table.members[table.offsets[c]], table.members[table.offsets[c] + 1]);
  for (const std::uint32_t nprobe : {0u, 8u}) {
    vulkan::VulkanClusterOptions cluster_options;
    cluster_options.nprobe = nprobe;
    Result<std::unique_ptr<vulkan::VulkanClusterSearch>> created =
        vulkan::VulkanClusterSearch::create(*context, db, table, options, cluster_options);
    ASSERT_FALSE(created.ok());
    EXPECT_NE(created.message().find("members are not in ascending order"), std::string::npos) << created.message();
  }
}

}  // namespace
}  // namespace mmvk::test
