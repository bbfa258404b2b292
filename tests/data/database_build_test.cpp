// Database builds on real motion capture from ../shared/data (MMVK_DATA):
// straight-walk trajectories, normalization under every mode, the Bandai
// locomotion set, manifests with flags, mirroring, resampling, mixed rates,
// custom sidecars, and the mmvk build / inspect / export commands.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/features/normalization.hpp"
#include "support/command.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

const char* kLocomotion = "bandai-namco-nc/locomotion-normal";

std::filesystem::path bandai(const std::filesystem::path& data, const std::string& stem) {
  return data / kLocomotion / (stem + ".bvh");
}

// Every channel kind and normalization mode, with weights other than 1.
FeatureSchema mixed_schema() {
  FeatureSchema schema = default_schema();
  const Normalization modes[] = {Normalization::GroupStd, Normalization::PerDimStd, Normalization::MeanAbsDev,
                                 Normalization::MinMax};
  const float weights[] = {1.0f, 2.0f, 0.5f, 1.5f, 3.0f, 0.75f, 1.25f};
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    schema.channels[c].normalization = modes[c % 4];
    schema.channels[c].weight = weights[c];
  }
  return schema;
}

// The check the issue asks for: mean ~0 (min 0 for min-max) and spread =
// weight, by the channel's own definition of spread.
void expect_normalized(const Database& db) {
  const std::vector<DimStatistics> stats = compute_statistics(db.features(), db.dims());
  const FeatureSchema& schema = db.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    SCOPED_TRACE(channel.name);
    const std::uint32_t first = schema.offset(c);
    double group_std = 0.0;
    for (std::uint32_t d = first; d < first + channel.dims(); ++d) {
      const DimStatistics& s = stats[d];
      switch (channel.normalization) {
        case Normalization::GroupStd:
          EXPECT_NEAR(s.mean, 0.0, 1e-3);
          group_std += s.std / channel.dims();
          break;
        case Normalization::PerDimStd:
          EXPECT_NEAR(s.mean, 0.0, 1e-3);
          EXPECT_NEAR(s.std, channel.weight, 1e-3 * channel.weight);
          break;
        case Normalization::MeanAbsDev:
          EXPECT_NEAR(s.mean, 0.0, 1e-3);
          EXPECT_NEAR(s.mean_abs_dev, channel.weight, 1e-3 * channel.weight);
          break;
        case Normalization::MinMax:
          EXPECT_NEAR(s.min, 0.0, 1e-4);
          EXPECT_NEAR(s.max, channel.weight, 1e-4 * channel.weight);
          break;
      }
    }
    if (channel.normalization == Normalization::GroupStd) {
      EXPECT_NEAR(group_std, channel.weight, 1e-3 * channel.weight);
    }
  }
}

TEST(DatabaseBuild, StraightWalkTrajectoryPointsForwardAndGrowsWithTheOffset) {
  MMVK_REQUIRE_DATA_DIR(data);
  Result<BvhFile> bvh = load_bvh(bandai(data, "dataset-2_walk_normal_001"));
  ASSERT_TRUE(bvh.ok()) << bvh.message();
  Result<Motion> motion = motion_from_bvh(*bvh, {});
  ASSERT_TRUE(motion.ok()) << motion.message();
  Result<CharacterRoot> root = compute_character_root(*motion, {});
  ASSERT_TRUE(root.ok()) << root.message();
  const FeatureSchema schema = default_schema();
  Result<RawFeatures> raw = extract_features(*motion, *root, schema, {});
  ASSERT_TRUE(raw.ok()) << raw.message();
  const std::uint32_t traj = schema.offset(static_cast<std::size_t>(schema.find("trajectory_position")));
  const std::uint32_t dir = schema.offset(static_cast<std::size_t>(schema.find("trajectory_direction")));
  // The middle of the clip: walking at full speed, away from the start and the end.
  const std::uint32_t frames = raw->frame_count;
  ASSERT_GT(frames, 150u);
  for (std::uint32_t f = 60; f + 40 < frames; ++f) {
    SCOPED_TRACE(f);
    const float* row = raw->values.data() + std::size_t{f} * raw->dims;
    float previous = 0.0f;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const float x = row[traj + 2 * k];
      const float z = row[traj + 2 * k + 1];
      EXPECT_GT(z, previous + 0.2f) << "offset " << k;  // ~1.2 m/s: ~0.4 m per third of a second
      // Within ~20 degrees of straight ahead: the smoothed facing still sways
      // a few degrees with the pelvis over a gait cycle.
      EXPECT_LT(std::abs(x), 0.36f * z) << "offset " << k;
      previous = z;
      EXPECT_GT(row[dir + 2 * k + 1], 0.95f) << "facing still forward, offset " << k;
    }
    EXPECT_GT(row[traj + 5], 0.9f);
    EXPECT_LT(row[traj + 5], 1.6f);
  }
}

TEST(DatabaseBuild, BandaiLocomotionBuildsAndIsNormalizedUnderEveryMode) {
  MMVK_REQUIRE_DATA_DIR(data);
  Result<Manifest> manifest = manifest_from_directory(data / kLocomotion);
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  manifest->schema = mixed_schema();
  ThreadPool pool(2);
  BuildOptions options;
  options.pool = &pool;
  std::size_t calls = 0;
  BuildProgress last;
  options.progress = [&](const BuildProgress& p) {
    ++calls;
    EXPECT_GE(p.frames_done, last.frames_done);
    last = p;
  };
  Result<Database> db = build_database(*manifest, options);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->clips().size(), 145u);
  EXPECT_EQ(db->frame_count(), 21791u);
  EXPECT_EQ(db->fps(), 30.0f);
  EXPECT_EQ(calls, 145u);
  EXPECT_EQ(last.clips_done, 145u);
  EXPECT_EQ(last.frames_done, 21791u);
  std::uint32_t edge = 0;
  for (std::uint32_t flags : db->frame_flags()) edge += (flags & kFrameEdgeExcluded) != 0;
  EXPECT_EQ(edge, 145u * 30u) << "1 s of trajectory at 30 fps excludes each clip's last 30 frames";
  expect_normalized(*db);

  // The file round trip on real data is bit-exact.
  Result<Database> back = deserialize_database(serialize_database(*db), "bandai.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back->content_hash(), db->content_hash());
}

TEST(DatabaseBuild, ManifestFlagsMirrorResampleAndMixedSkeletons) {
  MMVK_REQUIRE_DATA_DIR(data);
  const auto dir = test::make_temp_dir();
  const std::string walk = bandai(data, "dataset-2_walk_normal_001").string();
  const std::string run = bandai(data, "dataset-2_run_normal_001").string();
  const std::string cmu = (data / "cmu/amc2bvh-131/131_01.bvh").string();
  std::ofstream(dir / "m.json") << R"({"edge_rule": "exclude", "clips": [
      {"file": ")" << walk << R"(", "tags": ["walk"], "do_not_use": [[0, 1.0]], "block_transition": [[2.0, 2.5]]},
      {"file": ")" << run << R"(", "tags": ["run"], "loop": true, "mirror": true, "cost_multiplier": 1.5, "cost_bias": 0.25}]})";
  Result<Manifest> manifest = load_manifest(dir / "m.json");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  Result<Database> db = build_database(*manifest);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->clips().size(), 3u);
  const Clip& w = db->clips()[0];
  const Clip& r = db->clips()[1];
  const Clip& m = db->clips()[2];
  EXPECT_EQ(w.frame_count, 273u);
  EXPECT_EQ(r.frame_count, 68u);
  EXPECT_EQ(m.frame_count, 68u);
  EXPECT_TRUE(m.mirrored);
  EXPECT_TRUE(m.loop);
  EXPECT_EQ(m.cost_multiplier, 1.5f);
  EXPECT_EQ(m.cost_bias, 0.25f);
  EXPECT_EQ(r.tags, m.tags);
  std::uint32_t do_not_use = 0, block = 0, edge = 0;
  for (std::uint32_t f = 0; f < db->frame_count(); ++f) {
    const std::uint32_t flags = db->frame_flags()[f];
    do_not_use += (flags & kFrameDoNotUse) != 0;
    block += (flags & kFrameBlockTransition) != 0;
    edge += (flags & kFrameEdgeExcluded) != 0;
  }
  EXPECT_EQ(do_not_use, 30u);  // [0, 1) s at 30 fps
  EXPECT_EQ(block, 15u);       // [2, 2.5) s
  EXPECT_EQ(edge, 30u);        // only the non-looping walk
  for (std::uint32_t f = 0; f < 30; ++f) EXPECT_TRUE(db->frame_flags()[f] & kFrameDoNotUse);

  // CMU (120 fps, another skeleton) with Bandai (30 fps): an error naming
  // both files without resampling, fine with it.
  Manifest mixed;
  mixed.source = "mixed";
  mixed.clips.resize(2);
  mixed.clips[0].file = walk;
  mixed.clips[1].file = cmu;
  Result<Database> refused = build_database(mixed);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("mixed frame rates"), std::string::npos) << refused.message();
  EXPECT_NE(refused.message().find("walk_normal_001.bvh"), std::string::npos) << refused.message();
  EXPECT_NE(refused.message().find("131_01.bvh"), std::string::npos) << refused.message();
  mixed.fps = 30.0f;
  Result<Database> resampled = build_database(mixed);
  ASSERT_TRUE(resampled.ok()) << resampled.message();
  EXPECT_EQ(resampled->fps(), 30.0f);
  EXPECT_EQ(resampled->clips()[0].frame_count, 273u);
  Result<BvhFile> cmu_bvh = load_bvh(cmu);
  ASSERT_TRUE(cmu_bvh.ok());
  const double cmu_seconds = cmu_bvh->frame_count * cmu_bvh->frame_time;
  EXPECT_NEAR(resampled->clips()[1].frame_count, cmu_seconds * 30.0, 2.0);

  // A missing file is named.
  mixed.clips[1].file = dir / "absent.bvh";
  Result<Database> missing = build_database(mixed);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("absent.bvh"), std::string::npos) << missing.message();
}

TEST(DatabaseBuild, CustomChannelsComeFromSidecarFiles) {
  MMVK_REQUIRE_DATA_DIR(data);
  const auto dir = test::make_temp_dir();
  // A copy in the temp folder (never in the repository) so the sidecar can sit beside it.
  std::filesystem::copy_file(bandai(data, "dataset-2_walk_normal_002"), dir / "walk.bvh");
  Result<BvhFile> bvh = load_bvh(dir / "walk.bvh");
  ASSERT_TRUE(bvh.ok());
  const std::uint32_t frames = static_cast<std::uint32_t>(bvh->frame_count);
  std::vector<float> phase(std::size_t{frames} * 2);
  for (std::uint32_t f = 0; f < frames; ++f) {
    phase[2 * f] = std::sin(0.1f * float(f));
    phase[2 * f + 1] = std::cos(0.1f * float(f));
  }
  std::ofstream(dir / "walk.phase.f32", std::ios::binary)
      .write(reinterpret_cast<const char*>(phase.data()), static_cast<std::streamsize>(phase.size() * 4));
  std::ofstream(dir / "m.json") << R"({"schema": {"channels": [
      {"name": "traj", "kind": "trajectory_position", "offsets_seconds": [0.5]},
      {"name": "phase", "kind": "custom", "dims": 2, "normalization": "per_dim_std"}]},
      "clips": ["walk.bvh"]})";
  Result<Manifest> manifest = load_manifest(dir / "m.json");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  Result<Database> db = build_database(*manifest);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->frame_count(), frames);
  for (std::uint32_t f = 0; f < frames; f += 17) {
    for (std::uint32_t d = 0; d < 2; ++d) {
      const float raw = db->row(f)[2 + d] * db->normalization()[2 + d].scale + db->normalization()[2 + d].offset;
      EXPECT_NEAR(raw, phase[2 * f + d], 1e-5f);
    }
  }
  // Resampled to 60 fps the sidecar is interpolated too.
  manifest->fps = 60.0f;
  Result<Database> fast = build_database(*manifest);
  ASSERT_TRUE(fast.ok()) << fast.message();
  EXPECT_NEAR(double(fast->frame_count()), 2.0 * frames, 2.0);
  // A sidecar of the wrong size is named.
  std::filesystem::resize_file(dir / "walk.phase.f32", 12);
  Result<Database> broken = build_database(*manifest);
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.message().find("walk.phase.f32: 12 bytes"), std::string::npos) << broken.message();
}

int run(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()); }

TEST(DatabaseBuild, CommandLineBuildInspectExport) {
  MMVK_REQUIRE_DATA_DIR(data);
  const auto cli = test::cli_binary();
  if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
  const std::filesystem::path mmvk = *cli;
  const auto dir = test::make_temp_dir();
  const std::string walk = bandai(data, "dataset-2_walk_normal_003").string();
  const std::string turn = bandai(data, "dataset-2_walk-turn-left_normal_001").string();
  std::ofstream(dir / "m.json") << R"({"clips": [{"file": ")" << walk << R"(", "tags": ["walk"]},
      {"file": ")" << turn << R"(", "tags": ["turn"]}]})";
  const std::string db = (dir / "db.mmdb").string();
  ASSERT_EQ(run(mmvk.string() + " build " + (dir / "m.json").string() + " -o " + db + " --mirror --no-progress"), 0);
  Result<Database> loaded = load_database(db);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_EQ(loaded->clips().size(), 4u);
  EXPECT_TRUE(loaded->clips()[1].mirrored);

  ASSERT_EQ(run(mmvk.string() + " inspect " + db), 0);
  ASSERT_EQ(std::system((mmvk.string() + " inspect --json " + db + " > " + (dir / "inspect.json").string()).c_str()), 0);
  const nlohmann::json inspect = nlohmann::json::parse(std::ifstream(dir / "inspect.json"));
  EXPECT_EQ(inspect["frames"], loaded->frame_count());
  EXPECT_EQ(inspect["clips"].size(), 4u);
  EXPECT_EQ(inspect["channels"].size(), 7u);
  EXPECT_EQ(inspect["tags"][1]["name"], "turn");
  // Units at a glance: Bandai's centimetres (guessed), an adult's height, a
  // walking pace, and no run in two walks.
  EXPECT_EQ(loaded->clips()[1].metres_per_unit, 0.01f);
  const nlohmann::json& units = inspect["units"];
  ASSERT_EQ(units["metres_per_unit"].size(), 1u) << units.dump();
  EXPECT_NEAR(units["metres_per_unit"][0]["value"].get<double>(), 0.01, 1e-6);
  EXPECT_EQ(units["metres_per_unit"][0]["clips"], 4);
  EXPECT_EQ(units["metres_per_unit"][0]["name"], "centimetres");
  ASSERT_EQ(units["units_from"].size(), 1u) << units.dump();
  EXPECT_EQ(units["units_from"][0]["from"], "guessed from the skeleton's size");
  EXPECT_EQ(units["axes_from"][0]["from"], "BVH files are read Y-up unless told");
  EXPECT_GT(units["standing_height_m"].get<double>(), 1.2) << units.dump();
  EXPECT_LT(units["standing_height_m"].get<double>(), 2.0) << units.dump();
  EXPECT_GT(units["body_up"].get<double>(), 0.9) << units.dump();  // upright along +Y
  EXPECT_GT(units["walk_mps"].get<double>(), 0.8) << units.dump();
  EXPECT_LT(units["walk_mps"].get<double>(), 2.0) << units.dump();
  EXPECT_TRUE(units["run_mps"].is_null()) << units.dump();
  EXPECT_NE(units["run_note"].get<std::string>().find("no frame is tagged 'run'"), std::string::npos) << units.dump();
  const auto text = test::run_command(mmvk.string() + " inspect " + db);
  EXPECT_NE(text.output.find("units: 0.01 metres per file unit (centimetres)"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("units taken from: guessed from the skeleton's size\n"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("up axis taken from: BVH files are read Y-up unless told\n"), std::string::npos)
      << text.output;
  EXPECT_NE(text.output.find("speeds: walk "), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("up axis: +Y, upright (the feet-to-head direction's y is "), std::string::npos)
      << text.output;

  const std::string out = (dir / "out.f32").string();
  ASSERT_EQ(run(mmvk.string() + " export " + db + " --features " + out), 0);
  std::ifstream in(out, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(bytes.size(), loaded->features().size_bytes());
  EXPECT_EQ(0, std::memcmp(bytes.data(), loaded->features().data(), bytes.size()));  // little-endian host
  const nlohmann::json sidecar = nlohmann::json::parse(std::ifstream(out + ".json"));
  EXPECT_EQ(sidecar["dims"], 27);
  EXPECT_EQ(sidecar["frames"], loaded->frame_count());
  EXPECT_EQ(sidecar["dim_names"][0], "left_foot_position.x");
  EXPECT_EQ(sidecar["groups"][26], 6);
  EXPECT_EQ(sidecar["scales"][3].get<float>(), loaded->normalization()[3].scale);
  EXPECT_EQ(sidecar["clips"][2]["first_frame"], loaded->clips()[2].first_frame);
  EXPECT_EQ(sidecar["frame_flags"].size(), loaded->frame_count());

  // Errors exit non-zero: a missing input, an unknown option, a damaged database.
  EXPECT_NE(run(mmvk.string() + " build " + (dir / "absent").string() + " -o " + db), 0);
  EXPECT_NE(run(mmvk.string() + " build " + (dir / "m.json").string() + " -o " + db + " --bogus"), 0);
  std::filesystem::resize_file(db, 100);
  EXPECT_NE(run(mmvk.string() + " inspect " + db), 0);
}

TEST(DatabaseBuild, CommandLineBuildsOneBvhFile) {
  MMVK_REQUIRE_DATA_DIR(data);
  const auto cli = test::cli_binary();
  if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
  const auto dir = test::make_temp_dir();
  const std::filesystem::path walk = bandai(data, "dataset-2_walk_normal_003");
  const std::string db = (dir / "walk.mmdb").string();
  ASSERT_EQ(run(cli->string() + " build " + walk.string() + " -o " + db + " --fps 30 --no-progress"), 0);
  Result<Database> loaded = load_database(db);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_EQ(loaded->clips().size(), 1u);
  EXPECT_EQ(loaded->clips()[0].name, walk.stem().string());
  EXPECT_GT(loaded->frame_count(), 100u);
}

}  // namespace
}  // namespace mmvk
