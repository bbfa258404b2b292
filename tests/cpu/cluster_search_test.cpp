// ClusterSearch against the CPU reference: same frames, bit-identical costs,
// under every constraint and bias, ties and k > 1; nprobe = all equals exact.
#include <gtest/gtest.h>

#include <bit>
#include <cstdio>
#include <cmath>
#include <random>
#include <string>

#include "mmvk/search/cluster_search.hpp"
#include "mmvk/search/fast_search.hpp"
#include "mmvk/search/reference_search.hpp"
#include "support/clustered_data.hpp"

namespace mmvk {
namespace {

using test::clustered_database;

ClusterTable make_table(const Database& db, std::uint32_t clusters) {
  KMeansParams params;
  params.clusters = clusters;
  Result<ClusterTable> table = train_cluster_table(db, params);
  EXPECT_TRUE(table.ok()) << table.message();
  return std::move(table).value();
}

// Queries near rows (noise), between blobs, and far away.
std::vector<float> make_queries(const Database& db, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<float> q(count * db.dims());
  for (std::size_t i = 0; i < count; ++i) {
    const auto row = db.row(static_cast<std::uint32_t>(rng() % db.frame_count()));
    const int kind = static_cast<int>(i % 3);
    for (std::uint32_t d = 0; d < db.dims(); ++d) {
      const double n = test::normal(rng);
      q[i * db.dims() + d] = kind == 0   ? row[d] + static_cast<float>(0.05 * n)
                             : kind == 1 ? static_cast<float>(3.0 * n)
                                         : static_cast<float>(10.0 * n);
    }
  }
  return q;
}

// Every constraint and bias, varied per query.
std::vector<QueryParams> make_params(const Database& db, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<QueryParams> params(count);
  for (std::size_t i = 0; i < count; ++i) {
    QueryParams& p = params[i];
    switch (i % 6) {
      case 0: break;  // defaults
      case 1:
        p.continuing_frame = static_cast<std::uint32_t>(rng() % db.frame_count());
        p.continuing_bias = -static_cast<float>(test::unit_uniform(rng) * 5.0);
        p.exclusion_window = static_cast<std::uint32_t>(rng() % 40);
        break;
      case 2:
        p.continuing_frame = static_cast<std::uint32_t>(rng() % db.frame_count());
        p.continuing_bias = static_cast<float>(test::unit_uniform(rng));
        p.exclusion_window = 200;  // wider than clips: loops wrap
        break;
      case 3:
        p.require_all = rng() % 4;
        p.exclude_any = (rng() % 4) << 2;
        break;
      case 4:
        for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
          p.channel_weights[c] = (rng() % 3 == 0) ? 0.0f : static_cast<float>(0.25 + 2.0 * test::unit_uniform(rng));
        }
        break;
      case 5:
        p.continuing_frame = static_cast<std::uint32_t>(rng() % db.frame_count());
        p.continuing_bias = -0.5f;
        p.exclusion_window = 10;
        p.require_all = 1;
        p.channel_weights[0] = 0.0f;  // e.g. a pose-only query
        break;
    }
  }
  return params;
}

// Queries of every kind with every constraint and bias (make_queries and
// make_params with seeds `seed` and `seed + 1`).
struct ConstrainedQueries {
  std::vector<float> features;
  std::vector<QueryParams> params;
  std::size_t count;
  QueryBatch batch() const { return {features, params, count}; }
};

ConstrainedQueries constrained_queries(const Database& db, std::size_t count, std::uint64_t seed) {
  return {make_queries(db, count, seed), make_params(db, count, seed + 1), count};
}

void expect_identical(std::span<const Match> expected, std::span<const Match> actual, std::uint32_t k,
                      const std::string& what) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(expected[i].frame, actual[i].frame) << what << ": query " << i / k << " rank " << i % k;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(expected[i].cost), std::bit_cast<std::uint32_t>(actual[i].cost))
        << what << ": query " << i / k << " rank " << i % k << " costs " << expected[i].cost << " vs " << actual[i].cost;
  }
}

struct Variant {
  const char* name;
  ClusterSearchOptions options;
};

const Variant kExactVariants[] = {
    {"exact", {}},
    {"nprobe=all", {.nprobe = 1000000}},
    {"no tile bound", {.nprobe = 0, .box_bound = true, .tile_bound = false}},
    {"no bounds", {.nprobe = 0, .box_bound = false, .tile_bound = false}},
    {"no nearest seed", {.nprobe = 0, .seed_nearest = false}},
    // The SSE2 kernels the tile module falls back to (the same ones FastSearch
    // runs with kernels = Generic).
    {"generic kernels", {.kernels = CpuKernels::Generic}},
    {"generic kernels, no nearest seed", {.nprobe = 0, .seed_nearest = false, .kernels = CpuKernels::Generic}},
    // Every visited row evaluated from the float tiles (no half filter).
    {"float rows", {.nprobe = 0, .half_filter = false}},
    {"float rows, generic kernels", {.nprobe = 0, .half_filter = false, .kernels = CpuKernels::Generic}},
};

// 200 clusters: several groups of 32 (the level above the clusters, whose
// bounds decide which cluster bounds are computed at all); both walks.
TEST(ClusterSearch, MatchesReferenceBitForBitUnderEveryConstraint) {
  const Database db = clustered_database();
  ThreadPool pool(2);
  ReferenceSearch reference(db);
  const ConstrainedQueries queries = constrained_queries(db, 240, 11);
  const std::size_t count = queries.count;
  const QueryBatch batch = queries.batch();
  for (const std::uint32_t clusters : {30u, 200u}) {
    const ClusterTable table = make_table(db, clusters);
    for (std::uint32_t k : {1u, 3u, 16u}) {
      std::vector<Match> expected(count * k);
      ASSERT_TRUE(reference.search(batch, k, expected).ok());
      for (const bool grouped : {true, false}) {
        for (const Variant& variant : kExactVariants) {
          ClusterSearchOptions options = variant.options;
          options.batch_by_cluster = grouped;
          auto backend = ClusterSearch::create(db, table, pool, options);
          ASSERT_TRUE(backend.ok()) << backend.message();
          std::vector<Match> actual(count * k);
          ASSERT_TRUE((*backend)->search(batch, k, actual).ok());
          expect_identical(expected, actual, k,
                           std::string(variant.name) + " clusters=" + std::to_string(clusters) +
                               (grouped ? " grouped" : " walk") + " k=" + std::to_string(k));
        }
      }
    }
  }
}

TEST(ClusterSearch, UniqueMinimaAreFoundWithDefaultParams) {
  // Queries equal to a row: that row is the unique best at cost bias*... the
  // reference decides; plain clips keep multiplier 1 and bias 0.
  test::ClusteredDataSpec spec;
  spec.varied_clips = false;
  const Database db = clustered_database(spec);
  const ClusterTable table = make_table(db, 40);
  ThreadPool pool(2);
  auto backend = ClusterSearch::create(db, table, pool);
  ASSERT_TRUE(backend.ok());
  std::vector<float> features;
  std::vector<std::uint32_t> frames;
  for (std::uint32_t f = 5; f < db.frame_count(); f += 97) {
    frames.push_back(f);
    features.insert(features.end(), db.row(f).begin(), db.row(f).end());
  }
  std::vector<Match> out(frames.size());
  ASSERT_TRUE((*backend)->search({features, {}, frames.size()}, 1, out).ok());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(out[i].frame, frames[i]);
    EXPECT_EQ(out[i].cost, 0.0f);
  }
  // Exact hits prune almost everything.
  EXPECT_LT((*backend)->stats().rows_fraction(db.frame_count()), 0.25);
}

// Blobs of zero spread: every blob's rows are identical.
Database zero_spread_database(std::uint32_t frames, std::uint32_t blobs) {
  test::ClusteredDataSpec spec;
  spec.frames = frames;
  spec.blobs = blobs;
  spec.blob_spread = 0.0f;
  spec.varied_clips = false;
  return clustered_database(spec);
}

TEST(ClusterSearch, TiesGoToTheLowerFrameId) {
  // Costs tie in large groups spread over clusters and tiles.
  const Database db = zero_spread_database(600, 4);
  ThreadPool pool(2);
  ReferenceSearch reference(db);
  const ClusterTable table = make_table(db, 9);
  const std::size_t count = 30;
  const std::vector<float> features = make_queries(db, count, 5);
  for (std::uint32_t k : {1u, 7u, 16u}) {
    std::vector<Match> expected(count * k);
    ASSERT_TRUE(reference.search({features, {}, count}, k, expected).ok());
    for (const Variant& variant : kExactVariants) {
      auto backend = ClusterSearch::create(db, table, pool, variant.options);
      ASSERT_TRUE(backend.ok());
      std::vector<Match> actual(count * k);
      ASSERT_TRUE((*backend)->search({features, {}, count}, k, actual).ok());
      expect_identical(expected, actual, k, std::string("ties ") + variant.name);
    }
  }
}

TEST(ClusterSearch, AllCandidatesExcludedGivesNone) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 20);
  ThreadPool pool(1);
  auto backend = ClusterSearch::create(db, table, pool);
  ASSERT_TRUE(backend.ok());
  QueryParams params;
  params.require_all = 0xF;
  params.exclude_any = 0xF;  // contradictory: nothing passes
  const std::vector<float> features = make_queries(db, 1, 3);
  std::vector<Match> out(4);
  ASSERT_TRUE((*backend)->search({features, {&params, 1}, 1}, 4, out).ok());
  for (const Match& m : out) EXPECT_EQ(m, Match{});
  EXPECT_EQ((*backend)->stats().rows_evaluated, 0u);
}

TEST(ClusterSearch, NprobeResultsAreRealCandidatesWithTrueCosts) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 30);
  ThreadPool pool(2);
  const std::size_t count = 120;
  const std::vector<float> features = make_queries(db, count, 21);
  const std::vector<QueryParams> params = make_params(db, count, 22);
  ReferenceSearch reference(db);
  std::vector<Match> exact(count);
  ASSERT_TRUE(reference.search({features, params, count}, 1, exact).ok());
  std::size_t previous_hits = 0;
  for (std::uint32_t nprobe : {1u, 4u, 16u}) {
    auto backend = ClusterSearch::create(db, table, pool, {.nprobe = nprobe});
    ASSERT_TRUE(backend.ok());
    std::vector<Match> out(count);
    ASSERT_TRUE((*backend)->search({features, params, count}, 1, out).ok());
    std::size_t hits = 0;
    for (std::size_t i = 0; i < count; ++i) {
      hits += out[i].frame == exact[i].frame;
      if (out[i].frame == kNoFrame) continue;
      EXPECT_TRUE(is_candidate(db, out[i].frame, params[i]));
      EXPECT_EQ(out[i].cost, frame_cost(db, out[i].frame, {features.data() + i * db.dims(), db.dims()}, params[i]));
      EXPECT_FALSE(match_less(out[i], exact[i])) << "nprobe cannot beat exact";
    }
    EXPECT_GE(hits, previous_hits) << "more probes, no fewer exact hits (nprobe " << nprobe << ")";
    previous_hits = hits;
  }
}

TEST(ClusterSearch, CountsRowsAndPrunes) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 45);
  ThreadPool pool(2);
  auto backend = ClusterSearch::create(db, table, pool);
  ASSERT_TRUE(backend.ok());
  const std::size_t count = 90;
  std::vector<float> features = make_queries(db, count, 31);
  std::vector<Match> out(count);
  ASSERT_TRUE((*backend)->search({features, {}, count}, 1, out).ok());
  const SearchStats stats = (*backend)->stats();
  EXPECT_EQ(stats.queries, count);
  EXPECT_GT(stats.rows_evaluated, 0u);
  EXPECT_LT(stats.rows_fraction(db.frame_count()), 0.5);
  (*backend)->reset_stats();
  EXPECT_EQ((*backend)->stats().rows_evaluated, 0u);
}

// One tile module serves both CPU backends: they pick the same kernels, the
// widest this CPU runs, and the baseline when asked.
TEST(ClusterSearch, PicksTheSameKernelsAsFastSearch) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 10);
  ThreadPool pool(1);
  for (bool baseline : {false, true}) {
    const CpuKernels kernels = baseline ? CpuKernels::Generic : CpuKernels::Widest;
    auto clusters = ClusterSearch::create(db, table, pool, {.kernels = kernels});
    ASSERT_TRUE(clusters.ok());
    auto fast = FastSearch::create(db, pool, {.kernels = kernels});
    ASSERT_TRUE(fast.ok());
    EXPECT_EQ((*clusters)->kernel_name(), (*fast)->kernel_name());
    std::string expected = "generic";
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    if (!baseline && __builtin_cpu_supports("avx512f")) {
      expected = "avx512f";
    } else if (!baseline && __builtin_cpu_supports("avx2")) {
      expected = "avx2";
    }
#endif
    EXPECT_EQ((*clusters)->kernel_name(), expected) << "baseline " << baseline;
  }
}

TEST(ClusterSearch, BadInputIsAnError) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 10);
  ThreadPool pool(1);
  auto backend = ClusterSearch::create(db, table, pool);
  ASSERT_TRUE(backend.ok());
  std::vector<float> features = make_queries(db, 2, 1);
  std::vector<Match> out(2);
  // Wrong query dimension.
  std::vector<float> short_features(features.begin(), features.end() - 1);
  EXPECT_FALSE((*backend)->search({short_features, {}, 2}, 1, out).ok());
  // NaN in a query.
  features[3] = std::nanf("");
  const Status nan = (*backend)->search({features, {}, 2}, 1, out);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.message().find("not finite"), std::string::npos) << nan.message();
  features[3] = 0.0f;
  // k out of range.
  std::vector<Match> many(2 * 17);
  EXPECT_FALSE((*backend)->search({features, {}, 2}, 17, many).ok());
  std::vector<Match> none;
  EXPECT_FALSE((*backend)->search({features, {}, 2}, 0, none).ok());

  // A table from another database.
  test::ClusteredDataSpec spec;
  spec.seed = 99;
  const Database other = clustered_database(spec);
  auto mismatched = ClusterSearch::create(other, table, pool);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.message().find("another database"), std::string::npos) << mismatched.message();
}

// The exact paths against the reference, under every constraint and bias:
// the grouped batch (sub-batches of 512 queries per thread, so 1100 queries
// on 2 threads cross a sub-batch boundary), the span boxes (few clusters, so
// clusters hold many 16-tile spans), batches smaller than the pool, and each
// path alone.
TEST(ClusterSearch, GroupedAndSpannedPathsMatchTheReference) {
  test::ClusteredDataSpec spec;
  spec.frames = 6000;
  const Database db = clustered_database(spec);
  ReferenceSearch reference(db);
  const ConstrainedQueries queries = constrained_queries(db, 1100, 21);
  const std::size_t count = queries.count;
  const std::vector<float>& features = queries.features;
  const std::vector<QueryParams>& params = queries.params;
  const Variant variants[] = {
      {"all on", {}},
      {"grouped only", {.span_bound = false}},
      {"spans only", {.span_bound = true, .batch_by_cluster = false}},
      {"all off", {.span_bound = false, .batch_by_cluster = false}},
      {"all on, no seed", {.seed_nearest = false}},
      {"all on, float rows", {.half_filter = false}},
  };
  // 150 clusters: five groups of 32 in the group level above the clusters.
  for (const std::uint32_t clusters : {3u, 40u, 150u}) {
    const ClusterTable table = make_table(db, clusters);
    for (const unsigned threads : {1u, 2u, 3u}) {
      ThreadPool pool(threads);
      for (const std::uint32_t k : {1u, 4u}) {
        // The whole batch (grouped path), then the first 36 queries one at a
        // time and 2 at a time (fewer queries than threads).
        std::vector<Match> expected(count * k);
        ASSERT_TRUE(reference.search({features, params, count}, k, expected).ok());
        for (const Variant& variant : variants) {
          const std::string what = std::string(variant.name) + " clusters=" + std::to_string(clusters) +
                                   " threads=" + std::to_string(threads) + " k=" + std::to_string(k);
          auto backend = ClusterSearch::create(db, table, pool, variant.options);
          ASSERT_TRUE(backend.ok()) << backend.message();
          std::vector<Match> actual(count * k);
          ASSERT_TRUE((*backend)->search({features, params, count}, k, actual).ok());
          expect_identical(expected, actual, k, what + " batch");
          for (std::size_t size : {std::size_t{1}, std::size_t{2}}) {
            for (std::size_t first = 0; first + size <= 36; first += size) {
              const QueryBatch part{std::span<const float>(features).subspan(first * db.dims(), size * db.dims()),
                                    std::span<const QueryParams>(params).subspan(first, size), size};
              std::vector<Match> one(size * k);
              ASSERT_TRUE((*backend)->search(part, k, one).ok());
              expect_identical(std::span<const Match>(expected).subspan(first * k, size * k), one, k,
                               what + " B=" + std::to_string(size) + " from query " + std::to_string(first));
            }
          }
        }
      }
    }
  }
}

// nprobe runs the grouped path too: the exact best over the nprobe nearest
// clusters, so the same lists as the one-query walk, under every constraint.
TEST(ClusterSearch, GroupedNprobeEqualsTheOneQueryWalk) {
  const Database db = clustered_database();
  ThreadPool pool(2);
  const ConstrainedQueries queries = constrained_queries(db, 700, 41);
  // 150 clusters: the clusters are reordered into groups of 32 inside the
  // backend and the probed set is found group by group; without box bounds
  // the group level is off and every centroid is ranked, so equal lists
  // show the same probed set.
  for (const std::uint32_t clusters : {30u, 150u}) {
    const ClusterTable table = make_table(db, clusters);
    for (const std::uint32_t nprobe : {1u, 3u, 7u, 29u, 40u}) {
      for (const std::uint32_t k : {1u, 5u}) {
        auto grouped = ClusterSearch::create(db, table, pool, {.nprobe = nprobe});
        auto walk = ClusterSearch::create(db, table, pool, {.nprobe = nprobe, .batch_by_cluster = false});
        auto ranked = ClusterSearch::create(db, table, pool, {.nprobe = nprobe, .box_bound = false});
        ASSERT_TRUE(grouped.ok() && walk.ok() && ranked.ok());
        std::vector<Match> expected(queries.count * k);
        std::vector<Match> actual(queries.count * k);
        std::vector<Match> by_rank(queries.count * k);
        ASSERT_TRUE((*walk)->search(queries.batch(), k, expected).ok());
        ASSERT_TRUE((*grouped)->search(queries.batch(), k, actual).ok());
        ASSERT_TRUE((*ranked)->search(queries.batch(), k, by_rank).ok());
        const std::string what =
            "clusters=" + std::to_string(clusters) + " nprobe=" + std::to_string(nprobe) + " k=" + std::to_string(k);
        expect_identical(expected, actual, k, what);
        expect_identical(expected, by_rank, k, what + " against every centroid ranked");
      }
    }
  }
}

// Blobs of zero spread: many clusters share a centroid, so nprobe's
// distances tie and the probed set rests on the tie rule (the caller's lower
// cluster id), with and without the group level.
TEST(ClusterSearch, NprobeTiesGoToTheLowerClusterId) {
  const Database db = zero_spread_database(1200, 6);
  const ClusterTable table = make_table(db, 70);
  ThreadPool pool(2);
  const std::size_t count = 60;
  const std::vector<float> features = make_queries(db, count, 9);
  for (const std::uint32_t nprobe : {1u, 2u, 5u, 20u}) {
    const std::uint32_t k = 4;
    auto grouped = ClusterSearch::create(db, table, pool, {.nprobe = nprobe});
    auto ranked = ClusterSearch::create(db, table, pool, {.nprobe = nprobe, .box_bound = false});
    ASSERT_TRUE(grouped.ok() && ranked.ok());
    std::vector<Match> expected(count * k);
    std::vector<Match> actual(count * k);
    ASSERT_TRUE((*ranked)->search({features, {}, count}, k, expected).ok());
    ASSERT_TRUE((*grouped)->search({features, {}, count}, k, actual).ok());
    expect_identical(expected, actual, k, "ties nprobe=" + std::to_string(nprobe));
  }
}

// Every instruction set this CPU runs, forced, in both CPU backends, against
// the reference; a set the CPU lacks is refused by create().
TEST(CpuKernels, EveryInstructionSetTheCpuRunsMatchesTheReference) {
  const Database db = clustered_database();
  const ClusterTable table = make_table(db, 25);
  ThreadPool pool(2);
  ReferenceSearch reference(db);
  const ConstrainedQueries queries = constrained_queries(db, 120, 31);
  const std::size_t count = queries.count;
  const QueryBatch batch = queries.batch();
  const std::uint32_t k = 3;
  std::vector<Match> expected(count * k);
  ASSERT_TRUE(reference.search(batch, k, expected).ok());
  struct Set {
    CpuKernels set;
    const char* name;
    bool runs;
  };
  bool avx2 = false;
  bool avx512 = false;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  avx2 = __builtin_cpu_supports("avx2");
  avx512 = __builtin_cpu_supports("avx512f");
#endif
  const Set sets[] = {{CpuKernels::Generic, "generic", true},
                      {CpuKernels::Avx2, "avx2", avx2},
                      {CpuKernels::Avx512, "avx512f", avx512}};
  for (const Set& set : sets) {
    auto clusters = ClusterSearch::create(db, table, pool, {.kernels = set.set});
    auto brute = FastSearch::create(db, pool, {.prune = false, .kernels = set.set});
    auto box = FastSearch::create(db, pool, {.prune = true, .kernels = set.set});
    if (!set.runs) {
      EXPECT_FALSE(clusters.ok()) << set.name;
      EXPECT_FALSE(brute.ok()) << set.name;
      std::printf("[ info ] %s: not run by this CPU, refused as expected\n", set.name);
      continue;
    }
    ASSERT_TRUE(clusters.ok()) << clusters.message();
    ASSERT_TRUE(brute.ok()) << brute.message();
    ASSERT_TRUE(box.ok()) << box.message();
    EXPECT_EQ((*clusters)->kernel_name(), set.name);
    EXPECT_EQ((*brute)->kernel_name(), set.name);
    for (SearchBackend* backend : {static_cast<SearchBackend*>(clusters->get()), static_cast<SearchBackend*>(brute->get()),
                                   static_cast<SearchBackend*>(box->get())}) {
      std::vector<Match> actual(count * k);
      ASSERT_TRUE(backend->search(batch, k, actual).ok());
      expect_identical(expected, actual, k, std::string(set.name) + " " + std::string(backend->name()));
    }
  }
  // The widest set is the one picked by default where the CPU has it.
  auto widest = ClusterSearch::create(db, table, pool);
  ASSERT_TRUE(widest.ok());
  EXPECT_EQ((*widest)->kernel_name(), avx512 ? "avx512f" : avx2 ? "avx2" : "generic");
}

}  // namespace
}  // namespace mmvk
