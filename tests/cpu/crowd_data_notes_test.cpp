// The summary's notes on what the data cannot do (measure/data_notes.hpp):
// no idle on data without standing frames, in the words `mmvk inspect`
// uses, and none on the shipped cmu-walks (CMU 131, with standing loops);
// the speeds a scenario asks for beyond the data's moving speeds at the
// controller's play-rate and stride bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "measure/data_notes.hpp"
#include "mmvk/database/database_build.hpp"
#include "setup/crowd_session.hpp"
#include "setup/default_data.hpp"
#include "support/motion_fixtures.hpp"
#include "support/test_data.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

constexpr const char* kNoIdle = "the data has no idle";

bool any_note(const std::vector<std::string>& notes, const std::string& words) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(words) != std::string::npos; });
}

// Walks only, at 1.0 and 1.4 m/s (3 s each, turning gently either way so
// that no feature is constant): nothing stands.
Database walks_only() {
  std::vector<MotionClip> clips(2);
  for (std::size_t c = 0; c < clips.size(); ++c) {
    clips[c].motion = test::walker(90, c == 0 ? 1.0f : 1.4f, float(c), c == 0 ? 0.3f : -0.3f, 0.4f);
    clips[c].meta.name = "walk" + std::to_string(c);
    clips[c].meta.file = clips[c].meta.name + ".bvh";
    clips[c].meta.tags = {"walk"};
  }
  Result<Database> db = build_database_from_motions(clips, {});
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

Database cmu_walks() {
  const fs::path manifest = test::test_source_dir().parent_path() / "host/crowd/data/cmu131/manifest.json";
  Result<OpenedDatabase> opened = open_database(manifest, fs::path(), [](const std::string&) {});
  EXPECT_TRUE(opened.ok()) << opened.message();
  return std::move(opened.value().database);
}

// A session's notes after a second of the crowd's own steering (without
// foot IK: the hand-made walker has no knees).
std::vector<std::string> run_notes(const Database& db, std::optional<Scenario> scenario) {
  CrowdSessionOptions options;
  options.foot_ik = false;
  options.agents = scenario ? std::nullopt : std::optional<std::uint64_t>(8);
  options.scenario = std::move(scenario);
  options.backend = "fast-box";
  Result<std::unique_ptr<CrowdSession>> session = CrowdSession::create(db, options);
  EXPECT_TRUE(session.ok()) << session.message();
  if (!session.ok()) return {};
  for (int tick = 0; tick < 30; ++tick) EXPECT_TRUE((*session)->step().ok());
  return (*session)->summary().notes;
}

TEST(CrowdDataNotes, NoIdleOnDataThatCannotStandInTheWordsOfInspect) {
  const Database db = walks_only();
  const GaitCoverage coverage = measure_gait_coverage(db);
  ASSERT_FALSE(coverage.can_stand());
  const std::string note = no_idle_note(coverage, db.gait_bands());
  EXPECT_EQ(note.rfind(kNoIdle, 0), 0u) << note;
  EXPECT_NE(note.find("must hold a frame instead"), std::string::npos) << note;
  // `mmvk inspect` says the same line.
  EXPECT_NE(describe_gait_coverage(coverage, db.gait_bands()).find("\n" + note), std::string::npos);
  const std::vector<std::string> notes = run_notes(db, std::nullopt);
  for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
  EXPECT_EQ(std::count(notes.begin(), notes.end(), note), 1);
  // Unmeasured coverage knows no idle either, and says why.
  const std::string unmeasured = no_idle_note(GaitCoverage{}, nullptr);
  EXPECT_EQ(unmeasured.rfind(kNoIdle, 0), 0u) << unmeasured;
  EXPECT_NE(unmeasured.find("not measured"), std::string::npos) << unmeasured;
}

TEST(CrowdDataNotes, ShippedCmuWalksStandsAndLacksNoSpeedItsScenarioAsks) {
  const Database db = cmu_walks();
  const GaitCoverage coverage = measure_gait_coverage(db);
  EXPECT_TRUE(coverage.can_stand());
  EXPECT_EQ(no_idle_note(coverage, db.gait_bands()), "");
  const std::vector<std::string> notes = run_notes(db, std::nullopt);
  for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
  EXPECT_FALSE(any_note(notes, kNoIdle));
  EXPECT_FALSE(any_note(notes, "the data lacks"));
  EXPECT_TRUE(any_note(notes, "the data has no run"));  // walks only, as before
}

TEST(CrowdDataNotes, ScenarioSpeedsBeyondThePlayableOnesSayWhichTheDataLacks) {
  const Database db = walks_only();
  Scenario scenario;
  scenario.source = "test";
  scenario.world_size_m = 40.0f;
  scenario.agents.resize(3);
  const float speeds[] = {0.3f, 0.35f, 1.2f};  // the first two below 1.0 x 0.75 x 0.85
  for (std::size_t a = 0; a < 3; ++a) {
    scenario.agents[a].start = {4.0f * float(a), 0.0f};
    scenario.agents[a].goals = {{4.0f * float(a), 15.0f}};
    scenario.agents[a].speed = {Gait::Metres, speeds[a]};
  }
  const std::vector<std::string> notes = run_notes(db, scenario);
  for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
  EXPECT_TRUE(any_note(notes, "the data lacks slower motion: the scenario asks 2 of 3 characters for 0.30-0.35 m/s, "
                              "below the 0."))
      << ::testing::PrintToString(notes);
  EXPECT_FALSE(any_note(notes, "the data lacks faster motion: the scenario"));

  // Faster, from the bounds alone: 95th percentile 2 m/s x 1.3 x 1.15 = 2.99.
  GaitCoverage coverage;
  coverage.measured = true;
  coverage.stand_loop = true;
  coverage.moving_p5_mps = 1.0f;
  coverage.moving_p95_mps = 2.0f;
  const ControllerParams params;
  const PlayableSpeeds playable = playable_speeds(coverage, params);
  EXPECT_NEAR(playable.max_mps, 2.0 * 1.3 * 1.15, 1e-6);
  EXPECT_NEAR(playable.min_mps, 1.0 * 0.75 * 0.85, 1e-6);
  const std::vector<float> asked{1.5f, 3.2f, 2.99f};
  const GaitBandParams bands;
  const std::vector<std::string> fast = data_notes(coverage, &bands, params, asked);
  ASSERT_EQ(fast.size(), 1u) << ::testing::PrintToString(fast);
  EXPECT_EQ(fast[0], "the data lacks faster motion: the scenario asks 1 of 3 characters for 3.20 m/s, above the 2.99 "
                     "m/s its moving frames play at most (95th percentile 2.00 m/s x play rate 1.30 x stride 1.15)");
  // No speeds asked (a host steers): no speed notes.
  EXPECT_TRUE(data_notes(coverage, &bands, params, {}).empty());
}

}  // namespace
}  // namespace mmvk::crowd
