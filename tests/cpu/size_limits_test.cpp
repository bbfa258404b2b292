// Sizes a caller could get wrong by orders of magnitude (issue 13): a batch,
// a k, a file. Each is checked up front against a documented limit
// (kMaxBatch, kMaxK, kMaxFileBytes; docs/search.md) and ends in an error
// naming it, before any allocation of that size or any size product that
// could wrap around.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mmvk/search/backends.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/search/reference_search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// batch.size * dims and batch.size * k wrap to 0 for this size (2^62 x 4
// dims, x 4 results), so before the kMaxBatch check empty spans passed the
// size checks and the search walked 2^62 queries off the end of them.
TEST(SizeLimits, BatchWhoseSizeProductsWrapIsAnError) {
  const Database db = test::synthetic_database({.frames = 64, .clips = 2, .channel_dims = {4}});
  ASSERT_EQ(db.dims(), 4u);
  const std::size_t huge = std::size_t{1} << 62;
  ThreadPool pool(1);
  const BackendRegistry registry = cpu_backends();
  for (const std::string name : {"reference", "fast-brute", "fast-box"}) {
    BackendSpec spec;
    spec.name = name;
    spec.pool = &pool;
    Result<std::unique_ptr<SearchBackend>> backend = registry.make(spec, db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    const Status status = (*backend)->search(QueryBatch{{}, {}, huge}, 4, std::span<Match>());
    ASSERT_FALSE(status.ok()) << name;
    EXPECT_TRUE(contains(status.message(), std::to_string(huge) + " queries")) << status.message();
    EXPECT_TRUE(contains(status.message(), "kMaxBatch")) << status.message();
  }
}

TEST(SizeLimits, BatchJustOverTheLimitIsAnErrorAndAtTheLimitIsNot) {
  const Database db = test::synthetic_database({.frames = 64, .clips = 2, .channel_dims = {1}});
  ReferenceSearch search(db);
  std::vector<float> queries(kMaxBatch + 1, 0.0f);
  std::vector<Match> out(kMaxBatch + 1);
  const Status over = validate_search(db, QueryBatch{queries, {}, kMaxBatch + 1}, 1, out);
  ASSERT_FALSE(over.ok());
  EXPECT_TRUE(contains(over.message(), "over the limit of " + std::to_string(kMaxBatch))) << over.message();
  const Status at = validate_search(db, QueryBatch{std::span(queries).first(kMaxBatch), {}, kMaxBatch}, 1,
                                    std::span(out).first(kMaxBatch));
  EXPECT_TRUE(at.ok()) << at.message();
}

TEST(SizeLimits, KOutOfRangeIsAnError) {
  const Database db = test::synthetic_database({.frames = 64, .clips = 2});
  ReferenceSearch search(db);
  const std::vector<float> queries = test::synthetic_queries(db, 1, 3);
  std::vector<Match> out(std::size_t{kMaxK} + 1);
  const Status status = search.search(QueryBatch{queries, {}, 1}, kMaxK + 1, out);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "k = 17 is out of range [1, 16]")) << status.message();
}

// A sparse file: the size is there, the disk space is not used.
std::filesystem::path sparse_file(const std::string& name, std::uintmax_t bytes) {
  const std::filesystem::path path = test::make_temp_dir() / name;
  std::ofstream(path, std::ios::binary).put('M');
  std::filesystem::resize_file(path, bytes);
  return path;
}

TEST(SizeLimits, FilesOverTheLimitAreRefusedBeforeReading) {
  const std::filesystem::path path = sparse_file("huge.mmdb", kMaxFileBytes + 1);
  const Result<std::string> read = read_file(path);
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(contains(read.message(), path.string())) << read.message();
  EXPECT_TRUE(contains(read.message(), std::to_string(kMaxFileBytes + 1) + " bytes")) << read.message();
  EXPECT_TRUE(contains(read.message(), "kMaxFileBytes")) << read.message();
  const Result<Database> loaded = load_database(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_TRUE(contains(loaded.message(), "kMaxFileBytes")) << loaded.message();
}

TEST(SizeLimits, FilesUpToTheLimitStillRead) {
  const std::filesystem::path path = test::make_temp_dir() / "small.bin";
  const std::string bytes(200000, 'x');  // several read chunks
  std::ofstream(path, std::ios::binary) << bytes;
  const Result<std::string> read = read_file(path);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(*read, bytes);
}

TEST(SizeLimits, ThreadCountOverTheLimitIsAnError) {
  const Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(std::numeric_limits<unsigned>::max());
  ASSERT_FALSE(pool.ok());
  EXPECT_TRUE(contains(pool.message(), std::to_string(ThreadPool::kMaxThreads))) << pool.message();
}

}  // namespace
}  // namespace mmvk
