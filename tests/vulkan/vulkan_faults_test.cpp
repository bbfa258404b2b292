// Faults on the device (issue 13): a database or a batch too large for the
// device, and device loss, end in errors that name the limit and the sizes
// (or say the device was lost and what to do), and the objects stay safe
// to use and to destroy. The limits are lowered through
// ContextOptions::limit_caps; device loss, which lavapipe never reports, is
// injected at the Context's checked submit and wait calls
// (Context::inject_fault).
#include <memory>
#include <string>
#include <vector>

#include "mmvk/search/reference_search.hpp"
#include "mmvk/vulkan/vulkan_async_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/search_test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

ContextOptions capped(std::uint32_t storage_range, std::uint32_t texels, VkDeviceSize heap) {
  ContextOptions options;
  options.validation = true;
  options.limit_caps.max_storage_buffer_range = storage_range;
  options.limit_caps.max_texel_buffer_elements = texels;
  options.limit_caps.heap_bytes = heap;
  return options;
}

VulkanSearchOptions small_options(std::uint32_t max_batch = 64) {
  VulkanSearchOptions options;
  options.max_batch = max_batch;
  options.max_k = 4;
  options.max_tile = 4;
  options.warm_up = false;
  return options;
}

// ---------------------------------------------------------------------------
// Too large for the device

TEST(VulkanLimits, BatchOverMaxStorageBufferRangeNamesTheLimit) {
  // 27 dims = 7 vec4s = 112 bytes per query: 1024 queries need 114688 bytes.
  MMVK_VULKAN_CONTEXT(context, capped(65536, 0, 0));
  const Database db = synthetic_database({.frames = 500, .clips = 2});
  const Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, small_options(1024));
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), "the query buffer for max_batch = 1024 queries needs 114688 bytes"))
      << search.message();
  EXPECT_TRUE(contains(search.message(), "maxStorageBufferRange of 65536 bytes")) << search.message();
  EXPECT_TRUE(contains(search.message(), "lower max_batch to at most 585")) << search.message();
  // The advice is right: 585 queries fit.
  const Result<std::unique_ptr<VulkanBruteForce>> fits = VulkanBruteForce::create(*context, db, small_options(585));
  ASSERT_TRUE(fits.ok()) << fits.message();
  // ... and search right, in scratch chunks under the lowered range.
  const std::vector<float> queries = synthetic_queries(db, 585, 3);
  std::vector<Match> out(585 * 4), expected(585 * 4);
  ASSERT_TRUE((*fits)->search(QueryBatch{queries, {}, 585}, 4, out).ok());
  ASSERT_TRUE(ReferenceSearch(db).search(QueryBatch{queries, {}, 585}, 4, expected).ok());
  EXPECT_EQ(out, expected);
  EXPECT_EQ(context->validation_message_count(), 0u);
}

TEST(VulkanLimits, BatchOverLavapipesOwnStorageRangeNamesTheLimit) {
  // No cap: 2^20 queries of 128 dims need 512 MiB per query buffer, over
  // lavapipe's 128 MiB (and most GPUs' 2 or 4 GiB at kMaxBatch is fine,
  // so only check the message where the device's own limit is below).
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 300, .clips = 2, .channel_dims = {64, 64}});
  const std::uint64_t needed = std::uint64_t{kMaxBatch} * 32 * 16;
  if (needed <= context->properties().limits.maxStorageBufferRange) GTEST_SKIP() << "the device's range is larger";
  const Result<std::unique_ptr<VulkanBruteForce>> search =
      VulkanBruteForce::create(*context, db, small_options(static_cast<std::uint32_t>(kMaxBatch)));
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), std::to_string(needed) + " bytes, over the device's maxStorageBufferRange"))
      << search.message();
}

TEST(VulkanLimits, DatabaseOverMaxTexelBufferElementsNamesTheLimit) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 1000, 0));
  const Database db = synthetic_database({.frames = 500, .clips = 2});  // 504 (groups of 8) x 7 = 3528 texels
  const Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, small_options());
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), "500 frames, 504 in groups of 8, x 7 texels) needs 3528 texels")) << search.message();
  EXPECT_TRUE(contains(search.message(), "maxTexelBufferElements of 1000")) << search.message();
}

TEST(VulkanLimits, DatabaseOverTheDeviceHeapNamesTheHeap) {
  // 500 frames: 504 (groups of 8) x 7 x 16 + 500 x 16 + 500 x 8 + 500 x 20 (the
  // scanned frames and their terms) = 78448 bytes.
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 65536));
  const Database db = synthetic_database({.frames = 500, .clips = 2});
  const Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, small_options());
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), "the database (500 frames x 27 dims) needs 78448 bytes of device memory"))
      << search.message();
  EXPECT_TRUE(contains(search.message(), "more than the 65536 bytes of memory heap")) << search.message();
}

TEST(VulkanLimits, SlotsOverTheHostVisibleHeapNameTheSlots) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 1 << 20));
  const Database db = synthetic_database({.frames = 500, .clips = 2});
  VulkanSearchOptions options = small_options(1024);
  options.scratch_bytes = 1 << 20;
  const Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, options);
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), "2 submission slots of max_batch = 1024 queries needs")) << search.message();
}

TEST(VulkanLimits, MaxBatchOverKMaxBatchIsAnError) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 100, .clips = 2});
  const Result<std::unique_ptr<VulkanBruteForce>> search =
      VulkanBruteForce::create(*context, db, small_options(0xFFFFFFFFu));
  ASSERT_FALSE(search.ok());
  EXPECT_TRUE(contains(search.message(), "max_batch = 4294967295 is out of range [1, 1048576]")) << search.message();
}

// ---------------------------------------------------------------------------
// Device loss (injected: lavapipe has no device to lose)

// A small database, 8 queries and a search on it (k <= 4, 2 slots).
struct Fixture {
  Database db = synthetic_database({.frames = 600, .clips = 3, .seed = 5});
  std::vector<float> queries = synthetic_queries(db, 8, 9);
  std::vector<Match> out = std::vector<Match>(8 * 4);
  std::unique_ptr<VulkanSearch> search;

  explicit Fixture(Context& context) {
    Result<std::unique_ptr<VulkanBruteForce>> made = VulkanBruteForce::create(context, db, small_options());
    EXPECT_TRUE(made.ok()) << made.message();
    if (made.ok()) search = std::move(made).value();
  }
  QueryBatch batch() const { return QueryBatch{queries, {}, 8}; }
};

void expect_lost(const std::string& message, const std::string& call) {
  EXPECT_TRUE(contains(message, "was lost (VK_ERROR_DEVICE_LOST from " + call)) << message;
  EXPECT_TRUE(contains(message, "create new ones")) << message;
}

TEST(VulkanDeviceLoss, LostAtSubmitIsAnErrorAndTheSearchStaysSafe) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 0));
  Fixture f(*context);
  ASSERT_TRUE(f.search);
  ASSERT_TRUE(f.search->search(f.batch(), 4, f.out).ok());

  context->inject_fault("vkQueueSubmit", VK_ERROR_DEVICE_LOST);
  const Status lost = f.search->search(f.batch(), 4, f.out);
  ASSERT_FALSE(lost.ok());
  expect_lost(lost.message(), "vkQueueSubmit");
  EXPECT_TRUE(context->device_lost());
  // Every later use fails the same way, at once; nothing crashes.
  for (int i = 0; i < 3; ++i) {
    const Status again = f.search->search(f.batch(), 4, f.out);
    ASSERT_FALSE(again.ok());
    expect_lost(again.message(), "vkQueueSubmit");
  }
  const Result<std::unique_ptr<VulkanBruteForce>> another = VulkanBruteForce::create(*context, f.db, small_options());
  ASSERT_FALSE(another.ok());
  expect_lost(another.message(), "vkQueueSubmit");
  f.search.reset();  // destroys cleanly
  EXPECT_EQ(context->validation_message_count(), 0u);
}

// Two pages in flight on the two slots (8 queries, pages of 4): the wait
// of the first reports the loss; the second ran on the lost device, so it
// is waited out without results; both slots are free again, and every
// later use says lost (not "all slots in flight").
TEST(VulkanDeviceLoss, LostWhileWaitingFreesEverySlotOfTheBatch) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 0));
  Fixture f(*context);
  ASSERT_TRUE(f.search);
  Result<std::unique_ptr<VulkanBruteForce>> paged = VulkanBruteForce::create(*context, f.db, small_options(4));
  ASSERT_TRUE(paged.ok()) << paged.message();
  vulkan::VulkanAsyncSearch async(**paged, 8);
  std::vector<Match> out(8);
  ASSERT_TRUE(async.submit(f.batch()).ok());
  context->inject_fault("vkWaitForFences", VK_ERROR_DEVICE_LOST);
  const Status waited = async.collect(out);
  ASSERT_FALSE(waited.ok());
  expect_lost(waited.message(), "vkWaitForFences");
  const Status next = async.submit(f.batch());
  ASSERT_FALSE(next.ok());
  expect_lost(next.message(), "vkWaitForFences");
  // Another search on the same device fails the same way.
  const Status other = f.search->search(f.batch(), 4, f.out);
  ASSERT_FALSE(other.ok());
  expect_lost(other.message(), "vkWaitForFences");
  EXPECT_EQ(context->validation_message_count(), 0u);
}

TEST(VulkanDeviceLoss, OtherInjectedFaultsAreErrorsAndTheSearchRecovers) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 0));
  Fixture f(*context);
  ASSERT_TRUE(f.search);
  context->inject_fault("vkQueueSubmit", VK_ERROR_OUT_OF_DEVICE_MEMORY);
  const Status failed = f.search->search(f.batch(), 4, f.out);
  ASSERT_FALSE(failed.ok());
  EXPECT_TRUE(contains(failed.message(), "VK_ERROR_OUT_OF_DEVICE_MEMORY")) << failed.message();
  EXPECT_FALSE(context->device_lost());
  // Not a loss: the next search works and matches the reference.
  ASSERT_TRUE(f.search->search(f.batch(), 4, f.out).ok());
  ReferenceSearch reference(f.db);
  std::vector<Match> expected(8 * 4);
  ASSERT_TRUE(reference.search(f.batch(), 4, expected).ok());
  EXPECT_EQ(f.out, expected);
  EXPECT_EQ(context->validation_message_count(), 0u);
}

// The crowd's asynchronous search: a failed chunk submit in collect() used
// to leave the chunks already in flight holding their slots, so every
// later tick failed with "all submission slots are in flight".
TEST(VulkanDeviceLoss, AsyncSearchFreesItsSlotsAfterAFailedChunk) {
  MMVK_VULKAN_CONTEXT(context, capped(0, 0, 0));
  const Database db = synthetic_database({.frames = 600, .clips = 3, .seed = 6});
  VulkanSearchOptions options = small_options(8);  // 32 queries = 4 chunks on 2 slots
  Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, options);
  ASSERT_TRUE(search.ok()) << search.message();
  vulkan::VulkanAsyncSearch async(**search, 32);
  const std::vector<float> queries = synthetic_queries(db, 32, 4);
  const QueryBatch batch{queries, {}, 32};
  std::vector<Match> out(32), expected(32);
  ASSERT_TRUE(async.submit(batch).ok());
  context->inject_fault("vkQueueSubmit", VK_ERROR_OUT_OF_HOST_MEMORY);  // the third chunk's
  const Status failed = async.collect(out);
  ASSERT_FALSE(failed.ok());
  EXPECT_TRUE(contains(failed.message(), "VK_ERROR_OUT_OF_HOST_MEMORY")) << failed.message();
  // The next tick runs as if nothing happened.
  ASSERT_TRUE(async.submit(batch).ok());
  const Status collected = async.collect(out);
  ASSERT_TRUE(collected.ok()) << collected.message();
  ASSERT_TRUE(ReferenceSearch(db).search(batch, 1, expected).ok());
  EXPECT_EQ(out, expected);
  EXPECT_EQ(context->validation_message_count(), 0u);
}

}  // namespace
}  // namespace mmvk::test
