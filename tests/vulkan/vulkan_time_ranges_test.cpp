// The Vulkan backends on a real database with time-ranged tags and costs
// (manifest tag_ranges and cost_ranges, stored per frame): the reference's
// frames and cost bits on queries that require or exclude the range tags.
#include <gtest/gtest.h>

#include "mmvk/vulkan/backends.hpp"
#include "support/time_ranges_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

TEST(VulkanTimeRanges, EveryExactBackendMatchesTheReference) {
  MMVK_REQUIRE_DATA_DIR(data);
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  Result<Database> db = build_ranged_database(data);
  ASSERT_TRUE(db.ok()) << db.message();
  BackendRegistry registry;
  ASSERT_TRUE(vulkan::add_backends(registry, *context, search_options(64, 4, 16, false)).ok());
  BackendSpec spec;
  spec.kmeans.clusters = 16;
  spec.nprobe = 1u << 20;  // every cluster: exact
  const char* const names[] = {"vulkan-brute", "vulkan-clusters", "vulkan-nprobe"};
  expect_reference_results(*db, registry, spec, names);
}

}  // namespace
}  // namespace mmvk::test
