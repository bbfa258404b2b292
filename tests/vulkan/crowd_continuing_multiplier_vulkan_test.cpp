// The crowd controller's continuing_multiplier on Vulkan (lavapipe in CI)
// against the reference on Bandai locomotion: identical chosen frames every
// tick, and fewer jumps than without it (it favours the playing frame);
// a negative multiplier is refused.
#include <gtest/gtest.h>

#include "mmvk/reference_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/crowd_scenario.hpp"
#include "support/test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk {
namespace {

test::CrowdRun run_with(const Database& db, SearchBackend& backend, float continuing_multiplier) {
  ThreadPool pool(2);
  ControllerParams params;
  params.continuing_multiplier = continuing_multiplier;
  Result<CrowdController> controller = CrowdController::create(db, test::kCrowdCharacters, params);
  EXPECT_TRUE(controller.ok()) << controller.message();
  Result<test::CrowdRun> run = test::run_crowd(
      *controller, [&](CrowdController& c, const CrowdInput& in) { return c.tick(test::kCrowdDt, in, backend, pool); });
  EXPECT_TRUE(run.ok()) << run.message();
  return std::move(run).value();
}

TEST(CrowdContinuingMultiplierVulkan, SameFramesAsTheReferenceAndFewerJumps) {
  MMVK_REQUIRE_DATA_DIR(dir);
  MMVK_VULKAN_CONTEXT(context, {});
  Result<Database> db = test::build_locomotion(dir);
  ASSERT_TRUE(db.ok()) << db.message();
  ReferenceSearch reference(*db);
  vulkan::VulkanSearchOptions options;
  options.max_k = 1;
  options.max_batch = 64;
  Result<std::unique_ptr<vulkan::VulkanSearch>> gpu = vulkan::VulkanSearch::create(*context, *db, options);
  ASSERT_TRUE(gpu.ok()) << gpu.message();

  const test::CrowdRun plain = run_with(*db, reference, 1.0f);
  const test::CrowdRun expected = run_with(*db, reference, 0.6f);
  const test::CrowdRun actual = run_with(*db, **gpu, 0.6f);
  EXPECT_EQ(actual.totals.no_candidate, 0u);
  EXPECT_TRUE(expected.frames == actual.frames);
  EXPECT_EQ(expected.totals.jumps, actual.totals.jumps);
  std::printf("jumps over the run: %u with continuing_multiplier 1, %u with 0.6\n", plain.totals.jumps,
              expected.totals.jumps);
  EXPECT_LT(expected.totals.jumps, plain.totals.jumps);

  ControllerParams bad;
  bad.continuing_multiplier = -1.0f;
  Result<CrowdController> refused = CrowdController::create(*db, 4, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(), "crowd controller: continuing_multiplier must be finite and >= 0");
}

}  // namespace
}  // namespace mmvk
