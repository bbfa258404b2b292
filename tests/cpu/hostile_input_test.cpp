// Regression tests for hostile inputs and refused resources found by hand and
// by fuzzing (issue 13): each ends in an error naming what was wrong, never a
// crash, undefined behaviour or a garbage answer.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/hash.hpp"
#include "mmvk/common/json_check.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/query/pose_query.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/search/reference_search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define MMVK_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MMVK_TEST_ASAN 1
#endif
#endif

namespace mmvk {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// ---------------------------------------------------------------------------
// Thread pool

TEST(HostileThreadPool, TooManyThreadsIsAnError) {
  Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(100000);
  ASSERT_FALSE(pool.ok());
  EXPECT_TRUE(contains(pool.message(), "100000")) << pool.message();
  EXPECT_TRUE(contains(pool.message(), std::to_string(ThreadPool::kMaxThreads))) << pool.message();
}

TEST(HostileThreadPool, CreateWithinTheLimitWorks) {
  Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(3);
  ASSERT_TRUE(pool.ok()) << pool.message();
  EXPECT_EQ((*pool)->thread_count(), 3u);
}

// A refused thread start (here: an address-space limit too small for one
// more thread stack) is an error, not an uncaught std::system_error. Runs in
// a child process so that the limit stays there.
TEST(HostileThreadPool, RefusedThreadStartIsAnError) {
#if defined(MMVK_TEST_ASAN)
  GTEST_SKIP() << "ASan reserves terabytes of address space; an RLIMIT_AS test cannot run under it";
#else
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        rlimit limit{};
        getrlimit(RLIMIT_AS, &limit);
        // Whatever is mapped now plus 4 MiB: less than one default stack.
        std::FILE* statm = std::fopen("/proc/self/statm", "r");
        unsigned long pages = 0;
        if (statm == nullptr || std::fscanf(statm, "%lu", &pages) != 1) std::_Exit(10);
        std::fclose(statm);
        limit.rlim_cur = pages * 4096ul + (4ul << 20);
        if (setrlimit(RLIMIT_AS, &limit) != 0) std::_Exit(11);
        Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(64);
        if (pool.ok()) std::_Exit(12);
        std::fprintf(stderr, "%s\n", pool.message().c_str());
        std::_Exit(3);
      },
      ::testing::ExitedWithCode(3), "could not start thread");
#endif
}

// ---------------------------------------------------------------------------
// Cluster tables

TEST(HostileClusterTable, ZeroClustersIsAnError) {
  ClusterTable table;
  table.dims = 4;
  table.channel_count = 1;
  table.cluster_count = 0;
  table.offsets = {0};
  const std::filesystem::path path = test::make_temp_dir() / "empty.mmkc";
  ASSERT_TRUE(save_cluster_table(table, path).ok());
  Result<ClusterTable> loaded = load_cluster_table(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_TRUE(contains(loaded.message(), "cluster_count is 0")) << loaded.message();
  EXPECT_TRUE(contains(loaded.message(), path.string())) << loaded.message();
}

// Fuzz finding (fuzz_cluster_table): a header of 0xFFFFFFFF clusters, dims
// and channels made the loader's file-size formula wrap around 2^64 to the
// file's own 160 bytes, and the arrays were then allocated at those counts
// (std::length_error, an abort). The input is the finding, with its
// checksum repaired as the fuzz target does.
TEST(HostileClusterTable, HeaderCountsBeyondTheFileAreAnError) {
  const std::filesystem::path finding =
      test::test_source_dir() / "corpus" / "fuzz_cluster_table" / "size_formula_overflow.mmkc";
  std::ifstream in(finding, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  ASSERT_EQ(bytes.size(), 160u) << finding;
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size() - 8);
  const std::uint64_t digest = hasher.digest();
  std::memcpy(bytes.data() + bytes.size() - 8, &digest, 8);
  const std::filesystem::path path = test::make_temp_dir() / "overflow.mmkc";
  std::ofstream(path, std::ios::binary) << bytes;
  Result<ClusterTable> loaded = load_cluster_table(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_TRUE(contains(loaded.message(), "header counts")) << loaded.message();
  EXPECT_TRUE(contains(loaded.message(), path.string())) << loaded.message();
}

// ---------------------------------------------------------------------------
// Search

TEST(HostileSearch, QueriesWhoseCostsOverflowAreRejected) {
  const Database db = test::synthetic_database({.frames = 200, .clips = 2});
  std::vector<float> queries = test::synthetic_queries(db, 3, 5);
  queries[db.dims() + 2] = 1e30f;  // query 1 only
  ReferenceSearch search(db);
  std::vector<Match> out(3);
  const Status status = search.search(QueryBatch{queries, {}, 3}, 1, out);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "query 1")) << status.message();
  EXPECT_TRUE(contains(status.message(), "overflow")) << status.message();
}

TEST(HostileSearch, HugeWeightsThatOverflowAreRejected) {
  const Database db = test::synthetic_database({.frames = 200, .clips = 2});
  const std::vector<float> queries = test::synthetic_queries(db, 2, 5);
  std::vector<QueryParams> params(2);
  params[1].channel_weights[0] = 3e38f;
  ReferenceSearch search(db);
  std::vector<Match> out(2);
  const Status status = search.search(QueryBatch{queries, params, 2}, 1, out);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "query 1")) << status.message();
}

TEST(HostileSearch, LargeButSafeQueriesStillSearch) {
  const Database db = test::synthetic_database({.frames = 200, .clips = 2});
  std::vector<float> queries = test::synthetic_queries(db, 1, 5);
  queries[0] = 1e6f;
  ReferenceSearch search(db);
  std::vector<Match> out(1);
  ASSERT_TRUE(search.search(QueryBatch{queries, {}, 1}, 1, out).ok());
  EXPECT_NE(out[0].frame, kNoFrame);
  EXPECT_TRUE(std::isfinite(out[0].cost));
}

// ---------------------------------------------------------------------------
// JSON and frame rates

TEST(HostileJson, DuplicateManifestKeysAreRejected) {
  const Result<Manifest> manifest =
      parse_manifest_json(R"({"fps": 30, "clips": [{"file": "a.bvh", "loop": true, "loop": false}]})", "m.json", ".");
  ASSERT_FALSE(manifest.ok());
  EXPECT_TRUE(contains(manifest.message(), "m.json")) << manifest.message();
  EXPECT_TRUE(contains(manifest.message(), "duplicate key \"loop\"")) << manifest.message();
  const Result<Manifest> top = parse_manifest_json(R"({"fps": 30, "fps": 60, "clips": []})", "m.json", ".");
  ASSERT_FALSE(top.ok());
  EXPECT_TRUE(contains(top.message(), "duplicate key \"fps\"")) << top.message();
}

TEST(HostileJson, DuplicateSchemaKeysAreRejected) {
  const Result<FeatureSchema> schema = parse_schema_json(
      R"({"channels": [{"name": "a", "name": "b", "kind": "bone_position", "bone": "Hips"}]})", "s.json");
  ASSERT_FALSE(schema.ok());
  EXPECT_TRUE(contains(schema.message(), "s.json: duplicate key \"name\"")) << schema.message();
}

TEST(HostileJson, EqualKeysInDifferentObjectsAreFine) {
  const Result<Manifest> manifest = parse_manifest_json(
      R"({"clips": [{"file": "a.bvh", "loop": true}, {"file": "b.bvh", "loop": false}]})", "m.json", ".");
  EXPECT_TRUE(manifest.ok()) << manifest.message();
}

// Issue 23: bytes after the JSON, NULs among them, are errors in every JSON
// input; nlohmann's parser alone stops at a NUL and would accept the rest.
TEST(HostileJson, TrailingBytesAndNulsAreRejectedEverywhere) {
  const std::string manifest = R"({"clips": [{"file": "a.bvh"}]})";
  const std::string schema = R"({"channels": [{"name": "a", "kind": "bone_position", "bone": "Hips"}]})";
  const std::string targets = R"({"targets": [{"bone": "Hips", "position": [0, 0, 0]}]})";
  ASSERT_TRUE(parse_manifest_json(manifest, "m.json", ".").ok());
  ASSERT_TRUE(parse_schema_json(schema, "s.json").ok());
  ASSERT_TRUE(parse_pose_targets_json(targets, "t.json").ok());
  for (const std::string& tail : {std::string(1, '\0'), std::string("\0garbage", 8), std::string(" {}"), std::string("x")}) {
    const Result<Manifest> m = parse_manifest_json(manifest + tail, "m.json", ".");
    ASSERT_FALSE(m.ok()) << tail.size();
    EXPECT_TRUE(contains(m.message(), "m.json")) << m.message();
    EXPECT_FALSE(parse_schema_json(schema + tail, "s.json").ok()) << tail.size();
    EXPECT_FALSE(parse_pose_targets_json(targets + tail, "t.json").ok()) << tail.size();
    EXPECT_FALSE(check_json_text(targets + tail, "x.json").ok()) << tail.size();
  }
  const Status nul = check_json_text(std::string("{}") + std::string(2, '\0'), "x.json");
  ASSERT_FALSE(nul.ok());
  EXPECT_TRUE(contains(nul.message(), "x.json: a NUL byte at offset 2")) << nul.message();
  EXPECT_TRUE(check_json_text("  {\"a\": [1, {\"a\": 2}]}\n", "x.json").ok());
  const Status dup = check_json_text(R"({"a": 1, "b": {"c": 1, "c": 2}})", "x.json");
  ASSERT_FALSE(dup.ok());
  EXPECT_TRUE(contains(dup.message(), "duplicate key \"c\"")) << dup.message();
}

// Issue 23: a field a channel kind would ignore is an error, like an unknown one.
TEST(HostileJson, ABoneOnAChannelThatReadsNoneIsRejected) {
  const Result<FeatureSchema> schema =
      parse_schema_json(R"({"channels": [{"name": "turn", "kind": "root_angular_velocity", "bone": "Hips"}]})", "s.json");
  ASSERT_FALSE(schema.ok());
  EXPECT_TRUE(contains(schema.message(), "s.json: channels[0].bone: a root_angular_velocity channel reads no bone"))
      << schema.message();
  EXPECT_TRUE(parse_schema_json(R"({"channels": [{"name": "turn", "kind": "root_angular_velocity"}]})", "s.json").ok());
}

// Issue 23: a file that is not BVH is rejected without echoing it.
TEST(HostileBvh, ANonBvhFileIsNotEchoed) {
  const Result<BvhFile> file = parse_bvh("root:$6$salt$secrethash:19000:0:99999:7:::\n", "shadow");
  ASSERT_FALSE(file.ok());
  EXPECT_TRUE(contains(file.message(), "shadow:1: not a BVH file")) << file.message();
  EXPECT_FALSE(contains(file.message(), "root")) << file.message();
  EXPECT_FALSE(contains(file.message(), "secret")) << file.message();
}

TEST(HostileFrameRate, TinyManifestFpsIsABadFrameRate) {
  const Result<Manifest> manifest = parse_manifest_json(R"({"fps": 1e-9, "clips": []})", "m.json", ".");
  ASSERT_FALSE(manifest.ok());
  EXPECT_TRUE(contains(manifest.message(), "fps: 1e-09 is outside the supported")) << manifest.message();
}

TEST(HostileFrameRate, TinyFrameTimeIsABadFrameRate) {
  for (const char* frame_time : {"1e-30", "1e-9", "1000"}) {
    const std::string text = std::string("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n"
                                         " End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: ") +
                             frame_time + "\n0 0 0\n0 0 1\n";
    const Result<BvhFile> file = parse_bvh(text, "t.bvh");
    ASSERT_TRUE(file.ok()) << file.message();
    const Result<Motion> motion = motion_from_bvh(*file, ImportOptions{});
    ASSERT_FALSE(motion.ok()) << frame_time;
    EXPECT_TRUE(contains(motion.message(), "t.bvh: Frame Time")) << motion.message();
    EXPECT_TRUE(contains(motion.message(), "frames/s, outside the supported")) << motion.message();
  }
}

}  // namespace
}  // namespace mmvk
