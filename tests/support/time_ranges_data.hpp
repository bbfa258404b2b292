// A real database with time-ranged tags and costs (two Bandai walks with a
// manifest's tag_ranges and cost_ranges) and queries that require or exclude
// the range tags, shared by the CPU and Vulkan tests that check every
// backend against the reference on per-frame tags and costs.
#pragma once

#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/search/backends.hpp"
#include "mmvk/database/database_build.hpp"
#include "support/test_data.hpp"

namespace mmvk::test {

// A manifest over two Bandai walks (9 s each) at 30 fps; `clip0_extra` and
// `clip1_extra` are JSON members added to each clip object. The measured
// gait tags are off, so that the range tags are the frames' only per-frame
// tags (tests/cpu/gait_bands_test.cpp has the two together).
inline std::filesystem::path write_ranges_manifest(const std::filesystem::path& data, const std::string& clip0_extra,
                                                   const std::string& clip1_extra) {
  const std::filesystem::path dir = make_temp_dir();
  const std::filesystem::path folder = data / "bandai-namco-nc/locomotion-normal";
  std::ofstream(dir / "m.json") << R"({"fps": 30, "gait_bands": {"enabled": false}, "clips": [
      {"file": ")" << (folder / "dataset-2_walk_normal_001.bvh").string()
                                << R"(", "tags": ["walk"])" << clip0_extra << R"(},
      {"file": ")" << (folder / "dataset-2_walk_normal_002.bvh").string()
                                << R"(", "tags": ["run"], "cost_multiplier": 1.25, "cost_bias": 0.5)" << clip1_extra
                                << "}]}";
  return dir / "m.json";
}

inline Result<Database> build_features_only(const std::filesystem::path& manifest_path) {
  Result<Manifest> manifest = load_manifest(manifest_path);
  if (!manifest.ok()) return manifest.error();
  BuildOptions options;
  options.animation.enabled = false;
  return build_database(*manifest, options);
}

// Range tags "jump" and "rare" on both clips, a cost range on the second.
inline Result<Database> build_ranged_database(const std::filesystem::path& data) {
  return build_features_only(write_ranges_manifest(
      data, R"(, "tag_ranges": {"jump": [[0.5, 1.0], [2.0, 2.5]], "rare": [[1.3, 1.4]]})",
      R"(, "cost_ranges": [{"range": [1.0, 2.0], "cost_multiplier": 2.0, "cost_bias": -0.5}],
         "tag_ranges": {"jump": [[1.0, 1.2]], "rare": [[2.9, 3.0]]})"));
}

// Queries near random rows that require or exclude the range tags, half
// of them continuing from a random frame.
struct RangeQueries {
  std::vector<float> features;
  std::vector<QueryParams> params;
  QueryBatch batch() const { return {features, params, params.size()}; }
};

inline RangeQueries range_tag_queries(const Database& db, std::size_t count) {
  const TagMask jump = *db.tag_mask(std::vector<std::string>{"jump"});
  const TagMask rare = *db.tag_mask(std::vector<std::string>{"rare"});
  const TagMask run = *db.tag_mask(std::vector<std::string>{"run"});
  std::mt19937 rng(12);
  std::uniform_int_distribution<std::uint32_t> pick(0, db.frame_count() - 1);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  RangeQueries out;
  out.params.resize(count);
  for (std::size_t q = 0; q < count; ++q) {
    for (const float x : db.row(pick(rng))) out.features.push_back(x + noise(rng));
    QueryParams& p = out.params[q];
    const TagMask require[] = {0, jump, rare, jump | run};
    p.require_all = require[q % 4];
    p.exclude_any = q % 3 == 0 ? rare : 0;
    if (q % 2 == 1) {
      p.continuing_frame = pick(rng);
      p.continuing_bias = -0.1f;
      p.exclusion_window = 5;
    }
  }
  return out;
}

// Each backend's results equal the reference's, frames and cost bits.
inline void expect_reference_results(const Database& db, const BackendRegistry& registry, BackendSpec spec,
                                     std::span<const char* const> names) {
  constexpr std::size_t kQueries = 48;
  constexpr std::uint32_t k = 4;
  const RangeQueries queries = range_tag_queries(db, kQueries);
  std::vector<Match> expected(kQueries * k);
  Result<std::unique_ptr<SearchBackend>> reference = make_backend({.name = "reference"}, db);
  ASSERT_TRUE(reference.ok()) << reference.message();
  ASSERT_TRUE((*reference)->search(queries.batch(), k, expected).ok());
  std::size_t found = 0;
  for (std::size_t q = 0; q < kQueries; ++q) found += expected[q * k].frame != kNoFrame ? 1 : 0;
  EXPECT_GT(found, kQueries / 2);  // the tags leave candidates for most queries
  for (const char* name : names) {
    SCOPED_TRACE(name);
    spec.name = name;
    Result<std::unique_ptr<SearchBackend>> backend = registry.make(spec, db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    std::vector<Match> got(kQueries * k);
    const Status searched = (*backend)->search(queries.batch(), k, got);
    ASSERT_TRUE(searched.ok()) << searched.message();
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].frame, expected[i].frame) << "query " << i / k << " rank " << i % k;
      ASSERT_EQ(std::bit_cast<std::uint32_t>(got[i].cost), std::bit_cast<std::uint32_t>(expected[i].cost))
          << "query " << i / k << " rank " << i % k;
    }
  }
}

}  // namespace mmvk::test
