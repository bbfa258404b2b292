// The application-owned pipeline cache (Context) and VulkanSearch::warm_up():
// a blob round-trips through a second Context, foreign or garbage blobs are
// ignored with a note (never an error), an adopted VkPipelineCache is used,
// and searches after warm_up() match the reference.
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <vector>

#include "mmvk/search/reference_search.hpp"
#include "mmvk/vulkan/pipeline_cache_file.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/device_nodes.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

// Small variants (tile <= 4, k <= 4) so the kernels compile quickly.
VulkanSearchOptions small_options(bool warm_up) { return search_options(16, 4, 4, warm_up); }

ContextOptions with_blob(std::vector<std::byte> blob) {
  ContextOptions options;
  options.pipeline_cache_data = std::move(blob);
  return options;
}

const Database& test_database() {
  static const Database db = synthetic_database({.frames = 3000, .seed = 77, .constraints = true});
  return db;
}

// Searches with `context` (warm_up at creation) and checks it against the
// reference on a few batches.
void expect_search_matches(Context& context, bool call_warm_up) {
  const Database& db = test_database();
  Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(context, db, small_options(!call_warm_up));
  ASSERT_TRUE(search.ok()) << search.message();
  if (call_warm_up) {
    ASSERT_TRUE((*search)->warm_up().ok());
    EXPECT_EQ((*search)->stats().queries, 0u) << "warm_up() counted its own dispatches";
  }
  ReferenceSearch reference(db);
  for (const std::size_t count : {std::size_t{1}, std::size_t{5}, std::size_t{16}}) {
    const std::vector<float> queries = synthetic_queries(db, count, 500 + count);
    const std::vector<QueryParams> params = random_params(db, count, 600 + count);
    for (const std::uint32_t k : {1u, 4u}) {
      SCOPED_TRACE("batch " + std::to_string(count) + ", k " + std::to_string(k));
      expect_identical(run_search(reference, queries, params, count, k), run_search(**search, queries, params, count, k),
                       k, params, (*search)->name());
    }
  }
}

// A further Context in a test whose first came from MMVK_VULKAN_CONTEXT
// (which skips or fails when there is no device).
std::unique_ptr<Context> another_context(const ContextOptions& options) {
  Result<std::unique_ptr<Context>> context = Context::create(options);
  EXPECT_TRUE(context.ok()) << context.message();
  return context.ok() ? std::move(context).value() : nullptr;
}

std::vector<std::byte> blob_after_search(Context& context) {
  Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(context, test_database(), small_options(true));
  EXPECT_TRUE(search.ok()) << search.message();
  Result<std::vector<std::byte>> blob = context.pipeline_cache_data();
  EXPECT_TRUE(blob.ok()) << blob.message();
  return blob.ok() ? *blob : std::vector<std::byte>{};
}

TEST(PipelineCache, BlobRoundTripsThroughANewContext) {
  MMVK_VULKAN_CONTEXT(first, ContextOptions{});
  EXPECT_TRUE(first->pipeline_cache_note().empty());
  const std::vector<std::byte> blob = blob_after_search(*first);
  // At least the VkPipelineCacheHeaderVersionOne header (32 bytes); what
  // follows is the driver's (lavapipe stores no pipelines in it).
  ASSERT_GE(blob.size(), 32u);
  first.reset();

  std::unique_ptr<Context> second = another_context(with_blob(blob));
  ASSERT_NE(second, nullptr);
  EXPECT_TRUE(second->pipeline_cache_note().empty()) << second->pipeline_cache_note();
  expect_search_matches(*second, false);
  Result<std::vector<std::byte>> again = second->pipeline_cache_data();
  ASSERT_TRUE(again.ok()) << again.message();
  EXPECT_GE(again->size(), 32u);
  // The blob of a context started from a blob is accepted in turn.
  std::unique_ptr<Context> third = another_context(with_blob(*again));
  ASSERT_NE(third, nullptr);
  EXPECT_TRUE(third->pipeline_cache_note().empty()) << third->pipeline_cache_note();
}

TEST(PipelineCache, GarbageBlobIsIgnoredWithANote) {
  std::vector<std::byte> garbage(4096);
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = std::byte((i * 37 + 11) & 0xFF);
  MMVK_VULKAN_CONTEXT(context, with_blob(garbage));
  EXPECT_FALSE(context->pipeline_cache_note().empty());
  expect_search_matches(*context, false);
}

TEST(PipelineCache, TruncatedBlobIsIgnoredWithANote) {
  MMVK_VULKAN_CONTEXT(context, with_blob(std::vector<std::byte>(7, std::byte{1})));
  EXPECT_NE(context->pipeline_cache_note().find("header"), std::string::npos) << context->pipeline_cache_note();
  Result<std::vector<std::byte>> blob = context->pipeline_cache_data();
  ASSERT_TRUE(blob.ok()) << blob.message();
}

TEST(PipelineCache, BlobOfAnotherDriverBuildIsIgnoredWithANote) {
  MMVK_VULKAN_CONTEXT(first, ContextOptions{});
  std::vector<std::byte> blob = blob_after_search(*first);
  ASSERT_GE(blob.size(), 32u);
  blob[20] ^= std::byte{0x5A};  // inside pipelineCacheUUID (bytes 16..31)
  first.reset();
  std::unique_ptr<Context> context = another_context(with_blob(blob));
  ASSERT_NE(context, nullptr);
  EXPECT_NE(context->pipeline_cache_note().find("driver build"), std::string::npos) << context->pipeline_cache_note();
  expect_search_matches(*context, false);
}

TEST(PipelineCache, AdoptedCacheIsUsedAndKept) {
  MMVK_VULKAN_CONTEXT(owner, ContextOptions{});
  vulkan::AdoptedDevice handles;
  handles.instance = owner->instance();
  handles.physical_device = owner->physical_device();
  handles.device = owner->device();
  handles.queue_family = owner->queue_family();
  handles.queue = owner->queue();
  {
    Result<std::unique_ptr<Context>> adopted = Context::adopt(handles, owner->pipeline_cache());
    ASSERT_TRUE(adopted.ok()) << adopted.message();
    EXPECT_EQ((*adopted)->pipeline_cache(), owner->pipeline_cache());
    expect_search_matches(**adopted, true);
  }
  // The adopting Context did not destroy the application's cache.
  Result<std::vector<std::byte>> blob = owner->pipeline_cache_data();
  ASSERT_TRUE(blob.ok()) << blob.message();
  EXPECT_GE(blob->size(), 32u);
}

TEST(PipelineCache, WarmUpThenSearchMatchesReference) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  expect_search_matches(*context, true);
}

TEST(PipelineCache, WarmUpKeepsTheCallersStatistics) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const Database& db = test_database();
  Result<std::unique_ptr<VulkanBruteForce>> search = VulkanBruteForce::create(*context, db, small_options(false));
  ASSERT_TRUE(search.ok()) << search.message();
  const std::vector<float> queries = synthetic_queries(db, 3, 9);
  std::vector<Match> out(3);
  ASSERT_TRUE((*search)->search(QueryBatch{queries, {}, 3}, 1, out).ok());
  const SearchStats before = (*search)->stats();
  ASSERT_TRUE((*search)->warm_up().ok());
  EXPECT_EQ((*search)->stats().queries, before.queries);
  EXPECT_EQ((*search)->stats().rows_evaluated, before.rows_evaluated);
}

// A fresh directory per test under the build's temp dir.
std::filesystem::path fresh_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("mmvk_pipeline_cache_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(PipelineCacheFile, EncodeDecodeRoundTripAndDamageIsDetected) {
  std::vector<std::byte> blob(100);
  for (std::size_t i = 0; i < blob.size(); ++i) blob[i] = std::byte(i * 7);
  const std::string file = vulkan::encode_pipeline_cache_file(blob);
  Result<std::vector<std::byte>> decoded = vulkan::decode_pipeline_cache_file(file);
  ASSERT_TRUE(decoded.ok()) << decoded.message();
  EXPECT_EQ(*decoded, blob);
  EXPECT_FALSE(vulkan::decode_pipeline_cache_file(file.substr(0, file.size() - 1)).ok());
  EXPECT_FALSE(vulkan::decode_pipeline_cache_file(file.substr(0, 10)).ok());
  std::string flipped = file;
  flipped[file.size() - 3] ^= 0x10;
  EXPECT_NE(vulkan::decode_pipeline_cache_file(flipped).message().find("checksum"), std::string::npos);
  std::string magic = file;
  magic[0] = 'X';
  EXPECT_FALSE(vulkan::decode_pipeline_cache_file(magic).ok());
  EXPECT_TRUE(vulkan::decode_pipeline_cache_file(vulkan::encode_pipeline_cache_file({})).ok());
}

TEST(PipelineCacheFile, SaveThenLoadInANewContext) {
  MMVK_VULKAN_CONTEXT(first, ContextOptions{});
  const std::filesystem::path dir = fresh_directory("round_trip") / "nested";
  EXPECT_EQ(vulkan::load_pipeline_cache_file(*first, dir), "") << "a missing file is the first run, not a problem";
  (void)blob_after_search(*first);
  const Status saved = vulkan::save_pipeline_cache_file(*first, dir);
  ASSERT_TRUE(saved.ok()) << saved.message();
  const std::filesystem::path file = vulkan::pipeline_cache_file(*first, dir);
  EXPECT_EQ(file.parent_path(), dir);
  ASSERT_TRUE(std::filesystem::exists(file));
  first.reset();

  std::unique_ptr<Context> second = another_context(ContextOptions{});
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(vulkan::load_pipeline_cache_file(*second, dir), "");
  expect_search_matches(*second, true);
  EXPECT_TRUE(vulkan::save_pipeline_cache_file(*second, dir).ok());
  std::filesystem::remove_all(dir.parent_path());
}

TEST(PipelineCacheFile, GarbageFileIsIgnoredWithANote) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const std::filesystem::path dir = fresh_directory("garbage");
  std::filesystem::create_directories(dir);
  std::ofstream(vulkan::pipeline_cache_file(*context, dir), std::ios::binary) << "not a pipeline cache at all";
  const std::string note = vulkan::load_pipeline_cache_file(*context, dir);
  EXPECT_NE(note.find("ignored"), std::string::npos) << note;
  expect_search_matches(*context, false);
  // The next save replaces it with a good file.
  ASSERT_TRUE(vulkan::save_pipeline_cache_file(*context, dir).ok());
  EXPECT_EQ(vulkan::load_pipeline_cache_file(*context, dir), "");
  std::filesystem::remove_all(dir);
}

// Issue 23: a pipeline cache file that is a symlink to an endless device or
// a FIFO is refused at once (not read up to 4 GiB, not blocked on), and the
// next save replaces the link with a regular file, never writing through it.
// The device is a private node made with mknod (skipped where refused).
TEST(PipelineCacheFile, NonRegularFilesAreIgnoredAndReplaced) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  const std::filesystem::path dir = fresh_directory("non-regular");
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = vulkan::pipeline_cache_file(*context, dir);
  ASSERT_TRUE(make_fifo(dir / "fifo"));
  std::vector<std::pair<std::filesystem::path, std::string>> targets = {{dir / "fifo", "FIFO"}};
  if (make_device_node(dir / "zero", MemoryDevice::Zero)) targets.push_back({dir / "zero", "character device"});
  for (const auto& [target, kind] : targets) {
    std::filesystem::remove(file);
    std::filesystem::create_symlink(target, file);
    const std::string note = vulkan::load_pipeline_cache_file(*context, dir);
    EXPECT_NE(note.find(kind), std::string::npos) << note;
    EXPECT_NE(note.find("starts empty"), std::string::npos) << note;
    ASSERT_TRUE(vulkan::save_pipeline_cache_file(*context, dir).ok());
    EXPECT_EQ(file_type(file), "regular");
    EXPECT_NE(file_type(target), "regular");
    EXPECT_EQ(vulkan::load_pipeline_cache_file(*context, dir), "");
  }
  std::filesystem::remove_all(dir);
}

TEST(PipelineCacheFile, FileOfAnotherDriverBuildIsIgnoredWithANote) {
  MMVK_VULKAN_CONTEXT(context, ContextOptions{});
  std::vector<std::byte> blob = blob_after_search(*context);
  ASSERT_GE(blob.size(), 32u);
  blob[17] ^= std::byte{1};
  const std::filesystem::path dir = fresh_directory("foreign");
  std::filesystem::create_directories(dir);
  std::ofstream(vulkan::pipeline_cache_file(*context, dir), std::ios::binary)
      << vulkan::encode_pipeline_cache_file(blob);
  EXPECT_NE(vulkan::load_pipeline_cache_file(*context, dir).find("driver build"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mmvk::test
