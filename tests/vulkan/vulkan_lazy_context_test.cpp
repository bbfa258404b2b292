// The hosts' Vulkan context helper (LazyContext): the registry lists the
// Vulkan backends without touching the driver, the first Vulkan backend made
// creates the one context (merging in the cache directory's pipeline cache
// file), save_pipeline_cache writes that file for the next run, and a
// failure to create the context is kept and reported again the same way.
#include <filesystem>
#include <memory>
#include <system_error>

#include "mmvk/search/backends.hpp"
#include "mmvk/vulkan/lazy_context.hpp"
#include "mmvk/vulkan/pipeline_cache_file.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

using vulkan::LazyContext;
using vulkan::LazyContextOptions;

BackendSpec small_spec(const char* name) {
  BackendSpec spec;
  spec.name = name;
  return spec;
}

// The searches small_spec's backends are made with.
const vulkan::VulkanSearchOptions kSmall = search_options(4, 1, 1, false);

bool empty_dir(const std::filesystem::path& dir) {
  std::error_code error;
  return std::filesystem::is_empty(dir, error) && !error;
}

TEST(LazyContext, ListsTheBackendsWithoutMakingTheContext) {
  const std::filesystem::path dir = make_temp_dir();
  LazyContext lazy(LazyContextOptions{.context = {}, .cache_directory = dir});
  BackendRegistry registry = cpu_backends();
  ASSERT_TRUE(lazy.add_backends(registry).ok());
  for (const char* name : {"vulkan-brute", "vulkan-clusters", "vulkan-nprobe"}) {
    EXPECT_NE(registry.find(name), nullptr) << name;
  }
  EXPECT_EQ(lazy.created(), nullptr);
  EXPECT_TRUE(lazy.pipeline_cache_note().empty());
  // Nothing to save yet, and nothing written.
  EXPECT_TRUE(lazy.save_pipeline_cache().ok());
  EXPECT_TRUE(empty_dir(dir));
  // The names are registered once: a second add is an error naming one.
  const Status again = lazy.add_backends(registry);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.message().find("vulkan-brute"), std::string::npos) << again.message();
  std::filesystem::remove_all(dir);
}

TEST(LazyContext, MakesOneContextAndKeepsItsPipelineCacheForTheNextRun) {
  MMVK_VULKAN_CONTEXT(probe, {});  // skips (or fails under MMVK_REQUIRE_VULKAN) without a device
  probe.reset();
  const std::filesystem::path dir = make_temp_dir();
  const Database db = synthetic_database({.frames = 64, .seed = 5});
  {
    LazyContext lazy(LazyContextOptions{.context = {}, .cache_directory = dir});
    BackendRegistry registry = cpu_backends();
    ASSERT_TRUE(lazy.add_backends(registry, kSmall).ok());
    Result<std::unique_ptr<SearchBackend>> first = registry.make(small_spec("vulkan-brute"), db);
    ASSERT_TRUE(first.ok()) << first.message();
    vulkan::Context* context = lazy.created();
    ASSERT_NE(context, nullptr);
    // No file yet: not a reason for a note.
    EXPECT_TRUE(lazy.pipeline_cache_note().empty()) << lazy.pipeline_cache_note();
    Result<std::unique_ptr<SearchBackend>> second = registry.make(small_spec("vulkan-brute"), db);
    ASSERT_TRUE(second.ok()) << second.message();
    EXPECT_EQ(lazy.created(), context) << "a second backend made a second context";
    ASSERT_TRUE(lazy.save_pipeline_cache().ok());
    EXPECT_TRUE(std::filesystem::is_regular_file(vulkan::pipeline_cache_file(*context, dir)));
  }
  // The next run's context merges the saved file without a note.
  LazyContext next(LazyContextOptions{.context = {}, .cache_directory = dir});
  Result<vulkan::Context*> context = next.get();
  ASSERT_TRUE(context.ok()) << context.message();
  EXPECT_TRUE(next.pipeline_cache_note().empty()) << next.pipeline_cache_note();
  std::filesystem::remove_all(dir);
}

TEST(LazyContext, KeepsAFailureAndReportsItAgain) {
  LazyContextOptions options;
  options.context.device_index = 100000;  // no machine has that many devices
  LazyContext lazy(options);
  const Result<vulkan::Context*> first = lazy.get();
  ASSERT_FALSE(first.ok());
  const Result<vulkan::Context*> second = lazy.get();
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(first.message(), second.message());
  EXPECT_EQ(lazy.created(), nullptr);
  // A backend made on it fails with the same message, and saving is a no-op.
  BackendRegistry registry = cpu_backends();
  ASSERT_TRUE(lazy.add_backends(registry, kSmall).ok());
  const Database db = synthetic_database({.frames = 16, .seed = 6});
  Result<std::unique_ptr<SearchBackend>> made = registry.make(small_spec("vulkan-brute"), db);
  ASSERT_FALSE(made.ok());
  EXPECT_NE(made.message().find(first.message()), std::string::npos) << made.message();
  EXPECT_TRUE(lazy.save_pipeline_cache().ok());
}

}  // namespace
}  // namespace mmvk::test
