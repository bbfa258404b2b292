// Mirroring through a manifest on a real clip (Bandai walk): a sidecar
// channel's mirror_map (swapped and negated dims in the mirrored copy), and
// a mirror_bones table (the same pairs as the heuristics give the same
// database; a bone that is not there is an error naming the manifest).
#include <gtest/gtest.h>

#include <fstream>

#include "mmvk/database/database_build.hpp"
#include "mmvk/common/file_io.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

constexpr std::uint32_t kDims = 5;

class MirrorMap : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto data = test::find_data_dir();
    if (!data) GTEST_SKIP() << "motion data not found (set MMVK_DATA)";
    dir_ = test::make_temp_dir();
    const std::filesystem::path source = *data / "bandai-namco-nc/tiny/dataset-2_walk_normal_001_head30.bvh";
    std::filesystem::copy_file(source, dir_ / "walk.bvh");
    // Sidecar values 100 * frame + dim, so every dim is told apart.
    std::ifstream bvh(source);
    std::string word;
    while (bvh >> word && word != "Frames:") {}
    bvh >> frames_;
    std::vector<float> values;
    for (std::uint32_t f = 0; f < frames_; ++f) {
      for (std::uint32_t d = 0; d < kDims; ++d) values.push_back(100.0f * float(f) + float(d) + 1.0f);
    }
    ASSERT_TRUE(write_f32_rows(dir_ / "walk.phase.f32", values).ok());
  }

  Result<Database> build(const std::string& extra) {
    std::ofstream(dir_ / "m.json") << R"({"schema": {"channels": [
        {"name": "hipv", "kind": "root_velocity"},
        {"name": "phase", "kind": "custom", "dims": 5, "normalization": "min_max"}]},
      "edge_rule": "clamp")" << extra << R"(, "clips": [{"file": "walk.bvh", "mirror": true}]})";
    Result<Manifest> manifest = load_manifest(dir_ / "m.json");
    if (!manifest.ok()) return manifest.error();
    return build_database(*manifest);
  }

  std::filesystem::path dir_;
  std::uint32_t frames_ = 0;
};

// Raw value of the phase channel's dim d at database frame f.
float phase(const Database& db, std::uint32_t f, std::uint32_t d) {
  const std::uint32_t first = db.schema().offset(1);
  const DimNormalization& n = db.normalization()[first + d];
  return db.row(f)[first + d] * n.scale + n.offset;
}

TEST_F(MirrorMap, SidecarDimsSwapAndFlipInTheMirroredCopy) {
  Result<Database> db = build(R"(, "mirror_map": {"phase": {"swap": [[0, 2], [1, 3]], "negate": [4, 0]}})");
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->clips().size(), 2u);
  const Clip& source = db->clips()[0];
  const Clip& mirrored = db->clips()[1];
  ASSERT_TRUE(mirrored.mirrored);
  const std::uint32_t from[kDims] = {2, 3, 0, 1, 4};
  const float sign[kDims] = {-1, 1, 1, 1, -1};
  for (std::uint32_t f = 0; f < source.frame_count; ++f) {
    for (std::uint32_t d = 0; d < kDims; ++d) {
      const float original = phase(*db, source.first_frame + f, from[d]);
      EXPECT_NEAR(original, 100.0f * float(f) + float(from[d]) + 1.0f, 0.01f);
      ASSERT_NEAR(phase(*db, mirrored.first_frame + f, d), sign[d] * original, 0.01f) << "frame " << f << " dim " << d;
    }
  }
  // Without a map the copy is unchanged.
  Result<Database> plain = build("");
  ASSERT_TRUE(plain.ok()) << plain.message();
  for (std::uint32_t d = 0; d < kDims; ++d) {
    EXPECT_NEAR(phase(*plain, plain->clips()[1].first_frame + 3, d), phase(*plain, 3, d), 0.01f);
  }
}

TEST_F(MirrorMap, BonePairsOverrideTheHeuristicsInTheBuild) {
  Result<Database> heuristics = build("");
  ASSERT_TRUE(heuristics.ok()) << heuristics.message();
  Result<Database> same = build(R"(, "mirror_bones": [["@left_foot", "Foot_R"], ["Hand_L", "Hand_R"]])");
  ASSERT_TRUE(same.ok()) << same.message();
  EXPECT_EQ(same->content_hash(), heuristics->content_hash());
  ASSERT_NE(same->animation(), nullptr);
  EXPECT_EQ(same->animation()->mirror_pairs, heuristics->animation()->mirror_pairs);

  Result<Database> missing = build(R"(, "mirror_bones": [["Hand_L", "Hand_R"], ["Wing_L", "Hand_R"]])");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("m.json: "), std::string::npos) << missing.message();
  EXPECT_NE(missing.message().find("mirror_bones[1][0]: bone 'Wing_L' not found"), std::string::npos)
      << missing.message();
}

}  // namespace
}  // namespace mmvk
