// The benchmark suite's peers (bench/peers) against the reference on real
// features: the Bandai locomotion set built as the suite builds it (every
// frame a candidate, default schema), queried with the suite's streams.
//
//  - box-scan is exact: the reference's frames and cost bits, k = 1 and 10.
//  - FAISS IndexFlatL2 agrees with the reference except on float near-ties.
//    FAISS batches (20 queries or more) compute ||q||^2 + ||x||^2 - 2 q.x
//    through sgemm, and single queries sum (x - q)^2 in SIMD lanes; the
//    reference sums (x - q)^2 per channel in schema order. The expansion
//    rounds at the scale of ||q||^2 + ||x||^2, not of the (much smaller)
//    distance, so its error is about 1e-7 of the norms; the direct sums
//    differ by a few ulp of the cost. When two frames' exact costs are that
//    close FAISS may return the other one. Every disagreement must be such
//    a near-tie (the reference's cost of FAISS's frame within 1e-5 of the
//    norms of the best cost); they are counted, printed and bounded.
//  - pca-kdtree with every frame a candidate is exact; the Jacobi eigen
//    solver behind its PCA recovers a known spectrum.
//  - Peers refuse databases and batches that are not plain nearest neighbour.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "box_scan.hpp"
#include "faiss_peers.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/search/reference_search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "query_streams.hpp"
#include "support/test_data.hpp"
#if defined(MMVK_HAS_NANOFLANN)
#include "pca_kdtree.hpp"
#endif

namespace mmvk::test {
namespace {

constexpr std::size_t kQueries = 256;
constexpr bench::QueryStream kStreams[] = {bench::QueryStream::Continue, bench::QueryStream::Transition,
                                           bench::QueryStream::Uniform};

const Database* plain_locomotion(const std::filesystem::path& data) {
  static std::unique_ptr<Database> db;
  static bool tried = false;
  if (!tried) {
    tried = true;
    Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc" / "locomotion-normal");
    if (!manifest) {
      ADD_FAILURE() << manifest.message();
      return nullptr;
    }
    manifest->edge_rule = EdgeRule::Clamp;
    ThreadPool pool;
    BuildOptions options;
    options.pool = &pool;
    options.animation.enabled = false;
    Result<Database> built = build_database(*manifest, options);
    if (!built) {
      ADD_FAILURE() << built.message();
      return nullptr;
    }
    db = std::make_unique<Database>(std::move(built).value());
  }
  return db.get();
}

std::vector<Match> search(SearchBackend& backend, const std::vector<float>& queries, std::uint32_t k) {
  const std::size_t count = queries.size() / backend.database().dims();
  std::vector<Match> out(count * k);
  const Status status = backend.search({.features = queries, .params = {}, .size = count}, k, out);
  EXPECT_TRUE(status.ok()) << backend.name() << ": " << (status.ok() ? "" : status.message());
  return out;
}

#define MMVK_PLAIN_DB(db)                                   \
  MMVK_REQUIRE_DATA_DIR(data_dir_);                         \
  const Database* db = plain_locomotion(data_dir_);         \
  ASSERT_NE(db, nullptr)

void expect_exact(SearchBackend& backend, ReferenceSearch& reference, std::uint32_t k,
                  std::size_t count = kQueries) {
  for (const bench::QueryStream stream : kStreams) {
    const std::vector<float> queries = bench::make_queries(reference.database(), stream, count, 7);
    const std::vector<Match> want = search(reference, queries, k), got = search(backend, queries, k);
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(got[i].frame, want[i].frame) << backend.name() << " stream " << bench::query_stream_name(stream)
                                             << " query " << i / k << " rank " << i % k << " k " << k;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(got[i].cost), std::bit_cast<std::uint32_t>(want[i].cost))
          << backend.name() << " query " << i / k << " rank " << i % k;
    }
  }
}

TEST(PeersData, BoxScanReturnsTheReferenceFramesAndCosts) {
  MMVK_PLAIN_DB(db);
  Result<std::unique_ptr<peers::BoxScan>> box = peers::BoxScan::create(*db);
  ASSERT_TRUE(box.ok()) << box.message();
  ReferenceSearch reference(*db);
  expect_exact(**box, reference, 1);
  expect_exact(**box, reference, 10);
  // It prunes: far fewer rows than the brute force on the continue stream.
  (*box)->reset_stats();
  (void)search(**box, bench::make_queries(*db, bench::QueryStream::Continue, kQueries, 7), 1);
  EXPECT_LT((*box)->stats().rows_fraction(db->frame_count()), 0.5);
}

void expect_flat_agrees(bool one_at_a_time) {
  MMVK_PLAIN_DB(db);
  Result<std::unique_ptr<peers::PeerBackend>> flat = peers::make_faiss_flat(*db, one_at_a_time);
  ASSERT_TRUE(flat.ok()) << flat.message();
  ReferenceSearch reference(*db);
  std::size_t near_ties = 0, queries_run = 0;
  double worst_cost_error = 0.0;  // |FAISS distance - reference cost| / (||q||^2 + ||x||^2)
  auto squared_norm = [](std::span<const float> v) {
    double sum = 0.0;
    for (const float x : v) sum += double(x) * x;
    return sum;
  };
  for (const bench::QueryStream stream : kStreams) {
    const std::vector<float> queries = bench::make_queries(*db, stream, kQueries, 7);
    const std::vector<Match> want = search(reference, queries, 1), got = search(**flat, queries, 1);
    for (std::size_t q = 0; q < kQueries; ++q) {
      ++queries_run;
      const std::span<const float> query = std::span(queries).subspan(q * db->dims(), db->dims());
      // The scale the expansion ||q||^2 + ||x||^2 - 2 q.x rounds at.
      const double scale = squared_norm(query) + squared_norm(db->row(want[q].frame));
      const float best = want[q].cost;
      worst_cost_error = std::max(worst_cost_error, std::abs(double(got[q].cost) - best) / scale);
      if (got[q].frame == want[q].frame) continue;
      ASSERT_NE(got[q].frame, kNoFrame);
      EXPECT_TRUE(peers::is_float_near_tie(*db, query, want[q], got[q].frame))
          << (*flat)->name() << " stream " << bench::query_stream_name(stream) << " query " << q << ": frame "
          << got[q].frame << " costs " << frame_cost(*db, got[q].frame, query, {}) << ", the reference's frame " << want[q].frame << " " << best;
      ++near_ties;
    }
  }
  std::printf("%s: %zu of %zu queries answered with another frame of (nearly) equal cost; largest distance "
              "difference %.3g of ||q||^2 + ||x||^2\n",
              std::string((*flat)->name()).c_str(), near_ties, queries_run, worst_cost_error);
  EXPECT_LE(near_ties, queries_run / 100) << "near-ties should be rare";
  EXPECT_LT(worst_cost_error, 1e-5);
}

TEST(PeersData, NearTieRuleAcceptsRoundingAndRefusesANeighbour) {
  MMVK_PLAIN_DB(db);
  ReferenceSearch reference(*db);
  const std::vector<float> queries = bench::make_queries(*db, bench::QueryStream::Continue, 16, 7);
  const std::vector<Match> best = search(reference, queries, 1);
  std::size_t refused = 0;
  for (std::size_t q = 0; q < 16; ++q) {
    const std::span<const float> query = std::span(queries).subspan(q * db->dims(), db->dims());
    EXPECT_TRUE(peers::is_float_near_tie(*db, query, best[q], best[q].frame));
    // A frame half the database away: a real neighbour, not a rounding.
    const std::uint32_t far = (best[q].frame + db->frame_count() / 2) % db->frame_count();
    if (frame_cost(*db, far, query, {}) > best[q].cost + 1.0f) {
      EXPECT_FALSE(peers::is_float_near_tie(*db, query, best[q], far)) << q;
      ++refused;
    }
  }
  EXPECT_GT(refused, 8u);
}

TEST(PeersData, FaissFlatBatchedAgreesWithTheReferenceUpToNearTies) { expect_flat_agrees(false); }
TEST(PeersData, FaissFlatOneQueryAtATimeAgreesWithTheReferenceUpToNearTies) { expect_flat_agrees(true); }

TEST(PeersData, FaissIvfProbingEveryListFindsTheFlatAnswer) {
  MMVK_PLAIN_DB(db);
  Result<peers::FaissIvfBuild> ivf = peers::build_faiss_ivf(*db, {});
  ASSERT_TRUE(ivf.ok()) << ivf.message();
  Result<std::unique_ptr<peers::PeerBackend>> all = peers::make_faiss_ivf(*db, ivf->index, 1u << 20);
  Result<std::unique_ptr<peers::PeerBackend>> one = peers::make_faiss_ivf(*db, ivf->index, 1);
  Result<std::unique_ptr<peers::PeerBackend>> flat = peers::make_faiss_flat(*db, true);
  ASSERT_TRUE(all.ok() && one.ok() && flat.ok());
  const std::vector<float> queries = bench::make_queries(*db, bench::QueryStream::Uniform, kQueries, 7);
  const std::vector<Match> want = search(**flat, queries, 1), got = search(**all, queries, 1);
  std::size_t same = 0;
  for (std::size_t q = 0; q < kQueries; ++q) same += got[q].frame == want[q].frame;
  EXPECT_GE(same, kQueries - kQueries / 100);
  // One list is far less work than every list.
  (void)search(**one, queries, 1);
  EXPECT_LT((*one)->stats().rows_fraction(db->frame_count()), 0.1);
  EXPECT_GT((*all)->stats().rows_fraction(db->frame_count()), 0.99);
}

#if defined(MMVK_HAS_NANOFLANN)
TEST(PeersData, PcaKdTreeWithEveryFrameACandidateIsExact) {
  MMVK_PLAIN_DB(db);
  Result<std::shared_ptr<peers::PcaKdTreeIndex>> index = peers::build_pca_kdtree(*db);
  ASSERT_TRUE(index.ok()) << index.message();
  Result<std::unique_ptr<peers::PeerBackend>> all = peers::make_pca_kdtree(*db, *index, db->frame_count());
  ASSERT_TRUE(all.ok()) << all.message();
  ReferenceSearch reference(*db);
  // Every frame a candidate makes the KD-tree walk quadratic: few queries.
  expect_exact(**all, reference, 4, 8);
}

TEST(PeersPca, JacobiRecoversAKnownSpectrum) {
  // R diag(5, 2, 0.5) R^T for a rotation R about z by 30 degrees and a
  // permutation: the eigenvalues come back sorted with their axes.
  const double c = std::cos(0.5235987755982988), s = std::sin(0.5235987755982988);
  const double r[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
  const double lambda[3] = {2.0, 5.0, 0.5};
  std::vector<double> m(9, 0.0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) m[i * 3 + j] += r[i][k] * lambda[k] * r[j][k];
    }
  }
  std::vector<double> values, vectors;
  peers::symmetric_eigen(m, 3, values, vectors);
  EXPECT_NEAR(values[0], 5.0, 1e-9);
  EXPECT_NEAR(values[1], 2.0, 1e-9);
  EXPECT_NEAR(values[2], 0.5, 1e-9);
  // The first axis is column 1 of R, up to sign.
  EXPECT_NEAR(std::abs(vectors[0] * r[0][1] + vectors[1] * r[1][1] + vectors[2] * r[2][1]), 1.0, 1e-9);
}
#endif

TEST(PeersData, PeersRefuseWhatIsNotPlainNearestNeighbour) {
  MMVK_REQUIRE_DATA_DIR(data);
  // The locomotion set with the default edge rule: edge frames are flagged.
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc" / "locomotion-normal");
  ASSERT_TRUE(manifest.ok());
  manifest->clips.resize(3);
  BuildOptions options;
  options.animation.enabled = false;
  Result<Database> flagged = build_database(*manifest, options);
  ASSERT_TRUE(flagged.ok()) << flagged.message();
  Result<std::unique_ptr<peers::BoxScan>> box = peers::BoxScan::create(*flagged);
  ASSERT_FALSE(box.ok());
  EXPECT_NE(box.message().find("not a plain candidate"), std::string::npos) << box.message();
  EXPECT_FALSE(peers::make_faiss_flat(*flagged, false).ok());

  manifest->edge_rule = EdgeRule::Clamp;
  Result<Database> plain_db = build_database(*manifest, options);
  ASSERT_TRUE(plain_db.ok()) << plain_db.message();
  const Database* db = &*plain_db;
  Result<std::unique_ptr<peers::BoxScan>> plain = peers::BoxScan::create(*db);
  ASSERT_TRUE(plain.ok());
  const std::vector<float> query(db->row(0).begin(), db->row(0).end());
  const QueryParams params[1] = {QueryParams{.exclude_any = 1}};
  std::vector<Match> out(1);
  const Status refused = (*plain)->search({.features = query, .params = params, .size = 1}, 1, out);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("params"), std::string::npos) << refused.message();
}

}  // namespace
}  // namespace mmvk::test
