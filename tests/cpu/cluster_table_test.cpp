// k-means cluster tables: deterministic training, the partition and bound
// invariants, empty-cluster re-seeding, and the file format's validation.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "clusters/cluster_table_build.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/clustered_data.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

using test::clustered_database;

void expect_same_table(const ClusterTable& a, const ClusterTable& b) {
  EXPECT_EQ(a.database_hash, b.database_hash);
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.cluster_count, b.cluster_count);
  EXPECT_EQ(a.channel_count, b.channel_count);
  EXPECT_EQ(a.centroids, b.centroids);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.members, b.members);
  EXPECT_EQ(a.box_min, b.box_min);
  EXPECT_EQ(a.box_max, b.box_max);
  EXPECT_EQ(a.min_multiplier, b.min_multiplier);
  EXPECT_EQ(a.min_bias, b.min_bias);
  EXPECT_EQ(a.tag_union, b.tag_union);
  EXPECT_EQ(a.tag_intersection, b.tag_intersection);
  EXPECT_EQ(a.flags_intersection, b.flags_intersection);
  EXPECT_EQ(a.channel_radius, b.channel_radius);
}

TEST(ClusterTable, TrainingIsDeterministicAcrossRunsAndThreadCounts) {
  const Database db = clustered_database();
  KMeansParams params;
  params.clusters = 24;
  params.max_training_frames = 1000;  // exercise the subsample
  Result<ClusterTable> a = train_cluster_table(db, params);
  ThreadPool pool(2);
  Result<ClusterTable> b = train_cluster_table(db, params, pool);
  ASSERT_TRUE(a.ok()) << a.message();
  ASSERT_TRUE(b.ok()) << b.message();
  expect_same_table(*a, *b);
  params.seed = 99;
  Result<ClusterTable> c = train_cluster_table(db, params);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(a->centroids, c->centroids) << "another seed should give another clustering";
}

TEST(ClusterTable, EveryFrameInExactlyOneClusterAndBoundsCoverMembers) {
  const Database db = clustered_database();
  KMeansParams params;  // default cluster count: round(sqrt(2000)) = 45
  Result<ClusterTable> table = train_cluster_table(db, params);
  ASSERT_TRUE(table.ok()) << table.message();
  const ClusterTable& t = *table;
  EXPECT_EQ(t.cluster_count, 45u);
  EXPECT_EQ(t.database_hash, db.content_hash());
  ASSERT_TRUE(validate_cluster_table(t, db).ok()) << validate_cluster_table(t, db).message();
  std::vector<int> count(db.frame_count(), 0);
  std::uint32_t non_empty = 0;
  for (std::uint32_t c = 0; c < t.cluster_count; ++c) {
    if (t.offsets[c + 1] > t.offsets[c]) ++non_empty;
    for (std::uint32_t m = t.offsets[c]; m < t.offsets[c + 1]; ++m) {
      const std::uint32_t f = t.members[m];
      ++count[f];
      if (m > t.offsets[c]) {
        EXPECT_LT(t.members[m - 1], f);
      }
      for (std::uint32_t d = 0; d < t.dims; ++d) {
        EXPECT_LE(t.box_min[c * t.dims + d], db.row(f)[d]);
        EXPECT_GE(t.box_max[c * t.dims + d], db.row(f)[d]);
      }
      EXPECT_LE(t.min_multiplier[c], db.frame_multiplier()[f]);
      EXPECT_LE(t.min_bias[c], db.frame_bias()[f]);
      EXPECT_EQ(t.tag_union[c] & db.frame_tags()[f], db.frame_tags()[f]);
      EXPECT_EQ(t.flags_intersection[c] & db.frame_flags()[f], t.flags_intersection[c]);
    }
  }
  for (std::uint32_t f = 0; f < db.frame_count(); ++f) ASSERT_EQ(count[f], 1) << "frame " << f;
  EXPECT_GT(non_empty, 40u);
}

TEST(ClusterTable, FramesGoToTheirNearestCentroid) {
  const Database db = clustered_database();
  KMeansParams params;
  params.clusters = 16;
  Result<ClusterTable> table = train_cluster_table(db, params);
  ASSERT_TRUE(table.ok());
  const ClusterTable& t = *table;
  for (std::uint32_t c = 0; c < t.cluster_count; ++c) {
    for (std::uint32_t m = t.offsets[c]; m < t.offsets[c + 1]; m += 7) {
      const auto row = db.row(t.members[m]);
      auto dist = [&](std::uint32_t j) {
        double s = 0;
        for (std::uint32_t d = 0; d < t.dims; ++d) s += std::pow(double(row[d]) - t.centroids[j * t.dims + d], 2);
        return s;
      };
      for (std::uint32_t j = 0; j < t.cluster_count; ++j) EXPECT_LE(dist(c), dist(j) * (1 + 1e-5) + 1e-6);
    }
  }
}

TEST(ClusterTable, EmptyClusterIsReseededAtTheFarthestPoint) {
  // 1-D points {0, 1, 10, 11}; the second centroid starts far away and gets
  // no points, so it is re-seeded at the point farthest from its centroid
  // (0 or 11 from 5.5: the first, 0), and Lloyd then separates the groups.
  const std::vector<float> points = {0.0f, 1.0f, 10.0f, 11.0f};
  std::vector<float> centroids = {5.5f, 1000.0f};
  detail::run_lloyd(points.data(), points.size(), 1, centroids, 10, nullptr);
  std::sort(centroids.begin(), centroids.end());
  EXPECT_EQ(centroids, (std::vector<float>{0.5f, 10.5f}));
}

TEST(ClusterTable, DegenerateDataKeepsEmptyClustersValid) {
  // Only 3 distinct rows but 8 clusters: some clusters must stay empty.
  test::ClusteredDataSpec spec;
  spec.frames = 300;
  spec.blobs = 3;
  spec.blob_spread = 0.0f;
  spec.clip_frames = 100;
  const Database db = clustered_database(spec);
  KMeansParams params;
  params.clusters = 8;
  Result<ClusterTable> table = train_cluster_table(db, params);
  ASSERT_TRUE(table.ok()) << table.message();
  EXPECT_TRUE(validate_cluster_table(*table, db).ok()) << validate_cluster_table(*table, db).message();
}

TEST(ClusterTable, BadParameters) {
  test::ClusteredDataSpec spec;
  spec.frames = 50;
  const Database db = clustered_database(spec);
  KMeansParams params;
  params.clusters = 51;
  Result<ClusterTable> table = train_cluster_table(db, params);
  ASSERT_FALSE(table.ok());
  EXPECT_NE(table.message().find("clusters = 51"), std::string::npos) << table.message();
  params.clusters = 50;  // one frame per cluster is fine
  EXPECT_TRUE(train_cluster_table(db, params).ok());
}

class ClusterTableFile : public ::testing::Test {
 protected:
  void SetUp() override {
    KMeansParams params;
    params.clusters = 12;
    Result<ClusterTable> trained = train_cluster_table(db_, params);
    ASSERT_TRUE(trained.ok());
    table_ = *trained;
    path_ = test::make_temp_dir() / "table.mmct";
    ASSERT_TRUE(save_cluster_table(table_, path_).ok());
    std::ifstream in(path_, std::ios::binary);
    bytes_.assign(std::istreambuf_iterator<char>(in), {});
  }
  void write(const std::string& bytes) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  std::string load_error() {
    Result<ClusterTable> loaded = load_cluster_table(path_);
    EXPECT_FALSE(loaded.ok());
    return loaded.ok() ? std::string() : loaded.message();
  }

  Database db_ = clustered_database();
  ClusterTable table_;
  std::filesystem::path path_;
  std::string bytes_;
};

TEST_F(ClusterTableFile, RoundTrip) {
  Result<ClusterTable> loaded = load_cluster_table(path_);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  expect_same_table(table_, *loaded);
  EXPECT_TRUE(validate_cluster_table(*loaded, db_).ok());
}

TEST_F(ClusterTableFile, TruncatedFilesAreRejected) {
  for (std::size_t size : {std::size_t{0}, std::size_t{5}, std::size_t{20}, bytes_.size() / 2, bytes_.size() - 1}) {
    write(bytes_.substr(0, size));
    const std::string error = load_error();
    EXPECT_NE(error.find(path_.string()), std::string::npos) << error;
    EXPECT_TRUE(error.find("truncated") != std::string::npos || error.find("magic") != std::string::npos) << error;
  }
}

TEST_F(ClusterTableFile, BitFlipsAreRejected) {
  for (std::size_t pos : {std::size_t{60}, bytes_.size() / 2, bytes_.size() - 20, bytes_.size() - 1}) {
    std::string flipped = bytes_;
    flipped[pos] = static_cast<char>(flipped[pos] ^ 0x10);
    write(flipped);
    EXPECT_NE(load_error().find("checksum"), std::string::npos) << "flip at " << pos;
  }
}

TEST_F(ClusterTableFile, WrongVersionAndMagicAreRejected) {
  std::string wrong = bytes_;
  wrong[8] = 2;
  write(wrong);
  EXPECT_NE(load_error().find("version 2"), std::string::npos);
  wrong = bytes_;
  wrong[0] = 'X';
  write(wrong);
  EXPECT_NE(load_error().find("magic"), std::string::npos);
}

TEST_F(ClusterTableFile, MissingFileIsAnError) {
  std::filesystem::remove(path_);
  EXPECT_FALSE(load_cluster_table(path_).ok());
}

TEST(ClusterTableValidation, TableFromAnotherDatabaseIsRejected) {
  const Database a = clustered_database();
  test::ClusteredDataSpec spec;
  spec.seed = 8;
  const Database b = clustered_database(spec);
  KMeansParams params;
  params.clusters = 10;
  Result<ClusterTable> table = train_cluster_table(a, params);
  ASSERT_TRUE(table.ok());
  const Status status = validate_cluster_table(*table, b);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("another database"), std::string::npos) << status.message();

  spec.seed = 7;
  spec.frames = 1500;
  const Database smaller = clustered_database(spec);
  ClusterTable forged = *table;
  forged.database_hash = smaller.content_hash();  // same hash, wrong frame count
  const Status frames = validate_cluster_table(forged, smaller);
  ASSERT_FALSE(frames.ok());
  EXPECT_NE(frames.message().find("frames"), std::string::npos) << frames.message();
}

TEST(ClusterTableValidation, BrokenBoundsAreRejected) {
  const Database db = clustered_database();
  KMeansParams params;
  params.clusters = 10;
  const ClusterTable table = *train_cluster_table(db, params);
  auto expect_error = [&](const ClusterTable& t, const std::string& what) {
    const Status status = validate_cluster_table(t, db);
    ASSERT_FALSE(status.ok()) << what;
    EXPECT_NE(status.message().find(what), std::string::npos) << status.message();
  };
  ClusterTable t = table;
  t.box_max[0] = t.box_min[0] - 1.0f;
  expect_error(t, "outside the box");
  t = table;
  t.channel_radius[0] *= 0.5f;
  expect_error(t, "radius");
  t = table;
  t.min_bias[3] += 1.0f;
  expect_error(t, "min_bias");
  t = table;
  std::swap(t.members[0], t.members[1]);
  expect_error(t, "ascending");
  t = table;
  t.members[5] = t.members[6];
  expect_error(t, "more than one cluster");
  t = table;
  t.offsets.pop_back();
  expect_error(t, "offsets");
}

}  // namespace
}  // namespace mmvk
