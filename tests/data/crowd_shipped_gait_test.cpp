// The measured gait tags on real data (issue 31): the shipped sets stand on
// frames with both feet planted and the root still, their real clips are
// banded as they move (a jog to a stop ends standing, a start from rest
// starts so), `mmvk crowd --help`'s line for each set is what its build
// measures, `mmvk inspect` says it, and Bandai locomotion has no idle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "setup/default_data.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/database/gait_coverage.hpp"
#include "mmvk/database/manifest.hpp"
#include "support/command.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

Result<Database> build_shipped(const crowd::ShippedData& data) {
  const fs::path manifest = test::test_source_dir().parent_path() / "host" / "crowd" / "data" / data.folder / "manifest.json";
  MMVK_ASSIGN_OR_RETURN(Manifest parsed, load_manifest(manifest));
  return build_database(parsed);
}

TagMask tag(const Database& db, const char* name) { return *db.tag_mask(std::vector<std::string>{name}); }

const Clip* clip_named(const Database& db, const std::string& name) {
  for (const Clip& clip : db.clips()) {
    if (clip.name == name) return &clip;
  }
  ADD_FAILURE() << "no clip " << name;
  return nullptr;
}

// Candidate stand frames with both feet planted whose root moves under
// 0.1 m/s (smoothed as the bands are: a standing CMU body sways its hips by
// a few cm/s, and the markers jitter by about as much).
std::uint32_t still_frames(const Database& db) {
  const AnimationData& animation = *db.animation();
  const TagMask stand = tag(db, "gait:stand");
  std::uint32_t still = 0;
  for (const Clip& clip : db.clips()) {
    const std::span<const glm::vec3> root(animation.root_positions.data() + clip.first_frame, clip.frame_count);
    const std::vector<float> speeds = smoothed_root_speeds(root, db.fps(), clip.loop, db.gait_bands()->smoothing_seconds);
    for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
      const std::uint32_t g = clip.first_frame + f;
      if ((db.frame_flags()[g] & (kFrameDoNotUse | kFrameEdgeExcluded)) || !(db.frame_tags()[g] & stand)) continue;
      if ((animation.contacts[g] & (kContactLeft | kContactRight)) != (kContactLeft | kContactRight)) continue;
      still += speeds[f] < 0.1f;
    }
  }
  return still;
}

TEST(ShippedGait, EverySetStandsOnBothFeetAndItsHelpLineIsMeasured) {
  for (const crowd::ShippedData& data : crowd::shipped_data()) {
    Result<Database> db = build_shipped(data);
    ASSERT_TRUE(db.ok()) << db.message();
    const GaitCoverage coverage = measure_gait_coverage(*db);
    std::printf("%s: %s\n%s\n  still standing frames, both feet planted: %u\n", std::string(data.name).c_str(),
                gait_capabilities(coverage).c_str(), describe_gait_coverage(coverage, db->gait_bands()).c_str(),
                still_frames(*db));
    EXPECT_TRUE(coverage.can_stand()) << data.name;
    EXPECT_EQ(gait_capabilities(coverage), data.capabilities) << data.name << ": update ShippedData::capabilities";
    // At least the 0.2 s standing loop and its mirror.
    EXPECT_GE(still_frames(*db), 12u) << data.name;
    EXPECT_GE(coverage.stand_both_feet_frames, 12u) << data.name;
  }
}

TEST(ShippedGait, RealClipsAreBandedAsTheyMove) {
  Result<Database> cmu16 = build_shipped(crowd::shipped_data()[0]);
  ASSERT_TRUE(cmu16.ok()) << cmu16.message();
  const Clip* stop = clip_named(*cmu16, "jog_stop_57");
  ASSERT_NE(stop, nullptr);
  const auto tags_at = [&](const Database& db, const Clip& clip, std::uint32_t f) { return db.frame_tags()[clip.first_frame + f]; };
  // 16_57 runs at 3.1 m/s and stops dead: it starts jogging or running and ends standing, after a stop.
  EXPECT_TRUE(tags_at(*cmu16, *stop, 0) & (tag(*cmu16, "gait:run") | tag(*cmu16, "gait:jog")));
  EXPECT_TRUE(tags_at(*cmu16, *stop, stop->frame_count - 1) & tag(*cmu16, "gait:stand"));
  EXPECT_TRUE(tags_at(*cmu16, *stop, stop->frame_count - 16) & tag(*cmu16, "gait:stop"));
  // The 3.6 m/s run is banded run throughout, the 1.6 m/s walks walk.
  const Clip* run = clip_named(*cmu16, "run_veer_right_50");
  const Clip* walk = clip_named(*cmu16, "walk_veer_left_23");
  ASSERT_TRUE(run && walk);
  for (std::uint32_t f = 0; f < run->frame_count; ++f) EXPECT_TRUE(tags_at(*cmu16, *run, f) & tag(*cmu16, "gait:run")) << f;
  for (std::uint32_t f = 0; f < walk->frame_count; ++f) EXPECT_TRUE(tags_at(*cmu16, *walk, f) & tag(*cmu16, "gait:walk")) << f;
  // 131_02 starts from rest: standing, then a start (131_01 shuffles from its first frame).
  Result<Database> cmu131 = build_shipped(crowd::shipped_data()[1]);
  ASSERT_TRUE(cmu131.ok()) << cmu131.message();
  const Clip* start = clip_named(*cmu131, "start_walk_stop_02");
  ASSERT_NE(start, nullptr);
  EXPECT_TRUE(tags_at(*cmu131, *start, 0) & tag(*cmu131, "gait:stand"));
  bool started = false;
  for (std::uint32_t f = 0; f < 90; ++f) started = started || (tags_at(*cmu131, *start, f) & tag(*cmu131, "gait:start"));
  EXPECT_TRUE(started);
}

TEST(ShippedGait, InspectSaysWhatEachSetCanDo) {
  const auto cli = test::cli_binary();
  if (!cli) GTEST_SKIP() << "mmvk not built";
  const fs::path dir = test::make_temp_dir();
  Result<Database> db = build_shipped(crowd::shipped_data()[0]);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_TRUE(save_database(*db, dir / "cmu16.mmdb").ok());
  const test::CommandResult text = test::run_command(cli->string() + " inspect " + (dir / "cmu16.mmdb").string());
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("can do: " + std::string(crowd::shipped_data()[0].capabilities)), std::string::npos)
      << text.output;
  EXPECT_NE(text.output.find("standing frames with both feet planted: "), std::string::npos) << text.output;
  const test::CommandResult json = test::run_command(cli->string() + " inspect --json " + (dir / "cmu16.mmdb").string());
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const nlohmann::json parsed = nlohmann::json::parse(json.output);
  EXPECT_EQ(parsed["gait"]["stands"], true);
  EXPECT_GT(parsed["gait"]["band_frames"]["run"].get<int>(), 0);
  EXPECT_EQ(parsed["gait"]["start_frames"], 0);
  EXPECT_EQ(parsed["gait"]["thresholds"]["jog_from_mps"], 2.0);
  // The help says the same, without building anything.
  const test::CommandResult help = test::run_command(cli->string() + " crowd --help");
  for (const crowd::ShippedData& data : crowd::shipped_data()) {
    EXPECT_NE(help.output.find(std::string(data.name)), std::string::npos);
  }
  EXPECT_NE(help.output.find("Can do: stands: yes"), std::string::npos) << help.output;
}

TEST(ShippedGait, BandaiLocomotionHasNoIdle) {
  MMVK_REQUIRE_DATA_DIR(data);
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc/locomotion-normal");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  Result<Database> db = build_database(*manifest);
  ASSERT_TRUE(db.ok()) << db.message();
  const GaitCoverage coverage = measure_gait_coverage(*db);
  const std::string said = describe_gait_coverage(coverage, db->gait_bands());
  std::printf("Bandai locomotion: %s\n%s\n", gait_capabilities(coverage).c_str(), said.c_str());
  EXPECT_FALSE(coverage.can_stand());
  EXPECT_NE(said.find("the data has no idle"), std::string::npos) << said;
  // Its walks and runs are banded: walk frames most, some runs.
  EXPECT_GT(coverage.band_frames[1], coverage.band_frames[3]);
  EXPECT_GT(coverage.band_frames[3], 0u);
}

}  // namespace
}  // namespace mmvk
