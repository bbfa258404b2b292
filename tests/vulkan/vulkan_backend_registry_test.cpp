// The Vulkan entries of the backend registry: each name makes a backend
// whose name() is that name, they add to the CPU entries without a clash,
// a context source is only asked when a backend is made, and its error is
// the backend's error.
#include <gtest/gtest.h>

#include <memory>
#include <set>
#include <string>

#include "mmvk/search/backends.hpp"
#include "mmvk/vulkan/backends.hpp"
#include "support/cluster_table_cache.hpp"
#include "support/search_test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

TEST(VulkanBackendRegistry, EveryNameRoundTripsThroughName) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 600, .seed = 8});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  BackendRegistry registry = cpu_backends();
  const std::size_t cpu_count = registry.entries().size();
  ASSERT_TRUE(vulkan::add_backends(registry, *context, search_options(16, 2, 4, false)).ok());
  EXPECT_EQ(registry.entries().size(), cpu_count + 3);
  std::set<std::string> vulkan_names;
  for (const BackendEntry& entry : registry.entries()) {
    if (!entry.name.starts_with("vulkan-")) continue;
    SCOPED_TRACE(entry.name);
    vulkan_names.insert(entry.name);
    EXPECT_EQ(entry.uses_cluster_table, entry.name != "vulkan-brute");
    BackendSpec spec{.name = entry.name, .clusters = *table};
    Result<std::unique_ptr<SearchBackend>> backend = registry.make(spec, db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    EXPECT_EQ((*backend)->name(), entry.name);
    // The device text is the context's, which names the device, its index and type.
    EXPECT_EQ((*backend)->device(), context->description());
  }
  EXPECT_EQ(context->description().rfind(context->device_name() + " (Vulkan device ", 0), 0u) << context->description();
  EXPECT_EQ(vulkan_names, (std::set<std::string>{"vulkan-brute", "vulkan-clusters", "vulkan-nprobe"}));
  // Adding them twice clashes.
  EXPECT_FALSE(vulkan::add_backends(registry, *context).ok());
}

TEST(VulkanBackendRegistry, ContextSourceIsAskedOnlyWhenMaking) {
  const Database db = synthetic_database({.frames = 200, .seed = 9});
  int asked = 0;
  BackendRegistry registry = cpu_backends();
  ASSERT_TRUE(vulkan::add_backends(registry, [&asked]() -> Result<vulkan::Context*> {
                ++asked;
                return make_error("no device here");
              }).ok());
  EXPECT_NE(registry.names().find("vulkan-nprobe"), std::string::npos);
  EXPECT_EQ(asked, 0);
  Result<std::unique_ptr<SearchBackend>> backend = registry.make(BackendSpec{.name = "vulkan-brute"}, db);
  ASSERT_FALSE(backend.ok());
  EXPECT_NE(backend.message().find("no device here"), std::string::npos) << backend.message();
  EXPECT_EQ(asked, 1);
}

TEST(VulkanBackendRegistry, SpecMistakesAreErrors) {
  MMVK_VULKAN_CONTEXT(context, vulkan::ContextOptions{});
  const Database db = synthetic_database({.frames = 400, .seed = 10});
  const Database other = synthetic_database({.frames = 400, .seed = 11});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  BackendRegistry registry;
  ASSERT_TRUE(vulkan::add_backends(registry, *context, search_options(1024, kMaxK, 16, false)).ok());
  for (const char* name : {"vulkan-clusters", "vulkan-nprobe"}) {
    Result<std::unique_ptr<SearchBackend>> mismatched =
        registry.make(BackendSpec{.name = name, .clusters = *table}, other);
    ASSERT_FALSE(mismatched.ok()) << name;
    EXPECT_NE(mismatched.message().find("cluster table"), std::string::npos) << mismatched.message();
  }
  BackendSpec zero{.name = "vulkan-nprobe", .clusters = *table};
  zero.nprobe = 0;
  Result<std::unique_ptr<SearchBackend>> zero_probe = registry.make(zero, db);
  ASSERT_FALSE(zero_probe.ok());
  EXPECT_NE(zero_probe.message().find("nprobe"), std::string::npos) << zero_probe.message();
}

}  // namespace
}  // namespace mmvk::test
