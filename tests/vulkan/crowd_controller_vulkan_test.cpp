// The crowd controller on Vulkan (lavapipe in CI) against the reference
// backend on Bandai locomotion: 50 characters, 2 s at 30 Hz, identical
// chosen frames every tick, synchronously and on the deferred (async) path,
// with batches split over more chunks than the search has slots; and with a
// continuing_multiplier (fewer jumps, the same frames on both).
#include <gtest/gtest.h>

#include "mmvk/search/reference_search.hpp"
#include "mmvk/vulkan/vulkan_async_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/crowd_scenario.hpp"
#include "support/test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk {
namespace {

test::CrowdRun run_sync(const Database& db, SearchBackend& backend, const ControllerParams& params = {}) {
  ThreadPool pool(2);
  Result<CrowdController> controller = CrowdController::create(db, test::kCrowdCharacters, params);
  EXPECT_TRUE(controller.ok()) << controller.message();
  Result<test::CrowdRun> run = test::run_crowd(
      *controller, [&](CrowdController& c, const CrowdInput& in) { return c.tick(test::kCrowdDt, in, backend, pool); });
  EXPECT_TRUE(run.ok()) << run.message();
  return std::move(run).value();
}

test::CrowdRun run_deferred(const Database& db, AsyncSearch& search) {
  ThreadPool pool(2);
  Result<CrowdController> controller = CrowdController::create(db, test::kCrowdCharacters);
  EXPECT_TRUE(controller.ok()) << controller.message();
  Result<test::CrowdRun> run = test::run_crowd(
      *controller, [&](CrowdController& c, const CrowdInput& in) { return c.tick(test::kCrowdDt, in, search, pool); });
  EXPECT_TRUE(run.ok()) << run.message();
  return std::move(run).value();
}

// The first tick where two runs chose differently, for the failure message.
std::string first_difference(const test::CrowdRun& a, const test::CrowdRun& b) {
  for (std::size_t i = 0; i < std::min(a.frames.size(), b.frames.size()); ++i) {
    if (a.frames[i] != b.frames[i]) {
      return "tick " + std::to_string(i / test::kCrowdCharacters) + ", character " +
             std::to_string(i % test::kCrowdCharacters) + ": " + std::to_string(a.frames[i]) + " vs " +
             std::to_string(b.frames[i]);
    }
  }
  return "sizes differ";
}

TEST(CrowdControllerVulkan, SameFramesAsTheReferenceEveryTick) {
  MMVK_REQUIRE_DATA_DIR(dir);
  MMVK_VULKAN_CONTEXT(context, {});
  Result<Database> db = test::build_locomotion(dir);
  ASSERT_TRUE(db.ok()) << db.message();
  ReferenceSearch reference(*db);
  vulkan::VulkanSearchOptions options;
  options.max_k = 1;
  options.max_batch = 16;  // the first tick's 50 forced searches: 4 pages on 2 slots
  Result<std::unique_ptr<vulkan::VulkanBruteForce>> gpu = vulkan::VulkanBruteForce::create(*context, *db, options);
  ASSERT_TRUE(gpu.ok()) << gpu.message();

  const test::CrowdRun expected = run_sync(*db, reference);
  const test::CrowdRun actual = run_sync(*db, **gpu);
  EXPECT_EQ(expected.totals.no_candidate, 0u);
  EXPECT_EQ(actual.totals.no_candidate, 0u);
  EXPECT_GT(actual.totals.jumps, 50u);
  EXPECT_TRUE(expected.frames == actual.frames) << first_difference(expected, actual);
  EXPECT_EQ(expected.searched, actual.searched);

  // The deferred path: the GPU search overlaps the next tick.
  DeferredSearch later(reference, test::kCrowdCharacters);
  vulkan::VulkanAsyncSearch async(**gpu, test::kCrowdCharacters);
  const test::CrowdRun expected_deferred = run_deferred(*db, later);
  const test::CrowdRun actual_deferred = run_deferred(*db, async);
  EXPECT_EQ(actual_deferred.totals.no_candidate, 0u);
  EXPECT_TRUE(expected_deferred.frames == actual_deferred.frames) << first_difference(expected_deferred, actual_deferred);

  // A continuing_multiplier below 1 favours the playing frame: the same
  // frames on both backends, fewer jumps than without it.
  ControllerParams favour;
  favour.continuing_multiplier = 0.6f;
  const test::CrowdRun favoured = run_sync(*db, reference, favour);
  const test::CrowdRun favoured_gpu = run_sync(*db, **gpu, favour);
  EXPECT_EQ(favoured_gpu.totals.no_candidate, 0u);
  EXPECT_TRUE(favoured.frames == favoured_gpu.frames) << first_difference(favoured, favoured_gpu);
  std::printf("jumps over the run: %u with continuing_multiplier 1, %u with 0.6\n", expected.totals.jumps,
              favoured.totals.jumps);
  EXPECT_LT(favoured.totals.jumps, expected.totals.jumps);
  favour.continuing_multiplier = -1.0f;
  Result<CrowdController> refused = CrowdController::create(*db, 4, favour);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(), "crowd controller: continuing_multiplier must be finite and >= 0");
}

}  // namespace
}  // namespace mmvk
