// Manifest tag_ranges and cost_ranges on real clips (Bandai locomotion):
// per-frame tags, multipliers and biases, their .mmdb round trip, ranges
// outside a clip as errors naming the manifest and field, and the pruned
// backends (box and cluster bounds built from per-frame tags) against the
// reference on tag-range queries, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <span>

#include "mmvk/database/database_io.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/time_ranges_data.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;

using test::build_features_only;
using test::write_ranges_manifest;

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
  Result<Database> db = build_features_only(write_ranges_manifest(
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

  // The .mmdb keeps them (a version 7 file, since the build also records
  // where the clips' units and axes came from: version 3 files have
  // per-frame modifiers alone).
  EXPECT_EQ(serialize_database(*db)[8], char(7));
  Result<Database> back = deserialize_database(serialize_database(*db), "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back->content_hash(), db->content_hash());
  EXPECT_TRUE(std::equal(back->frame_tags().begin(), back->frame_tags().end(), db->frame_tags().begin()));
  EXPECT_TRUE(std::equal(back->frame_multiplier().begin(), back->frame_multiplier().end(),
                         db->frame_multiplier().begin()));
  EXPECT_TRUE(std::equal(back->frame_bias().begin(), back->frame_bias().end(), db->frame_bias().begin()));
}

TEST_F(TimeRanges, AClipRangeTakesPartOfTheFileAndCanLoop) {
  // Clip 0 takes [1, 2) s of its file, looped; clip 1 the whole file. The
  // cut clip's frames are the whole clip's frames 30..59, and its tag range
  // counts from the cut.
  Result<Database> whole = build_features_only(write_ranges_manifest(data_, "", ""));
  Result<Database> cut = build_features_only(
      write_ranges_manifest(data_, R"(, "range": [1.0, 2.0], "loop": true, "tag_ranges": {"jump": [[0.5, 1.0]]})", ""));
  ASSERT_TRUE(whole.ok() && cut.ok()) << whole.message() << cut.message();
  const Clip& a = cut->clips()[0];
  ASSERT_EQ(a.frame_count, 30u);
  EXPECT_TRUE(a.loop);
  EXPECT_EQ(cut->clips()[1].frame_count, whole->clips()[1].frame_count);
  // The left foot's speed: the same wherever the clip starts (its direction
  // in character space is not: the facing is smoothed up to the clip's ends).
  const auto raw = [&](const Database& db, std::uint32_t f) {
    double sum = 0.0;
    for (std::uint32_t d = 6; d < 9; ++d) {  // left_foot_velocity
      const double v = db.row(f)[d] * db.normalization()[d].scale + db.normalization()[d].offset;
      sum += v * v;
    }
    return std::sqrt(sum);
  };
  for (std::uint32_t f = 1; f + 1 < 30; ++f) ASSERT_NEAR(raw(*cut, f), raw(*whole, 30 + f), 1e-4) << f;
  const TagMask jump = *cut->tag_mask(std::vector<std::string>{"jump"});
  for (std::uint32_t f = 0; f < 30; ++f) EXPECT_EQ((cut->frame_tags()[f] & jump) != 0, f >= 15) << f;
  for (std::uint32_t flags : std::span(cut->frame_flags()).first(30)) EXPECT_EQ(flags & kFrameEdgeExcluded, 0u);

  // A range that misses the file names the manifest and the field.
  Result<Database> outside = build_features_only(write_ranges_manifest(data_, R"(, "range": [20, 30])", ""));
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.message().find("clips[0].range: [20, 30) s lies outside the clip"), std::string::npos)
      << outside.message();
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
    const std::filesystem::path path = write_ranges_manifest(data_, c.clip0, c.clip1);
    Result<Database> db = build_features_only(path);
    ASSERT_FALSE(db.ok()) << c.field;
    EXPECT_NE(db.message().find(c.field), std::string::npos) << db.message();
    EXPECT_NE(db.message().find("outside the clip"), std::string::npos) << db.message();
  }
}

// Queries that require or exclude a range tag (and continue from frames in
// and out of ranges): every pruned CPU backend returns the reference's
// frames and costs exactly, so box and cluster tag bounds are exact.
TEST_F(TimeRanges, PrunedBackendsMatchTheReferenceOnRangeTags) {
  Result<Database> db = test::build_ranged_database(data_);
  ASSERT_TRUE(db.ok()) << db.message();
  ThreadPool pool(2);
  BackendSpec spec{.pool = &pool};
  spec.kmeans.clusters = 16;
  spec.nprobe = 1u << 20;  // every cluster: exact
  const char* const names[] = {"fast-brute", "fast-box", "clusters", "clusters-nprobe"};
  test::expect_reference_results(*db, cpu_backends(), spec, names);
}

}  // namespace
}  // namespace mmvk
