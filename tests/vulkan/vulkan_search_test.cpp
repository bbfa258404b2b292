// VulkanSearch against ReferenceSearch on cases the shared backend suite
// does not cover: the large-N loop-limit pitfall, every kernel variant
// (K 1/4/16 x tile 1/4/16), chunked batches, async submit/collect,
// timestamps and the validation layer with zero messages.
#include <bit>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <thread>

#include "mmvk/search/reference_search.hpp"
#include "mmvk/vulkan/vulkan_async_search.hpp"
#include "mmvk/vulkan/vulkan_cluster_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

ContextOptions validation_options() {
  ContextOptions options;
  options.validation = true;
  return options;
}

ContextOptions index_options(std::uint32_t index) {
  ContextOptions options;
  options.device_index = index;
  return options;
}

std::unique_ptr<VulkanSearch> make_search(Context& context, const Database& db, const VulkanSearchOptions& options = {}) {
  Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(context, db, options);
  EXPECT_TRUE(search.ok()) << search.message();
  return search.ok() ? std::move(search).value() : nullptr;
}

void compare(SearchBackend& backend, const Database& db, std::span<const float> queries,
             std::span<const QueryParams> params, std::size_t count, std::uint32_t k) {
  ReferenceSearch reference(db);
  expect_identical(run_search(reference, queries, params, count, k), run_search(backend, queries, params, count, k), k,
                   params, backend.name());
}

TEST(VulkanSearch, EveryVariantMatchesReference) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 5000, .seed = 101, .constraints = true});
  std::unique_ptr<VulkanSearch> search = make_search(*context, db);
  ASSERT_NE(search, nullptr);
  for (std::size_t count : {std::size_t{1}, std::size_t{3}, std::size_t{7}, std::size_t{64}, std::size_t{100}}) {
    const std::vector<float> queries = synthetic_queries(db, count, 200 + count);
    const std::vector<QueryParams> params = random_params(db, count, 300 + count);
    for (std::uint32_t k : {1u, 2u, 4u, 5u, 16u}) {
      SCOPED_TRACE("batch " + std::to_string(count) + ", k " + std::to_string(k));
      compare(*search, db, queries, params, count, k);
      compare(*search, db, queries, {}, count, k);
    }
  }
}
// llvmpipe stops a loop after 65,535 iterations and the kernel then returns
// wrong answers silently (shared/LAVAPIPE.md). 16k rows per invocation with
// 16-query tiles and 4 dims: any inner loop left rolled would pass that
// limit, and the large N gives hundreds of thousands of rows in total.
TEST(VulkanSearch, LargeDatabaseStaysExact) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 300000, .clips = 64, .seed = 103, .channel_dims = {2, 2}});
  const std::vector<float> queries = synthetic_queries(db, 64, 104);
  ReferenceSearch reference(db);
  const std::vector<Match> expected = run_search(reference, queries, {}, 64, 1);
  for (std::uint32_t rows : {0u, 16384u}) {
    SCOPED_TRACE("rows_per_invocation " + std::to_string(rows));
    VulkanSearchOptions options = search_options(64, 1);
    options.rows_per_invocation = rows;
    std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
    ASSERT_NE(search, nullptr);
    expect_identical(expected, run_search(*search, queries, {}, 64, 1), 1, {}, search->name());
  }
  // Queries equal to the last rows: a scan cut short would miss them.
  std::vector<float> tail;
  for (std::uint32_t f : {db.frame_count() - 1, db.frame_count() - 2, 150000u, 17u}) {
    tail.insert(tail.end(), db.row(f).begin(), db.row(f).end());
  }
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, search_options(4, 1));
  ASSERT_NE(search, nullptr);
  const std::vector<Match> out = run_search(*search, tail, {}, 4, 1);
  EXPECT_EQ(out[0].frame, db.frame_count() - 1);
  EXPECT_EQ(out[1].frame, db.frame_count() - 2);
  EXPECT_EQ(out[2].frame, 150000u);
  EXPECT_EQ(out[3].frame, 17u);
}

// A workgroup's lanes take its rows in turn, and the feature rows are
// interleaved in groups of 8 (brute_force_scan.comp): frame counts that end
// inside a group and inside a workgroup, with lanes of the last workgroup
// running different row counts, still visit every row exactly once.
TEST(VulkanSearch, InterleavedRowsCoverEveryFrame) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  for (std::uint32_t frames : {1003u, 1009u}) {
    const Database db = synthetic_database({.frames = frames, .seed = 121, .constraints = true});
    std::vector<float> queries = synthetic_queries(db, 28, 122);
    // Queries equal to the first and last rows: a lane that skipped its
    // last or first step would miss them.
    for (std::uint32_t f : {frames - 1, frames - 2, frames - 9, 0u}) {
      queries.insert(queries.end(), db.row(f).begin(), db.row(f).end());
    }
    ReferenceSearch reference(db);
    const std::vector<Match> expected = run_search(reference, queries, {}, 32, 1);
    for (std::uint32_t rows : {1u, 7u, 64u}) {
      SCOPED_TRACE("frames " + std::to_string(frames) + ", rows_per_invocation " + std::to_string(rows));
      VulkanSearchOptions options = search_options(32, 1);
      options.rows_per_invocation = rows;
      std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
      ASSERT_NE(search, nullptr);
      expect_identical(expected, run_search(*search, queries, {}, 32, 1), 1, {}, search->name());
    }
  }
}

// The scan visits only frames no flag excludes (scan_frames); with every
// frame flagged it visits none, and the continuing frames, which the merge
// evaluates on its own, are the only answers.
TEST(VulkanSearch, EveryFrameFlaggedLeavesTheContinuingFrames) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  DatabaseParts parts = synthetic_parts({.frames = 300, .clips = 3, .seed = 123});
  for (std::uint32_t f = 0; f < 300; ++f) parts.frame_flags[f] = f % 2 == 0 ? kFrameBlockTransition : kFrameDoNotUse;
  const Database db = make_database(std::move(parts));
  const std::vector<float> queries = synthetic_queries(db, 4, 124);
  std::vector<QueryParams> params(4);
  params[0].continuing_frame = 10;  // block-transition: a candidate as the continuing frame
  params[2].continuing_frame = 11;  // do-not-use: never a candidate
  ReferenceSearch reference(db);
  const std::vector<Match> expected = run_search(reference, queries, params, 4, 4);
  ASSERT_EQ(expected[0].frame, 10u);
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, search_options(4, 4));
  ASSERT_NE(search, nullptr);
  expect_identical(expected, run_search(*search, queries, params, 4, 4), 4, params, search->name());
}

TEST(VulkanSearch, ChunkedBatchesMatchReference) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 6000, .seed = 105, .constraints = true});
  VulkanSearchOptions options;
  options.max_batch = 200;
  options.scratch_bytes = 1;  // one chunk per query tile or query: many scan/merge pairs
  options.warm_up = false;
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
  ASSERT_NE(search, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 200, 106);
  const std::vector<QueryParams> params = random_params(db, 200, 107);
  compare(*search, db, queries, params, 200, 1);
  compare(*search, db, std::span<const float>(queries).first(37 * db.dims()), std::span(params).first(37), 37, 16);
}

// A batch larger than max_batch x slots is paged inside the search: the
// same matches as the reference, with constraints, for k = 1 and k > 1.
TEST(VulkanSearch, PagesABatchLargerThanItsSlotsWithTheSameResult) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 3000, .seed = 115, .constraints = true});
  VulkanSearchOptions options = search_options(8, 4, 4, false);
  options.slots = 2;  // 37 queries: 5 pages on 2 slots
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
  ASSERT_NE(search, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 37, 116);
  const std::vector<QueryParams> params = random_params(db, 37, 117);
  compare(*search, db, queries, params, 37, 1);
  compare(*search, db, queries, {}, 37, 4);
  EXPECT_EQ(search->stats().queries, 2u * 37u);
}

// The 32-query tile (k = 1, batches of 512 or more), with a partial last
// tile and every constraint.
TEST(VulkanSearch, LargestTileMatchesReference) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 3000, .seed = 109, .constraints = true});
  // No warm-up: only the 32-query variant compiles (seconds on lavapipe).
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, search_options(600, 1, 32, false));
  ASSERT_NE(search, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 600, 110);
  const std::vector<QueryParams> params = random_params(db, 600, 111);
  compare(*search, db, queries, params, 600, 1);
  compare(*search, db, queries, {}, 600, 1);
}

// The one asynchronous interface (AsyncSearch): submit() returns while the
// pages run, a second submit() before collect() is an error, not a block,
// and a blocking search() meanwhile runs on the slots the batch leaves free.
TEST(VulkanSearch, AsyncSubmitCollect) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 4000, .seed = 109, .constraints = true});
  VulkanSearchOptions options;
  options.max_batch = 32;
  options.slots = 3;
  options.max_tile = 4;
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
  ASSERT_NE(search, nullptr);
  ReferenceSearch reference(db);
  const std::vector<float> a = synthetic_queries(db, 64, 110);
  const std::vector<float> b = synthetic_queries(db, 5, 111);
  const std::vector<QueryParams> params = random_params(db, 64, 112);
  vulkan::VulkanAsyncSearch async(*search, 64);

  // Two pages on two of the three slots.
  ASSERT_TRUE(async.submit(QueryBatch{a, params, 64}).ok());
  const Status twice = async.submit(QueryBatch{a, params, 64});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.message().find("in flight"), std::string::npos) << twice.message();
  // The blocking search of k = 3 on the third slot, while the batch runs.
  const std::vector<Match> blocking = run_search(*search, b, {}, 5, 3);
  expect_identical(run_search(reference, b, {}, 5, 3), blocking, 3, {}, "vulkan search beside an async batch");
  std::vector<Match> out_a(64);
  std::vector<Match> wrong_size(63);
  EXPECT_FALSE(async.collect(wrong_size).ok());  // waits the pages out: the slots are free again
  EXPECT_FALSE(async.collect(out_a).ok());       // nothing submitted
  ASSERT_TRUE(async.submit(QueryBatch{a, params, 64}).ok());
  ASSERT_TRUE(async.collect(out_a).ok());
  expect_identical(run_search(reference, a, params, 64, 1), out_a, 1, params, "vulkan async");
  // Over its capacity.
  EXPECT_FALSE(vulkan::VulkanAsyncSearch(*search, 4).submit(QueryBatch{b, {}, 5}).ok());

  // lavapipe's queue has timestamps: the kernel time is measured.
  if (context->timestamp_valid_bits() != 0) {
    ASSERT_TRUE(search->last_kernel_seconds().has_value());
    EXPECT_GT(*search->last_kernel_seconds(), 0.0);
  }
  EXPECT_EQ(search->stats().queries, 64u + 5u + 64u);
}

TEST(VulkanSearch, ErrorsAreReturned) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database db = synthetic_database({.frames = 1000, .seed = 113});
  std::unique_ptr<VulkanSearch> search =
      make_search(*context, db, search_options(8, 4, 4));
  ASSERT_NE(search, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 9, 114);
  std::vector<Match> out(9 * 4);
  // k over max_k.
  Status status = search->search(QueryBatch{std::span<const float>(queries).first(8 * db.dims()), {}, 8}, 5,
                          std::span<Match>(out).first(8 * 5));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("max_k"), std::string::npos) << status.message();
  // Still usable.
  EXPECT_TRUE(search->search(QueryBatch{std::span<const float>(queries).first(8 * db.dims()), {}, 8}, 4,
                             std::span<Match>(out).first(8 * 4))
                  .ok());

  // Options out of range.
  EXPECT_FALSE(VulkanBruteForce::create(*context, db, search_options(0, 1)).ok());
  EXPECT_FALSE(VulkanBruteForce::create(*context, db, search_options(8, 17)).ok());
  EXPECT_FALSE(VulkanBruteForce::create(*context, db, search_options(8, 1, 8)).ok());
  VulkanSearchOptions too_many_rows;
  too_many_rows.rows_per_invocation = 40000;
  EXPECT_FALSE(VulkanBruteForce::create(*context, db, too_many_rows).ok());

  // A cluster table from another database.
  const Database other = synthetic_database({.frames = 1000, .seed = 115});
  ClusterTable table;
  table.database_hash = other.content_hash();
  table.dims = other.dims();
  table.cluster_count = 1;
  table.offsets = {0, other.frame_count()};
  table.members.resize(other.frame_count());
  Result<std::unique_ptr<vulkan::VulkanClusterSearch>> mismatched = vulkan::VulkanClusterSearch::create(*context, db, table);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.message().find("does not belong"), std::string::npos) << mismatched.message();

  // More dims than the kernels support.
  const Database wide = synthetic_database({.frames = 50, .clips = 1, .seed = 116, .channel_dims = {100, 40}});
  Result<std::unique_ptr<VulkanBruteForce>> too_wide = VulkanBruteForce::create(*context, wide);
  ASSERT_FALSE(too_wide.ok());
  EXPECT_NE(too_wide.message().find("128"), std::string::npos) << too_wide.message();
}

// The loader pointed at no driver: Context::create returns an error.
TEST(VulkanContext, NoDriverIsAnError) {
  struct EnvOverride {
    std::string name;
    std::optional<std::string> saved;
    EnvOverride(std::string n, const char* value) : name(std::move(n)) {
      if (const char* old = std::getenv(name.c_str())) saved = old;
      setenv(name.c_str(), value, 1);
    }
    ~EnvOverride() {
      if (saved) {
        setenv(name.c_str(), saved->c_str(), 1);
      } else {
        unsetenv(name.c_str());
      }
    }
  };
  const std::string missing = (make_temp_dir() / "no_such_icd.json").string();
  EnvOverride driver_files("VK_DRIVER_FILES", missing.c_str());
  EnvOverride icd_filenames("VK_ICD_FILENAMES", missing.c_str());
  Result<std::unique_ptr<Context>> context = Context::create();
  ASSERT_FALSE(context.ok());
  EXPECT_NE(context.message().find("no Vulkan"), std::string::npos) << context.message();
}

TEST(VulkanContext, ExplicitIndexAndAdoption) {
  MMVK_VULKAN_CONTEXT(owner, ContextOptions{});
  Result<std::vector<vulkan::DeviceInfo>> devices = Context::enumerate_devices();
  ASSERT_TRUE(devices.ok()) << devices.message();
  ASSERT_FALSE(devices->empty());
  EXPECT_FALSE(Context::create(index_options(static_cast<std::uint32_t>(devices->size()))).ok());
  Result<std::unique_ptr<Context>> first = Context::create(index_options(0));
  ASSERT_TRUE(first.ok()) << first.message();
  EXPECT_NE((*first)->description().find("(Vulkan device 0, "), std::string::npos) << (*first)->description();

  // A second Context on the application's own handles; it destroys none.
  const Database db = synthetic_database({.frames = 2000, .seed = 117});
  const std::vector<float> queries = synthetic_queries(db, 6, 118);
  for (int round = 0; round < 2; ++round) {
    Result<std::unique_ptr<Context>> adopted = Context::adopt(vulkan::AdoptedDevice{
        owner->instance(), owner->physical_device(), owner->device(), owner->queue_family(), owner->queue()});
    ASSERT_TRUE(adopted.ok()) << adopted.message();
    EXPECT_FALSE((*adopted)->owns_device());
    // An adopted device is described as the one it is, with its index.
    EXPECT_EQ((*adopted)->description(), owner->description());
    std::unique_ptr<VulkanSearch> search =
        make_search(**adopted, db, search_options(6, 2, 16, false));
    ASSERT_NE(search, nullptr);
    compare(*search, db, queries, {}, 6, 2);
  }
  EXPECT_FALSE(Context::adopt(vulkan::AdoptedDevice{}).ok());
}

// The validation layer is really on: a deliberate misuse is reported, and
// a full search reports nothing.
TEST(VulkanContext, ValidationCollectsMessages) {
  MMVK_VULKAN_CONTEXT(context, validation_options());
  const Database db = synthetic_database({.frames = 3000, .seed = 119, .constraints = true});
  // The staging upload (discrete GPUs' path) under synchronization validation.
  VulkanSearchOptions options = search_options(16, 16, 4);
  options.force_staging_upload = true;
  std::unique_ptr<VulkanSearch> search = make_search(*context, db, options);
  ASSERT_NE(search, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 16, 120);
  compare(*search, db, queries, random_params(db, 16, 121), 16, 5);
  search.reset();
  EXPECT_EQ(context->validation_message_count(), 0u)
      << (context->validation_messages().empty() ? "" : context->validation_messages().front());

  VkBufferCreateInfo bad{};
  bad.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bad.size = 0;  // invalid: size must be > 0
  bad.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  if (vkCreateBuffer(context->device(), &bad, nullptr, &buffer) == VK_SUCCESS && buffer != VK_NULL_HANDLE) {
    vkDestroyBuffer(context->device(), buffer, nullptr);
  }
  EXPECT_GT(context->validation_message_count(), 0u);
}

}  // namespace
}  // namespace mmvk::test
