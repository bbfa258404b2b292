// The measured gait tags (mmvk/database/gait_bands.hpp) on hand-made root paths and
// clips: bands, hysteresis, starts and stops, the manifest block, the
// database build and the .mmdb round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/database/gait_bands.hpp"
#include "mmvk/database/gait_coverage.hpp"
#include "mmvk/database/manifest.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;

// A root path along +Z whose speed at frame f is speed(f) m/s.
template <typename Speed>
std::vector<glm::vec3> path(std::size_t frames, Speed speed) {
  std::vector<glm::vec3> root(frames, glm::vec3(0.0f));
  for (std::size_t f = 1; f < frames; ++f) root[f] = root[f - 1] + glm::vec3(0.0f, 0.0f, speed(f) / kFps);
  return root;
}

GaitBand band_of(GaitTags tags) {
  for (std::size_t b = 0; b < kGaitBandCount; ++b) {
    if (tags & (1u << b)) return GaitBand(b);
  }
  ADD_FAILURE() << "no band bit in " << int(tags);
  return GaitBand::Stand;
}

bool has(GaitTags tags, std::size_t tag) { return (tags >> tag) & 1u; }

int band_changes(const std::vector<GaitTags>& tags) {
  int changes = 0;
  for (std::size_t f = 1; f < tags.size(); ++f) changes += band_of(tags[f]) != band_of(tags[f - 1]);
  return changes;
}

TEST(GaitBands, StandWalkStandWithStartAndStop) {
  // 2 s standing, a 1 s ramp to 1.3 m/s, 3 s walking, a 1 s ramp down, 2 s standing.
  const auto speed = [](std::size_t f) {
    const float t = float(f) / kFps;
    if (t < 2.0f || t >= 7.0f) return 0.0f;
    if (t < 3.0f) return 1.3f * (t - 2.0f);
    if (t < 6.0f) return 1.3f;
    return 1.3f * (7.0f - t);
  };
  const std::vector<GaitTags> tags = measure_gait_tags(path(270, speed), kFps, false, GaitBandParams{});
  ASSERT_EQ(tags.size(), 270u);
  EXPECT_EQ(band_of(tags[0]), GaitBand::Stand);
  EXPECT_EQ(band_of(tags[45]), GaitBand::Stand);
  EXPECT_EQ(band_of(tags[135]), GaitBand::Walk);
  EXPECT_EQ(band_of(tags[269]), GaitBand::Stand);
  EXPECT_EQ(band_changes(tags), 2);
  // Starts: the moving frames of the second after the stand; stops: of the second before it.
  int starts = 0, stops = 0;
  for (std::size_t f = 0; f < tags.size(); ++f) {
    starts += has(tags[f], kGaitStartTag);
    stops += has(tags[f], kGaitStopTag);
    if (band_of(tags[f]) == GaitBand::Stand) {
      EXPECT_FALSE(has(tags[f], kGaitStartTag) || has(tags[f], kGaitStopTag)) << "frame " << f;
    }
  }
  EXPECT_EQ(starts, 30);
  EXPECT_EQ(stops, 30);
  EXPECT_TRUE(has(tags[70], kGaitStartTag));
  EXPECT_FALSE(has(tags[135], kGaitStartTag) || has(tags[135], kGaitStopTag));
  EXPECT_TRUE(has(tags[200], kGaitStopTag));
}

TEST(GaitBands, HysteresisKeepsAWaveringSpeedInOneBand) {
  // 2.05 m/s wavering by +-0.15 m/s every 0.2 s: across jog_from (2 m/s).
  const auto speed = [](std::size_t f) { return 2.05f + 0.15f * std::sin(2.0f * 3.14159265f * float(f) / 6.0f); };
  const std::vector<glm::vec3> root = path(300, speed);
  const std::vector<GaitTags> held = measure_gait_tags(root, kFps, false, GaitBandParams{});
  EXPECT_EQ(band_changes(held), 0);
  // Without smoothing or hysteresis the same clip flickers.
  GaitBandParams raw;
  raw.hysteresis = 0.0f;
  raw.smoothing_seconds = 0.0f;
  EXPECT_GT(band_changes(measure_gait_tags(root, kFps, false, raw)), 20);
}

TEST(GaitBands, BandsByThresholdAndManifestOverride) {
  GaitBandParams params;
  EXPECT_EQ(gait_band_of_speed(params, 0.0f), GaitBand::Stand);
  EXPECT_EQ(gait_band_of_speed(params, 1.0f), GaitBand::Walk);
  EXPECT_EQ(gait_band_of_speed(params, 2.5f), GaitBand::Jog);
  EXPECT_EQ(gait_band_of_speed(params, 3.6f), GaitBand::Run);
  params.run_from_mps = 4.0f;
  EXPECT_EQ(gait_band_of_speed(params, 3.6f), GaitBand::Jog);
  const std::vector<GaitTags> jogs = measure_gait_tags(path(60, [](std::size_t) { return 3.6f; }), kFps, false, params);
  for (GaitTags tags : jogs) EXPECT_EQ(band_of(tags), GaitBand::Jog);
}

TEST(GaitBands, ALoopingClipWrapsItsSpeed) {
  // A looping clip at constant speed: the frames at the seam move as fast as the others.
  const std::vector<float> speeds = smoothed_root_speeds(path(20, [](std::size_t) { return 1.2f; }), kFps, true, 0.25f);
  for (float s : speeds) EXPECT_NEAR(s, 1.2f, 1e-3f);
  // Standing in place, looped: every frame stands.
  const std::vector<GaitTags> still = measure_gait_tags(std::vector<glm::vec3>(6, glm::vec3(0.0f)), kFps, true, {});
  for (GaitTags tags : still) EXPECT_EQ(tags, GaitTags(1u << unsigned(GaitBand::Stand)));
}

TEST(GaitBands, BadParametersNameTheField) {
  const auto error = [](GaitBandParams params) { return validate_gait_band_params(params, "db.json: gait_bands").message(); };
  GaitBandParams p;
  EXPECT_TRUE(validate_gait_band_params(p, "x").ok());
  p.jog_from_mps = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error(p).find("db.json: gait_bands.jog_from_mps: must be a finite speed > 0"), std::string::npos) << error(p);
  p = {};
  p.run_from_mps = std::numeric_limits<float>::infinity();
  EXPECT_NE(error(p).find("gait_bands.run_from_mps: must be a finite"), std::string::npos) << error(p);
  p = {};
  p.run_from_mps = 1.5f;
  EXPECT_NE(error(p).find("gait_bands.run_from_mps: must be above jog_from_mps (2 m/s), got 1.5"), std::string::npos)
      << error(p);
  p = {};
  p.hysteresis = 0.3f;  // 2 x 1.3 >= 3 x 0.7
  EXPECT_NE(error(p).find("gait_bands.hysteresis: 0.3 makes the margins of jog_from_mps and run_from_mps overlap"),
            std::string::npos)
      << error(p);
  p = {};
  p.smoothing_seconds = -1.0f;
  EXPECT_NE(error(p).find("gait_bands.smoothing_seconds"), std::string::npos);
  p = {};
  p.transition_seconds = 0.0f;
  EXPECT_NE(error(p).find("gait_bands.transition_seconds"), std::string::npos);
}

Result<Manifest> manifest_with(const std::string& block) {
  return parse_manifest_json(R"({"gait_bands": )" + block + R"(, "clips": ["a.bvh"]})", "db.json", ".");
}

TEST(GaitBands, TheManifestBlock) {
  Result<Manifest> read = manifest_with(R"({"walk_from_mps": 0.2, "run_from_mps": 3.5, "hysteresis": 0.05})");
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(read->gait_bands.walk_from_mps, 0.2f);
  EXPECT_EQ(read->gait_bands.jog_from_mps, 2.0f);
  EXPECT_EQ(read->gait_bands.run_from_mps, 3.5f);
  EXPECT_EQ(read->gait_bands.hysteresis, 0.05f);
  EXPECT_TRUE(read->gait_bands.enabled);
  EXPECT_FALSE(manifest_with(R"({"enabled": false})")->gait_bands.enabled);
  EXPECT_EQ(manifest_with(R"({"walk_from": 0.2})").message(), "db.json: gait_bands.walk_from: unknown field");
  EXPECT_EQ(manifest_with(R"({"jog_from_mps": 3.5})").message(),
            "db.json: gait_bands.run_from_mps: must be above jog_from_mps (3.5 m/s), got 3");
  EXPECT_NE(manifest_with(R"({"walk_from_mps": -0.1})").message().find("gait_bands.walk_from_mps: must be a finite speed > 0"),
            std::string::npos);
  EXPECT_NE(manifest_with("[]").message().find("db.json: gait_bands: expected an object"), std::string::npos);
  // The measured tags' prefix is the build's own.
  Result<Manifest> taken =
      parse_manifest_json(R"({"clips": [{"file": "a.bvh", "tags": ["walk", "gait:walk"]}]})", "db.json", ".");
  EXPECT_NE(taken.message().find("db.json: clips[0].tags[1]: 'gait:walk' begins with 'gait:'"), std::string::npos)
      << taken.message();
  Result<Manifest> ranged = parse_manifest_json(
      R"({"clips": [{"file": "a.bvh", "tag_ranges": {"gait:stand": [[0, 1]]}}]})", "db.json", ".");
  EXPECT_NE(ranged.message().find("clips[0].tag_ranges.gait:stand: 'gait:stand' begins with"), std::string::npos)
      << ranged.message();
}

// Two clips: a walker at 1.3 m/s and one standing still, facing elsewhere.
std::vector<MotionClip> walk_and_stand() {
  std::vector<MotionClip> clips(2);
  clips[0].motion = test::walker(90, 1.3f, 0.0f, 0.4f, 0.3f);  // turning, so that no feature is constant
  clips[0].meta.file = "walk.bvh";
  clips[0].meta.name = "walk";
  clips[0].meta.tags = {"walk"};
  clips[1].motion = test::walker(90, 0.0f, 1.0f);
  clips[1].meta.file = "stand.bvh";
  clips[1].meta.name = "stand";
  return clips;
}

TEST(GaitBands, TheBuildTagsEveryFrameAndTheFileKeepsThem) {
  MotionBuildSettings settings;
  settings.gait_bands.walk_from_mps = 0.2f;
  Result<Database> db = build_database_from_motions(walk_and_stand(), settings);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->tag_names().size(), 1u + kGaitTagNames.size());
  EXPECT_EQ(db->tag_names()[0], "walk");  // the manifest's tags keep their bits
  for (std::size_t i = 0; i < kGaitTagNames.size(); ++i) EXPECT_EQ(db->tag_names()[1 + i], kGaitTagNames[i]);
  EXPECT_EQ(db->clips()[0].tags, TagMask{1});  // a clip's own tags stay its own
  const TagMask walk_band = *db->tag_mask(std::vector<std::string>{"gait:walk"});
  const TagMask stand_band = *db->tag_mask(std::vector<std::string>{"gait:stand"});
  for (std::uint32_t f = 0; f < 90; ++f) {
    EXPECT_EQ(db->frame_tags()[f], TagMask{1} | walk_band) << "frame " << f;
    EXPECT_EQ(db->frame_tags()[90 + f], stand_band) << "frame " << f;
  }
  ASSERT_NE(db->gait_bands(), nullptr);
  EXPECT_EQ(db->gait_bands()->walk_from_mps, 0.2f);
  Result<Database> loaded = deserialize_database(serialize_database(*db), "db.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_NE(loaded->gait_bands(), nullptr);
  EXPECT_EQ(loaded->gait_bands()->walk_from_mps, 0.2f);
  EXPECT_EQ(loaded->gait_bands()->transition_seconds, 1.0f);
  EXPECT_TRUE(std::equal(db->frame_tags().begin(), db->frame_tags().end(), loaded->frame_tags().begin()));
  // The stand clip is 3 s still: the data can stand.
  const GaitCoverage coverage = measure_gait_coverage(*loaded);
  EXPECT_TRUE(coverage.can_stand());
  EXPECT_EQ(coverage.band_frames[0], 90u - 30u);  // the default exclude rule drops each clip's last second
  EXPECT_EQ(gait_capabilities(coverage), "stands: yes, starts: no, stops: no, speeds: walk");
}

TEST(GaitBands, OffMeansNoMeasuredTags) {
  MotionBuildSettings settings;
  settings.gait_bands.enabled = false;
  Result<Database> db = build_database_from_motions(walk_and_stand(), settings);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->tag_names().size(), 1u);
  EXPECT_EQ(db->gait_bands(), nullptr);
  EXPECT_FALSE(measure_gait_coverage(*db).measured);
  // An unknown tag lists the known ones.
  Result<TagMask> unknown = db->tag_mask(std::vector<std::string>{"gait:stand"});
  EXPECT_NE(unknown.message().find("gait:stand"), std::string::npos) << unknown.message();
  EXPECT_NE(unknown.message().find("walk"), std::string::npos) << unknown.message();
  // A file without them is version 6 or older and loads without them.
  Result<Database> loaded = deserialize_database(serialize_database(*db), "db.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->gait_bands(), nullptr);
}

}  // namespace
}  // namespace mmvk
