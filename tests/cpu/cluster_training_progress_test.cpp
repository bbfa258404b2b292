// The progress callback of train_cluster_table: every stage is reported in
// order, the fraction never decreases and ends at 1, and the table is the
// one trained without a callback.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/clustered_data.hpp"

namespace mmvk {
namespace {

TEST(ClusterTrainingProgress, StagesInOrderFractionMonotoneAndSameTable) {
  Result<Database> db = Database::create(test::clustered_parts({}));
  ASSERT_TRUE(db.ok()) << db.message();
  KMeansParams params;
  params.clusters = 12;
  params.iterations = 6;
  params.max_training_frames = 500;  // a subsample: assigning covers more frames than training
  ThreadPool pool(2);
  std::vector<TrainingProgress> reports;
  Result<ClusterTable> with_progress =
      train_cluster_table(*db, params, pool, [&](const TrainingProgress& p) { reports.push_back(p); });
  ASSERT_TRUE(with_progress.ok()) << with_progress.message();
  Result<ClusterTable> without = train_cluster_table(*db, params, pool);
  ASSERT_TRUE(without.ok()) << without.message();
  EXPECT_EQ(with_progress->centroids, without->centroids);
  EXPECT_EQ(with_progress->members, without->members);

  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(std::string(reports.front().stage), "seeding");
  EXPECT_EQ(reports.front().fraction, 0.0);
  EXPECT_EQ(std::string(reports.back().stage), "assigning");
  EXPECT_EQ(reports.back().fraction, 1.0);
  std::vector<std::string> stages;
  for (std::size_t i = 0; i < reports.size(); ++i) {
    if (stages.empty() || stages.back() != reports[i].stage) stages.emplace_back(reports[i].stage);
    EXPECT_LE(reports[i].step, reports[i].steps) << i;
    if (i > 0) {
      EXPECT_GE(reports[i].fraction, reports[i - 1].fraction) << "report " << i;
    }
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"seeding", "lloyd", "assigning"}));
  // Seeding reports each centroid.
  std::uint32_t seeded = 0;
  for (const TrainingProgress& p : reports) {
    if (std::string(p.stage) == "seeding") seeded = p.step;
  }
  EXPECT_EQ(seeded, params.clusters);
}

}  // namespace
}  // namespace mmvk
