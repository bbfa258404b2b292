// The phase and foot_contact kinds on the Bandai straight walks: the phase
// of each toe's height advances monotonically at the stride frequency that
// the contacts give, and a mirrored clip's left phase is the source's right.
// Prints a per-clip table (bench/RESULTS.md, "Motion quality", "Feature kinds").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

// The (a sin, a cos) pair at `dim` of frame f as a phase in cycles.
double cycles(const Database& db, std::uint32_t f, std::uint32_t dim) {
  const auto raw = [&](std::uint32_t d) {
    return double(db.row(f)[d]) * db.normalization()[d].scale + db.normalization()[d].offset;
  };
  return std::atan2(raw(dim), raw(dim + 1)) / (2.0 * std::numbers::pi);
}

TEST(NewKindsOnBandai, PhaseAdvancesAtTheStrideFrequencyAndMirrorsSwap) {
  MMVK_REQUIRE_DATA_DIR(data);
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc" / "locomotion-normal");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  std::vector<ManifestClip> walks;
  for (ManifestClip& clip : manifest->clips) {
    if (clip.name.find("_walk_normal_") != std::string::npos) {
      clip.mirror = true;
      walks.push_back(clip);
    }
  }
  ASSERT_EQ(walks.size(), 24u);
  manifest->clips = walks;
  Result<FeatureSchema> schema = parse_schema_json(R"({"channels": [
      {"name": "contact", "kind": "foot_contact"},
      {"name": "phase", "kind": "phase", "curves": ["@left_toe.height", "@right_toe.height"]}]})", "phase.json");
  ASSERT_TRUE(schema.ok()) << schema.message();
  manifest->schema = *schema;
  manifest->edge_rule = EdgeRule::Clamp;
  ThreadPool pool;
  BuildOptions options;
  options.pool = &pool;
  Result<Database> db = build_database(*manifest, options);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->clips().size(), 48u);
  const float fps = db->fps();
  const std::uint32_t edge = static_cast<std::uint32_t>(std::lround(fps));  // the default 1 s window
  std::printf("clip, stride Hz (left touch-downs), phase Hz left toe, right toe, backward steps\n");
  double ratio_sum = 0.0;
  for (std::size_t c = 0; c < db->clips().size(); c += 2) {
    const Clip& clip = db->clips()[c];
    const Clip& mirrored = db->clips()[c + 1];
    SCOPED_TRACE(clip.name);
    ASSERT_TRUE(mirrored.mirrored);
    const std::uint32_t first = clip.first_frame;
    const std::uint32_t n = clip.frame_count;
    ASSERT_GT(n, 2 * edge + 30);
    // Stride frequency: left touch-downs (contact 0 -> 1) per second.
    std::vector<std::uint32_t> downs;
    for (std::uint32_t f = 1; f < n; ++f) {
      if (db->row(first + f)[0] > db->row(first + f - 1)[0]) downs.push_back(f);
    }
    ASSERT_GE(downs.size(), 3u);
    const double stride_hz = double(downs.size() - 1) * fps / double(downs.back() - downs.front());
    double hz[2] = {0.0, 0.0};
    std::uint32_t backward = 0;
    for (std::uint32_t side = 0; side < 2; ++side) {
      double total = 0.0;
      for (std::uint32_t f = first + edge + 1; f + edge < first + n; ++f) {
        double step = cycles(*db, f, 2 + 2 * side) - cycles(*db, f - 1, 2 + 2 * side);
        step -= std::round(step);
        backward += step <= 0.0;
        total += step;
      }
      hz[side] = total * fps / double(n - 2 * edge - 1);
      EXPECT_NEAR(hz[side], stride_hz, 0.05 * stride_hz) << "side " << side;
    }
    EXPECT_EQ(backward, 0u) << "the phase advances on every frame inside the edges";
    std::printf("%s, %.3f, %.3f, %.3f, %u\n", clip.name.c_str(), stride_hz, hz[0], hz[1], backward);
    ratio_sum += hz[0] / stride_hz;
    // Mirrored: the left curve's pair is the source's right one and back.
    for (std::uint32_t f = 0; f < n; ++f) {
      for (std::uint32_t d = 0; d < 2; ++d) {
        ASSERT_NEAR(db->row(mirrored.first_frame + f)[2 + d], db->row(first + f)[4 + d], 1e-3f) << f;
        ASSERT_NEAR(db->row(mirrored.first_frame + f)[4 + d], db->row(first + f)[2 + d], 1e-3f) << f;
        ASSERT_EQ(db->row(mirrored.first_frame + f)[d], db->row(first + f)[1 - d]) << "contacts swap, frame " << f;
      }
    }
  }
  std::printf("mean phase / stride frequency (left): %.4f over %zu walks\n", ratio_sum / 24.0, db->clips().size() / 2);
}

}  // namespace
}  // namespace mmvk
