// The typed backend suite on real features: the Bandai locomotion set
// (bandai-namco-nc/locomotion-normal, ~22k frames, default schema), built
// once per test program. Same factories and the same bit-exact comparison
// with ReferenceSearch as backend_suite.hpp; instantiate it from a test in
// tests/data/ (or tests/vulkan/ for backends that need a device):
//
//   INSTANTIATE_TYPED_TEST_SUITE_P(My, BackendDataSuite, MyBackends);
#pragma once

#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/search/reference_search.hpp"
#include "support/new_kinds_data.hpp"
#include "support/search_test_data.hpp"
#include "support/test_data.hpp"

namespace mmvk::test {

// The locomotion database, or nullptr (after a failure) when it cannot be
// built. Built on first use and kept for the program's lifetime.
inline const Database* locomotion_database(const std::filesystem::path& data) {
  static const std::unique_ptr<Database> db = build_locomotion(data, default_schema());
  return db.get();
}

// Queries from real rows: a frame's features plus noise ("continue"), and
// the pose channels of one frame with the trajectory channels of another
// ("transition"), alternating.
inline std::vector<float> real_queries(const Database& db, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.0f, 0.1f);
  std::uniform_int_distribution<std::uint32_t> frame(0, db.frame_count() - 1);
  std::vector<bool> trajectory(db.dims(), false);
  for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
    if (uses_trajectory_offsets(db.schema().channels[c].kind)) {
      const std::uint32_t offset = db.schema().offset(c);
      for (std::uint32_t d = 0; d < db.schema().channels[c].dims(); ++d) trajectory[offset + d] = true;
    }
  }
  std::vector<float> queries(count * db.dims());
  for (std::size_t q = 0; q < count; ++q) {
    const std::span<const float> pose = db.row(frame(rng));
    const std::span<const float> path = q % 2 == 0 ? pose : db.row(frame(rng));
    for (std::uint32_t d = 0; d < db.dims(); ++d) {
      queries[q * db.dims() + d] = (trajectory[d] ? path[d] : pose[d]) + (q % 2 == 0 ? normal(rng) : 0.0f);
    }
  }
  return queries;
}

template <class Factory>
class BackendDataSuite : public ::testing::Test {
 protected:
  void SetUp() override {
    if constexpr (requires(Factory& f) { f.skip_reason(); }) {
      const std::string reason = factory_.skip_reason();
      if (!reason.empty()) GTEST_SKIP() << reason;
    }
  }

  void check(const Database& db, std::span<const float> features, std::span<const QueryParams> params,
             std::size_t count, std::uint32_t k) {
    Result<std::unique_ptr<SearchBackend>> backend = factory_.make(db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    const std::vector<Match> expected = reference_results(db, features, params, count, k);
    const std::vector<Match> actual = run_search(**backend, features, params, count, k);
    expect_identical(expected, actual, k, params, (*backend)->name());
  }

  Factory factory_;
};

TYPED_TEST_SUITE_P(BackendDataSuite);

TYPED_TEST_P(BackendDataSuite, LocomotionMatchesReference) {
  MMVK_REQUIRE_DATA_DIR(data);
  const Database* db = locomotion_database(data);
  ASSERT_NE(db, nullptr);
  EXPECT_GT(db->frame_count(), 20000u);  // 21,791 frames at 30 fps
  const std::vector<float> queries = real_queries(*db, 64, 101);
  this->check(*db, queries, {}, 64, 1);
  this->check(*db, queries, {}, 64, 8);
}

TYPED_TEST_P(BackendDataSuite, LocomotionWithConstraintsMatchesReference) {
  MMVK_REQUIRE_DATA_DIR(data);
  const Database* db = locomotion_database(data);
  ASSERT_NE(db, nullptr);
  const std::vector<float> queries = real_queries(*db, 96, 103);
  const std::vector<QueryParams> params = random_params(*db, 96, 104);
  this->check(*db, queries, params, 96, 4);
  // One query alone (multi-threaded backends split rows instead of queries).
  this->check(*db, std::span<const float>(queries).first(db->dims()), std::span<const QueryParams>(params).first(1), 1, 16);
}

// Every channel kind of issue 12, on real and on random motion.
TYPED_TEST_P(BackendDataSuite, NewChannelKindsMatchReference) {
  MMVK_REQUIRE_DATA_DIR(data);
  for (const Database* db : {locomotion_new_kinds_database(data), random_new_kinds_database(data)}) {
    ASSERT_NE(db, nullptr);
    SCOPED_TRACE(db->frame_count());
    ASSERT_EQ(db->dims(), new_kinds_schema().dims());
    const std::vector<float> queries = real_queries(*db, 64, 107);
    const std::vector<QueryParams> params = random_params(*db, 64, 108);
    this->check(*db, queries, {}, 64, 1);
    this->check(*db, queries, params, 64, 4);
  }
}

REGISTER_TYPED_TEST_SUITE_P(BackendDataSuite, LocomotionMatchesReference, LocomotionWithConstraintsMatchesReference,
                            NewChannelKindsMatchReference);

}  // namespace mmvk::test
