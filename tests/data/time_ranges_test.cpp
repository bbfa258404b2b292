// Manifest tag_ranges and cost_ranges on real clips (Bandai locomotion):
// per-frame tags, multipliers and biases, their .mmdb round trip, ranges
// outside a clip as errors naming the manifest and field, and the pruned
// backends (box and cluster bounds built from per-frame tags) against the
// reference on tag-range queries, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "mmvk/backends.hpp"
#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/thread_pool.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;

// A manifest over two Bandai walks (9 s each) at 30 fps; `clip0_extra` and
// `clip1_extra` are JSON members added to each clip object.
std::filesystem::path write_manifest(const std::filesystem::path& data, const std::string& clip0_extra,
                                     const std::string& clip1_extra) {
  const std::filesystem::path dir = test::make_temp_dir();
  const std::filesystem::path folder = data / "bandai-namco-nc/locomotion-normal";
  std::ofstream(dir / "m.json") << R"({"fps": 30, "clips": [
      {"file": ")" << (folder / "dataset-2_walk_normal_001.bvh").string()
                                << R"(", "tags": ["walk"])" << clip0_extra << R"(},
      {"file": ")" << (folder / "dataset-2_walk_normal_002.bvh").string()
                                << R"(", "tags": ["run"], "cost_multiplier": 1.25, "cost_bias": 0.5)" << clip1_extra
                                << "}]}";
  return dir / "m.json";
}

Result<Database> build(const std::filesystem::path& manifest_path) {
  Result<Manifest> manifest = load_manifest(manifest_path);
  if (!manifest.ok()) return manifest.error();
  BuildOptions options;
  options.animation.enabled = false;
  return build_database(*manifest, options);
}

// The rule of database_build.hpp: begin <= f / fps < end, with the time in
// double and the bounds as the manifest's floats.
bool inside(std::uint32_t f, float begin, float end) {
  const double t = double(f) / kFps;
  return t >= double(begin) && t < double(end);
}

class TimeRanges : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto data = test::find_data_dir();
    if (!data) GTEST_SKIP() << "motion data not found (set MMVK_DATA)";
    data_ = *data;
  }
  std::filesystem::path data_;
};

TEST_F(TimeRanges, PerFrameTagsAndCostsFollowTheRanges) {
  Result<Database> db = build(write_manifest(
      data_, R"(, "tag_ranges": {"jump": [[0.5, 1.0], [2.0, 2.5]], "walk_start": [[0.0, 0.4]]})",
      R"(, "cost_ranges": [{"range": [1.0, 2.0], "cost_multiplier": 2.0, "cost_bias": 0.25},
                           {"range": [1.5, 3.0], "cost_multiplier": 3.0}],
         "tag_ranges": {"jump": [[1.0, 1.2]]})"));
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->tag_names().size(), 4u);
  const TagMask walk = *db->tag_mask(std::vector<std::string>{"walk"});
  const TagMask run = *db->tag_mask(std::vector<std::string>{"run"});
  const TagMask jump = *db->tag_mask(std::vector<std::string>{"jump"});
  const TagMask start = *db->tag_mask(std::vector<std::string>{"walk_start"});
  const Clip& a = db->clips()[0];
  const Clip& b = db->clips()[1];
  EXPECT_EQ(a.tags, walk);  // clip tags stay the clip's own
  for (std::uint32_t f = 0; f < a.frame_count; ++f) {
    const bool in_jump = inside(f, 0.5f, 1.0f) || inside(f, 2.0f, 2.5f);
    const TagMask expected = walk | (in_jump ? jump : 0) | (inside(f, 0.0f, 0.4f) ? start : 0);
    ASSERT_EQ(db->frame_tags()[a.first_frame + f], expected) << "frame " << f;
    ASSERT_EQ(db->frame_multiplier()[a.first_frame + f], 1.0f);
    ASSERT_EQ(db->frame_bias()[a.first_frame + f], 0.0f);
  }
  for (std::uint32_t f = 0; f < b.frame_count; ++f) {
    const std::uint32_t g = b.first_frame + f;
    EXPECT_EQ(db->frame_tags()[g], run | (inside(f, 1.0f, 1.2f) ? jump : 0)) << "frame " << f;
    float multiplier = 1.25f;
    float bias = 0.5f;
    if (inside(f, 1.0f, 2.0f)) {
      multiplier *= 2.0f;
      bias += 0.25f;
    }
    if (inside(f, 1.5f, 3.0f)) multiplier *= 3.0f;
    ASSERT_EQ(db->frame_multiplier()[g], multiplier) << "frame " << f;
    ASSERT_EQ(db->frame_bias()[g], bias) << "frame " << f;
  }
  EXPECT_EQ(db->max_multiplier(), 1.25f * 6.0f);

  // The .mmdb keeps them.
  Result<Database> back = deserialize_database(serialize_database(*db), "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back->content_hash(), db->content_hash());
  EXPECT_TRUE(std::equal(back->frame_tags().begin(), back->frame_tags().end(), db->frame_tags().begin()));
  EXPECT_TRUE(std::equal(back->frame_multiplier().begin(), back->frame_multiplier().end(),
                         db->frame_multiplier().begin()));
  EXPECT_TRUE(std::equal(back->frame_bias().begin(), back->frame_bias().end(), db->frame_bias().begin()));
}

TEST_F(TimeRanges, RangesOutsideTheClipNameTheManifestAndField) {
  struct Case {
    std::string clip0;
    std::string clip1;
    std::string field;
  };
  const Case cases[] = {
      {R"(, "tag_ranges": {"jump": [[0.5, 1.0], [500.0, 501.0]]})", "", "m.json: clips[0].tag_ranges.jump[1]: "},
      {"", R"(, "cost_ranges": [{"range": [0.0, 1.0]}, {"range": [1.0, 900.0], "cost_bias": 1}])",
       "m.json: clips[1].cost_ranges[1].range: "},
  };
  for (const Case& c : cases) {
    const std::filesystem::path path = write_manifest(data_, c.clip0, c.clip1);
    Result<Database> db = build(path);
    ASSERT_FALSE(db.ok()) << c.field;
    EXPECT_NE(db.message().find(c.field), std::string::npos) << db.message();
    EXPECT_NE(db.message().find("outside the clip"), std::string::npos) << db.message();
  }
}

// Queries that require or exclude a range tag (and continue from frames in
// and out of ranges): every pruned CPU backend returns the reference's
// frames and costs exactly, so box and cluster tag bounds are exact.
TEST_F(TimeRanges, PrunedBackendsMatchTheReferenceOnRangeTags) {
  Result<Database> db = build(write_manifest(
      data_, R"(, "tag_ranges": {"jump": [[0.5, 1.0], [2.0, 2.5]], "rare": [[1.3, 1.4]]})",
      R"(, "cost_ranges": [{"range": [1.0, 2.0], "cost_multiplier": 2.0, "cost_bias": -0.5}],
         "tag_ranges": {"jump": [[1.0, 1.2]], "rare": [[2.9, 3.0]]})"));
  ASSERT_TRUE(db.ok()) << db.message();
  const TagMask jump = *db->tag_mask(std::vector<std::string>{"jump"});
  const TagMask rare = *db->tag_mask(std::vector<std::string>{"rare"});
  const TagMask run = *db->tag_mask(std::vector<std::string>{"run"});
  constexpr std::size_t kQueries = 48;
  std::mt19937 rng(12);
  std::uniform_int_distribution<std::uint32_t> pick(0, db->frame_count() - 1);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  std::vector<float> queries;
  std::vector<QueryParams> params(kQueries);
  for (std::size_t q = 0; q < kQueries; ++q) {
    for (const float x : db->row(pick(rng))) queries.push_back(x + noise(rng));
    QueryParams& p = params[q];
    const TagMask require[] = {0, jump, rare, jump | run};
    p.require_all = require[q % 4];
    p.exclude_any = q % 3 == 0 ? rare : 0;
    if (q % 2 == 1) {
      p.continuing_frame = pick(rng);
      p.continuing_bias = -0.1f;
      p.exclusion_window = 5;
    }
  }
  const QueryBatch batch{queries, params, kQueries};
  constexpr std::uint32_t k = 4;
  ThreadPool pool(2);
  std::vector<Match> expected(kQueries * k);
  Result<std::unique_ptr<SearchBackend>> reference = make_backend({.name = "reference"}, *db);
  ASSERT_TRUE(reference.ok()) << reference.message();
  ASSERT_TRUE((*reference)->search(batch, k, expected).ok());
  std::size_t found = 0;
  for (std::size_t q = 0; q < kQueries; ++q) found += expected[q * k].frame != kNoFrame ? 1 : 0;
  EXPECT_GT(found, kQueries / 2);  // the tags leave candidates for most queries
  for (const char* name : {"fast-brute", "fast-box", "clusters", "clusters-nprobe"}) {
    SCOPED_TRACE(name);
    BackendSpec spec{.name = name, .pool = &pool};
    spec.kmeans.clusters = 16;
    spec.nprobe = 1u << 20;  // every cluster: exact
    Result<std::unique_ptr<SearchBackend>> backend = make_backend(spec, *db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    std::vector<Match> got(kQueries * k);
    ASSERT_TRUE((*backend)->search(batch, k, got).ok());
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].frame, expected[i].frame) << "query " << i / k << " rank " << i % k;
      ASSERT_EQ(got[i].cost, expected[i].cost) << "query " << i / k << " rank " << i % k;
    }
  }
}

}  // namespace
}  // namespace mmvk
