// The typed test suite every search backend instantiates. It checks a
// backend against ReferenceSearch: the same frames and bit-identical costs
// (compared as bit patterns, never with a tolerance), on random data, every
// constraint and bias, ties, k > 1, several batch sizes and bad input.
//
// A backend is described by a factory, a default-constructible struct that
// owns whatever the backend needs (a thread pool, cluster tables, a Vulkan
// context) and builds it for a database:
//
//   struct MyFactory {
//     mmvk::Result<std::unique_ptr<mmvk::SearchBackend>> make(const mmvk::Database& db);
//     // Optional: a non-empty reason skips the test (e.g. no Vulkan device
//     // and MMVK_REQUIRE_VULKAN unset; fail instead when it is set).
//     std::string skip_reason();
//   };
//   using MyBackends = ::testing::Types<MyFactory>;
//   INSTANTIATE_TYPED_TEST_SUITE_P(My, BackendSuite, MyBackends);
//
// make() may be called several times in one test, for different databases,
// while backends it returned earlier are still alive: keep what each backend
// needs (cluster tables, uploads) alive with it, e.g. in a std::vector.
// Sizes stay in the thousands of frames so software Vulkan runs it quickly.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/database/database.hpp"
#include "mmvk/search/reference_search.hpp"
#include "mmvk/search/search.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::test {

// ---------------------------------------------------------------------------
// The suite

template <class Factory>
class BackendSuite : public ::testing::Test {
 protected:
  void SetUp() override {
    if constexpr (requires(Factory& f) { f.skip_reason(); }) {
      const std::string reason = factory_.skip_reason();
      if (!reason.empty()) GTEST_SKIP() << reason;
    }
  }

  std::unique_ptr<SearchBackend> make(const Database& db) {
    Result<std::unique_ptr<SearchBackend>> backend = factory_.make(db);
    if (!backend.ok()) {
      ADD_FAILURE() << "cannot create the backend: " << backend.message();
      return nullptr;
    }
    return std::move(backend).value();
  }

  // Searches with the backend and the reference and expects identical lists.
  void check(const Database& db, std::span<const float> features, std::span<const QueryParams> params,
             std::size_t count, std::uint32_t k) {
    std::unique_ptr<SearchBackend> backend = make(db);
    ASSERT_NE(backend, nullptr);
    const std::vector<Match> expected = reference_results(db, features, params, count, k);
    const std::vector<Match> actual = run_search(*backend, features, params, count, k);
    expect_identical(expected, actual, k, params, backend->name());
  }

  Factory factory_;
};

TYPED_TEST_SUITE_P(BackendSuite);

TYPED_TEST_P(BackendSuite, RandomDataMatchesReference) {
  const Database db = synthetic_database({.frames = 2000, .seed = 11});
  const std::vector<float> queries = synthetic_queries(db, 64, 12);
  this->check(db, queries, {}, 64, 1);
  this->check(db, queries, {}, 64, 5);
}

TYPED_TEST_P(BackendSuite, OddChannelSizesMatchReference) {
  const Database db = synthetic_database({.frames = 1500, .seed = 13, .channel_dims = {1, 7, 2, 5}});
  const std::vector<float> queries = synthetic_queries(db, 33, 14);
  this->check(db, queries, {}, 33, 3);
}

TYPED_TEST_P(BackendSuite, FindsTheUniqueMinimum) {
  const Database db = synthetic_database({.frames = 2500, .seed = 15});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<std::uint32_t> frames = {0, 1, 17, 255, 256, 1234, 2499};
  std::vector<float> queries;
  for (std::uint32_t f : frames) queries.insert(queries.end(), db.row(f).begin(), db.row(f).end());
  const std::vector<Match> out = run_search(*backend, queries, {}, frames.size(), 2);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(out[i * 2].frame, frames[i]);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out[i * 2].cost), 0u) << "an exact match costs +0";
    EXPECT_GT(out[i * 2 + 1].cost, 0.0f);
  }
}

TYPED_TEST_P(BackendSuite, FlagsAreNeverResultsUnlessContinued) {
  const Database db = synthetic_database({.frames = 3000, .seed = 17, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  // A query equal to a do-not-use, an edge-excluded and a block-transition row.
  const Clip& clip = db.clips()[2];
  const std::vector<std::uint32_t> frames = {clip.first_frame + 6, clip.first_frame + clip.frame_count - 1,
                                             clip.first_frame + 21};
  ASSERT_NE(db.frame_flags()[frames[1]] & kFrameEdgeExcluded, 0u);
  std::vector<float> queries;
  for (std::uint32_t f : frames) queries.insert(queries.end(), db.row(f).begin(), db.row(f).end());
  std::vector<QueryParams> params(3);
  const std::vector<Match> out = run_search(*backend, queries, params, 3, 4);
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_NE(out[i].frame, kNoFrame);
    EXPECT_EQ(db.frame_flags()[out[i].frame] & (kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition), 0u)
        << "frame " << out[i].frame;
  }
  // The block-transition row is a result as the continuing frame.
  params[2].continuing_frame = frames[2];
  const std::vector<Match> continued = run_search(*backend, queries, params, 3, 4);
  EXPECT_EQ(continued[2 * 4].frame, frames[2]);
  // A do-not-use continuing frame is still not a candidate.
  params[0].continuing_frame = frames[0];
  params[0].continuing_bias = -1000.0f;
  const std::vector<Match> not_usable = run_search(*backend, queries, params, 3, 4);
  EXPECT_NE(not_usable[0].frame, frames[0]);
  expect_identical(reference_results(db, queries, params, 3, 4), not_usable, 4, params, backend->name());
}

TYPED_TEST_P(BackendSuite, BlockTransitionWithAndWithoutContinuingFrame) {
  const Database db = synthetic_database({.frames = 3000, .seed = 19, .constraints = true});
  std::vector<float> queries;
  std::vector<QueryParams> params;
  for (const Clip& clip : db.clips()) {
    if (clip.frame_count < 30) continue;
    for (std::uint32_t f = clip.first_frame + 19; f < clip.first_frame + 26; ++f) {
      queries.insert(queries.end(), db.row(f).begin(), db.row(f).end());
      QueryParams p;
      if (f % 2 == 0) p.continuing_frame = f;
      params.push_back(p);
    }
  }
  this->check(db, queries, params, params.size(), 3);
}

TYPED_TEST_P(BackendSuite, TagMasks) {
  const Database db = synthetic_database({.frames = 3000, .seed = 21, .constraints = true});
  const std::vector<float> queries = synthetic_queries(db, 16, 22);
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<std::pair<TagMask, TagMask>> masks = {
      {kTagWalk, 0}, {kTagRun, 0}, {kTagIdle | kTagRun, 0}, {0, kTagRun}, {0, kTagWalk | kTagIdle}, {kTagWalk, kTagRare}};
  for (const auto& [require, exclude] : masks) {
    std::vector<QueryParams> params(16);
    for (QueryParams& p : params) {
      p.require_all = require;
      p.exclude_any = exclude;
    }
    const std::vector<Match> out = run_search(*backend, queries, params, 16, 4);
    for (const Match& m : out) {
      ASSERT_NE(m.frame, kNoFrame);
      const TagMask tags = db.frame_tags()[m.frame];
      EXPECT_EQ(tags & require, require);
      EXPECT_EQ(tags & exclude, 0u);
    }
    expect_identical(reference_results(db, queries, params, 16, 4), out, 4, params, backend->name());
  }
}

// Tags in either 32-bit word, or on no frame at all (the Vulkan scan tests
// only the words some frame uses), with rules no row can pass: a tag both
// required and excluded, a required tag no frame holds in either word. Once
// with every cost multiplier 1 and bias 0 (the Vulkan scan then skips the
// cost terms).
TYPED_TEST_P(BackendSuite, TagsInEitherWordOrNone) {
  const std::pair<int, bool> cases[] = {{-1, false}, {30, false}, {32, false}, {30, true}};  // -1: no frame is tagged
  for (const auto& [shift, unit_terms] : cases) {
    SCOPED_TRACE("tag shift " + std::to_string(shift) + (unit_terms ? ", unit cost terms" : ""));
    DatabaseParts parts = synthetic_parts({.frames = 2000, .seed = 45, .constraints = true});
    parts.tag_names.clear();
    for (int t = 0; t < 64; ++t) parts.tag_names.push_back("tag" + std::to_string(t));
    for (Clip& clip : parts.clips) {
      clip.tags = shift < 0 ? 0 : clip.tags << shift;
      if (unit_terms) {
        clip.cost_multiplier = 1.0f;
        clip.cost_bias = 0.0f;
      }
    }
    const Database db = make_database(std::move(parts));
    const int s = std::max(shift, 0);
    const TagMask walk = kTagWalk << s, run = kTagRun << s, idle = kTagIdle << s;
    const std::vector<std::pair<TagMask, TagMask>> masks = {
        {walk, 0}, {idle | run, 0}, {0, run}, {walk, walk}, {TagMask{1} << 63, 0}, {TagMask{1} << 5, idle}, {0, 0}};
    std::vector<QueryParams> params(64);
    for (std::size_t q = 0; q < params.size(); ++q) {
      params[q].require_all = masks[q % masks.size()].first;
      params[q].exclude_any = masks[q % masks.size()].second;
    }
    const std::vector<float> queries = synthetic_queries(db, params.size(), 46);
    this->check(db, queries, params, params.size(), 1);
    this->check(db, queries, params, params.size(), 4);
  }
}

TYPED_TEST_P(BackendSuite, ExclusionWindowWrapsInLoopingClips) {
  const Database db = synthetic_database({.frames = 3000, .seed = 23, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const Clip& looping = db.clips()[3];  // clip 3 loops, clip 4 does not
  const Clip& straight = db.clips()[4];
  ASSERT_TRUE(looping.loop);
  ASSERT_FALSE(straight.loop);
  // Continuing at the clip's second frame; the query is the clip's
  // next-to-last frame: 3 frames away through the wrap.
  const std::uint32_t wrapped_target = looping.first_frame + looping.frame_count - 2;
  const std::uint32_t straight_target = straight.first_frame + 40;
  std::vector<float> queries;
  for (std::uint32_t f : {wrapped_target, wrapped_target, straight_target, straight_target}) {
    queries.insert(queries.end(), db.row(f).begin(), db.row(f).end());
  }
  std::vector<QueryParams> params(4);
  params[0].continuing_frame = looping.first_frame + 1;
  params[0].exclusion_window = 3;  // excludes the target through the wrap
  params[1].continuing_frame = looping.first_frame + 1;
  params[1].exclusion_window = 2;  // does not reach it
  params[2].continuing_frame = straight.first_frame + 36;
  params[2].exclusion_window = 4;  // excludes the target
  params[3].continuing_frame = straight.first_frame + 36;
  params[3].exclusion_window = 3;
  const std::vector<Match> out = run_search(*backend, queries, params, 4, 2);
  EXPECT_NE(out[0].frame, wrapped_target);
  EXPECT_EQ(out[2].frame, wrapped_target);
  EXPECT_NE(out[4].frame, straight_target);
  EXPECT_EQ(out[6].frame, straight_target);
  expect_identical(reference_results(db, queries, params, 4, 2), out, 2, params, backend->name());
  // The continuing frame itself stays a candidate inside its window.
  std::vector<float> self(db.row(params[0].continuing_frame).begin(), db.row(params[0].continuing_frame).end());
  QueryParams p = params[0];
  p.exclusion_window = 10;
  const std::vector<Match> own = run_search(*backend, self, std::span<const QueryParams>(&p, 1), 1, 1);
  EXPECT_EQ(own[0].frame, p.continuing_frame);
}

TYPED_TEST_P(BackendSuite, MultiplierAndBiasEnterTheCost) {
  const Database db = synthetic_database({.frames = 3000, .seed = 25, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 64, 26);
  const std::vector<Match> out = run_search(*backend, queries, {}, 64, 3);
  const QueryParams defaults;
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_NE(out[i].frame, kNoFrame);
    const float cost = frame_cost(db, out[i].frame, std::span<const float>(queries).subspan(i / 3 * db.dims(), db.dims()), defaults);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out[i].cost), std::bit_cast<std::uint32_t>(cost)) << "frame " << out[i].frame;
  }
  this->check(db, queries, {}, 64, 3);
}

TYPED_TEST_P(BackendSuite, ContinuingBiasNegativeAndPositive) {
  const Database db = synthetic_database({.frames = 3000, .seed = 27, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 8, 28, 0.05f);
  std::vector<QueryParams> stay(8), leave(8);
  for (std::size_t q = 0; q < 8; ++q) {
    stay[q].continuing_frame = db.clips()[6].first_frame + 30 + static_cast<std::uint32_t>(q);
    stay[q].continuing_bias = -1.0e6f;
    leave[q] = stay[q];
    leave[q].continuing_bias = 1.0e6f;
  }
  const std::vector<Match> stayed = run_search(*backend, queries, stay, 8, 2);
  const std::vector<Match> left = run_search(*backend, queries, leave, 8, 16);
  for (std::size_t q = 0; q < 8; ++q) {
    EXPECT_EQ(stayed[q * 2].frame, stay[q].continuing_frame);
    for (std::size_t r = 0; r < 16; ++r) EXPECT_NE(left[q * 16 + r].frame, leave[q].continuing_frame);
  }
  expect_identical(reference_results(db, queries, stay, 8, 2), stayed, 2, stay, backend->name());
  expect_identical(reference_results(db, queries, leave, 8, 16), left, 16, leave, backend->name());
  // Small biases of both signs, where the continuing frame competes.
  std::vector<QueryParams> close(8);
  for (std::size_t q = 0; q < 8; ++q) {
    close[q].continuing_frame = stay[q].continuing_frame;
    close[q].continuing_bias = q % 2 == 0 ? -0.5f : 0.5f;
  }
  this->check(db, queries, close, 8, 4);
}

// The continuing frame's cost is (multiplier * total + bias) *
// continuing_multiplier + continuing_bias, each step rounded: a multiplier
// of 0 leaves only the bias (staying wins), others compete.
TYPED_TEST_P(BackendSuite, ContinuingMultiplierScalesBeforeTheBias) {
  const Database db = synthetic_database({.frames = 3000, .seed = 31, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  constexpr std::size_t kCount = 16;
  const std::vector<float> queries = synthetic_queries(db, kCount, 32, 0.05f);
  std::vector<QueryParams> params(kCount);
  const float multipliers[] = {0.0f, 0.5f, 0.9f, 1.0f, 1.1f, 2.0f, 0.25f, 4.0f};
  for (std::size_t q = 0; q < kCount; ++q) {
    params[q].continuing_frame = db.clips()[5].first_frame + 10 + static_cast<std::uint32_t>(7 * q);
    params[q].continuing_multiplier = multipliers[q % 8];
    params[q].continuing_bias = q < 8 ? -1.0e-3f : 0.25f;
  }
  const std::vector<Match> got = run_search(*backend, queries, params, kCount, 4);
  expect_identical(reference_results(db, queries, params, kCount, 4), got, 4, params, backend->name());
  for (std::size_t q = 0; q < kCount; ++q) {
    const std::span<const float> query = std::span<const float>(queries).subspan(q * db.dims(), db.dims());
    if (params[q].continuing_multiplier == 0.0f && q < 8 && is_candidate(db, params[q].continuing_frame, params[q])) {
      EXPECT_EQ(got[q * 4].frame, params[q].continuing_frame) << describe(params[q]);
    }
    for (std::size_t r = 0; r < 4; ++r) {
      if (got[q * 4 + r].frame != params[q].continuing_frame) continue;
      QueryParams plain = params[q];
      plain.continuing_frame = kNoFrame;
      float expected = frame_cost(db, params[q].continuing_frame, query, plain);
      expected = expected * params[q].continuing_multiplier;
      expected = expected + params[q].continuing_bias;
      EXPECT_EQ(std::bit_cast<std::uint32_t>(got[q * 4 + r].cost), std::bit_cast<std::uint32_t>(expected))
          << describe(params[q]);
    }
  }
}

TYPED_TEST_P(BackendSuite, ChannelWeightsIncludingZero) {
  const Database db = synthetic_database({.frames = 3000, .seed = 29});
  const std::vector<float> queries = synthetic_queries(db, 24, 30);
  std::vector<QueryParams> params(24);
  for (std::size_t q = 0; q < 24; ++q) {
    for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
      params[q].channel_weights[c] = (q + c) % 3 == 0 ? 0.0f : float((q + c) % 5) * 0.5f;
    }
  }
  // A pose-only query: every channel but the first off.
  params[0].channel_weights.fill(0.0f);
  params[0].channel_weights[0] = 1.0f;
  // Every channel off: every cost is mult * 0 + bias, ties everywhere.
  params[1].channel_weights.fill(0.0f);
  this->check(db, queries, params, 24, 4);
}

TYPED_TEST_P(BackendSuite, TiesGoToTheLowerFrameId) {
  DatabaseParts parts = synthetic_parts({.frames = 3000, .seed = 31});
  const std::uint32_t dims = parts.schema.dims();
  // The same row at frames 2900, 1000, 40 and 700 (written in that order).
  const std::vector<std::uint32_t> copies = {2900, 1000, 40, 700};
  for (std::uint32_t f : copies) {
    std::copy_n(parts.features.begin() + std::ptrdiff_t{1500} * dims, dims, parts.features.begin() + std::ptrdiff_t{f} * dims);
  }
  const Database db = make_database(std::move(parts));
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  std::vector<float> query(db.row(1500).begin(), db.row(1500).end());
  const std::vector<Match> out = run_search(*backend, query, {}, 1, 6);
  const std::vector<std::uint32_t> expected = {40, 700, 1000, 1500, 2900};
  for (std::size_t r = 0; r < expected.size(); ++r) {
    EXPECT_EQ(out[r].frame, expected[r]) << "rank " << r;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out[r].cost), 0u);
  }
  // The continuing frame (bias 0) ties with lower copies: they still win,
  // even though a backend may evaluate the continuing frame first. (A batch
  // of 4, so that multi-threaded backends split queries, not rows.)
  std::vector<float> four;
  for (int i = 0; i < 4; ++i) four.insert(four.end(), query.begin(), query.end());
  std::vector<QueryParams> continuing(4);
  for (QueryParams& p : continuing) p.continuing_frame = 2900;
  continuing[1].continuing_frame = 1000;
  continuing[2].continuing_frame = 40;
  continuing[2].continuing_bias = -0.0f;
  continuing[3].continuing_frame = 700;
  const std::vector<Match> with_continuing = run_search(*backend, four, continuing, 4, 2);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(with_continuing[i * 2].frame, 40u) << "query " << i;
    EXPECT_EQ(with_continuing[i * 2 + 1].frame, 700u) << "query " << i;
  }
  // A near copy: ties at a non-zero cost, still by frame id.
  for (float& v : query) v += 0.125f;
  const std::vector<Match> shifted = run_search(*backend, query, {}, 1, 6);
  expect_identical(reference_results(db, query, {}, 1, 6), shifted, 6, {}, backend->name());
  EXPECT_EQ(shifted[0].frame, 40u);
  // All weights 0: every frame costs +0; the best k are frames 0..k-1.
  QueryParams flat;
  flat.channel_weights.fill(0.0f);
  const std::vector<Match> all_tied = run_search(*backend, query, std::span<const QueryParams>(&flat, 1), 1, 16);
  for (std::uint32_t r = 0; r < 16; ++r) EXPECT_EQ(all_tied[r].frame, r);
}

// Every frame ties at +0 when every weight is 0, so a query's answers are
// the lowest frames its exclusion window leaves. A backend may treat the
// rows some query of a batch skips apart from the others (the Vulkan brute
// force scans them in a loop of their own, with the skip tests): ties must
// still go to the lower frame across both. Queries 1-7 skip frames near the
// start, which query 0 (its window elsewhere) and 8-23 need; a few keep
// their weights.
TYPED_TEST_P(BackendSuite, TiesAroundExclusionWindows) {
  const Database db = synthetic_database({.frames = 3000, .seed = 35, .constraints = true});
  const std::vector<float> queries = synthetic_queries(db, 24, 36);
  std::vector<QueryParams> params(24);
  for (std::uint32_t q = 0; q < 24; ++q) {
    params[q].continuing_frame = q == 0 ? 500 : q < 8 ? q * 3 : (q * 397) % db.frame_count();
    params[q].exclusion_window = 2 + (q % 5) * 9;
    if (q % 6 != 5) params[q].channel_weights.fill(0.0f);
  }
  this->check(db, queries, params, 24, 1);
  this->check(db, queries, params, 24, 4);
}

TYPED_TEST_P(BackendSuite, KGreaterThanOneAndNonePadding) {
  const Database db = synthetic_database({.frames = 3000, .seed = 33, .constraints = true});
  const std::vector<float> queries = synthetic_queries(db, 32, 34);
  this->check(db, queries, {}, 32, 16);
  // Only clip 1 (10 frames, all candidates) holds kTagRare: k = 16 leaves
  // none padding after its candidates.
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  std::vector<QueryParams> params(32);
  for (QueryParams& p : params) p.require_all = kTagRare;
  const std::vector<Match> out = run_search(*backend, queries, params, 32, 16);
  std::uint32_t rare_candidates = 0;
  for (std::uint32_t f = 0; f < db.frame_count(); ++f) rare_candidates += is_candidate(db, f, params[0]) ? 1 : 0;
  ASSERT_GT(rare_candidates, 0u);
  ASSERT_LT(rare_candidates, 16u);
  for (std::size_t q = 0; q < 32; ++q) {
    for (std::uint32_t r = 0; r < 16; ++r) {
      const Match& m = out[q * 16 + r];
      if (r < rare_candidates) {
        EXPECT_NE(m.frame, kNoFrame);
      } else {
        EXPECT_EQ(m, Match{}) << "query " << q << " rank " << r;
      }
    }
  }
  expect_identical(reference_results(db, queries, params, 32, 16), out, 16, params, backend->name());
}

TYPED_TEST_P(BackendSuite, NoCandidateReturnsNone) {
  const Database db = synthetic_database({.frames = 2000, .seed = 35, .constraints = true});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 3, 36);
  std::vector<QueryParams> params(3);
  params[0].require_all = kTagUnused;
  params[1].require_all = kTagRare;
  params[1].exclude_any = kTagWalk;
  params[2].exclude_any = kTagWalk | kTagRun;
  const std::vector<Match> out = run_search(*backend, queries, params, 3, 2);
  for (const Match& m : out) EXPECT_EQ(m, Match{});
}

TYPED_TEST_P(BackendSuite, BatchSizes) {
  const Database db = synthetic_database({.frames = 2500, .clips = 20, .seed = 37, .constraints = true});
  for (std::size_t count : {std::size_t{1}, std::size_t{7}, std::size_t{64}, std::size_t{1024}}) {
    SCOPED_TRACE("batch size " + std::to_string(count));
    const std::vector<float> queries = synthetic_queries(db, count, 38 + count);
    const std::vector<QueryParams> params = random_params(db, count, 39 + count);
    this->check(db, queries, params, count, count == 1024 ? 1 : 4);
    if (count <= 64) this->check(db, queries, {}, count, 1);
  }
}

TYPED_TEST_P(BackendSuite, RandomParamsAndKMatchReference) {
  const Database db = synthetic_database({.frames = 3000, .seed = 41, .constraints = true});
  const std::vector<float> queries = synthetic_queries(db, 64, 42);
  const std::vector<QueryParams> params = random_params(db, 64, 43);
  for (std::uint32_t k : {1u, 2u, 7u, 16u}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    this->check(db, queries, params, 64, k);
  }
}

TYPED_TEST_P(BackendSuite, RepeatedCallsAndStats) {
  const Database db = synthetic_database({.frames = 2000, .seed = 45});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::vector<float> queries = synthetic_queries(db, 10, 46);
  const std::vector<Match> first = run_search(*backend, queries, {}, 10, 3);
  const std::vector<Match> second = run_search(*backend, queries, {}, 10, 3);
  expect_identical(first, second, 3, {}, backend->name());
  const SearchStats stats = backend->stats();
  EXPECT_EQ(stats.queries, 20u);
  EXPECT_GT(stats.rows_evaluated, 0u);
  EXPECT_LE(stats.rows_fraction(db.frame_count()), 1.0 + 1e-9);
  backend->reset_stats();
  EXPECT_EQ(backend->stats().queries, 0u);
  // An empty batch is valid and leaves everything untouched.
  std::vector<Match> none;
  EXPECT_TRUE(backend->search(QueryBatch{{}, {}, 0}, 1, none).ok());
}

TYPED_TEST_P(BackendSuite, BadInputIsAnError) {
  const Database db = synthetic_database({.frames = 1000, .seed = 47});
  std::unique_ptr<SearchBackend> backend = this->make(db);
  ASSERT_NE(backend, nullptr);
  const std::uint32_t dims = db.dims();
  std::vector<float> queries = synthetic_queries(db, 2, 48);
  std::vector<Match> out(2);
  auto error_of = [&](std::span<const float> features, std::span<const QueryParams> params, std::size_t count,
                      std::uint32_t k, std::span<Match> results) {
    const Status status = backend->search(QueryBatch{features, params, count}, k, results);
    return status.ok() ? std::string("<ok>") : status.message();
  };
  // Wrong query dimension.
  EXPECT_NE(error_of(std::span<const float>(queries).first(2 * dims - 1), {}, 2, 1, out).find("dims"), std::string::npos);
  // NaN and infinity in a query name the query and the dimension.
  queries[dims + 4] = std::numeric_limits<float>::quiet_NaN();
  const std::string nan_error = error_of(queries, {}, 2, 1, out);
  EXPECT_NE(nan_error.find("query 1"), std::string::npos) << nan_error;
  EXPECT_NE(nan_error.find("not finite"), std::string::npos) << nan_error;
  queries[dims + 4] = std::numeric_limits<float>::infinity();
  EXPECT_NE(error_of(queries, {}, 2, 1, out).find("not finite"), std::string::npos);
  queries[dims + 4] = 0.0f;
  // k out of range.
  std::vector<Match> big(2 * 17);
  EXPECT_NE(error_of(queries, {}, 2, 0, {}).find("k = 0"), std::string::npos);
  EXPECT_NE(error_of(queries, {}, 2, 17, big).find("k = 17"), std::string::npos);
  // Result span of the wrong size.
  EXPECT_NE(error_of(queries, {}, 2, 2, out).find("result"), std::string::npos);
  // Params: wrong count, continuing frame out of range, bad weights and bias.
  std::vector<QueryParams> params(2);
  EXPECT_NE(error_of(queries, std::span<const QueryParams>(params).first(1), 2, 1, out).find("params"), std::string::npos);
  params[1].continuing_frame = db.frame_count();
  EXPECT_NE(error_of(queries, params, 2, 1, out).find("continuing_frame"), std::string::npos);
  params[1] = QueryParams{};
  params[0].channel_weights[1] = -1.0f;
  EXPECT_NE(error_of(queries, params, 2, 1, out).find("channel1"), std::string::npos);
  params[0] = QueryParams{};
  params[0].continuing_bias = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_of(queries, params, 2, 1, out).find("continuing_bias"), std::string::npos);
  params[0] = QueryParams{};
  params[0].continuing_multiplier = -0.5f;
  EXPECT_NE(error_of(queries, params, 2, 1, out).find("continuing_multiplier"), std::string::npos);
  params[0].continuing_multiplier = std::numeric_limits<float>::infinity();
  EXPECT_NE(error_of(queries, params, 2, 1, out).find("continuing_multiplier"), std::string::npos);
  // Still usable after errors.
  params[0] = QueryParams{};
  EXPECT_EQ(error_of(queries, params, 2, 1, out), "<ok>");
}

REGISTER_TYPED_TEST_SUITE_P(BackendSuite, RandomDataMatchesReference, OddChannelSizesMatchReference,
                            FindsTheUniqueMinimum, FlagsAreNeverResultsUnlessContinued,
                            BlockTransitionWithAndWithoutContinuingFrame, TagMasks, TagsInEitherWordOrNone,
                            ExclusionWindowWrapsInLoopingClips, MultiplierAndBiasEnterTheCost,
                            ContinuingBiasNegativeAndPositive, ContinuingMultiplierScalesBeforeTheBias,
                            ChannelWeightsIncludingZero, TiesGoToTheLowerFrameId,
                            TiesAroundExclusionWindows, KGreaterThanOneAndNonePadding, NoCandidateReturnsNone, BatchSizes,
                            RandomParamsAndKMatchReference, RepeatedCallsAndStats, BadInputIsAnError);

}  // namespace mmvk::test
