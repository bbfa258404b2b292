// Speed from the animation on the shipped default data (CMU 16,
// `cmu-walk-run`, whose walk plays at 1.67 m/s): a host that commands 0.8
// and 1.3 m/s through CrowdSession::step gets played speeds nearer the
// command than the data's own speed (--speed-from-animation off), and the
// root correction supplies less of the travel, little where the command is
// within the play-rate bounds; beyond them the summary's notes say so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "setup/crowd_session.hpp"
#include "setup/default_data.hpp"
#include "support/test_data.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

// Measured with this run (6 s from standing, which this data cannot do,
// so the first second walks in place): the played speed is off by 31% /
// 0.3% at 0.8 / 1.3 m/s with speed from the animation (median of 1 s
// windows), 105% / 26% without; the correction supplies 37% / 6.4% of the
// travel, 113% / 32% without. 1.3 m/s lies within the play-rate bounds of
// the data's 1.67 m/s walk, 0.8 beyond them (0.75 x 0.85 of it is 1.06
// m/s), so only 1.3 has a bound of its own: twice the share measured.
constexpr float kWithinBounds = 1.3f;
constexpr double kMaxGlideShareWithinBounds = 0.12;

Database default_data() {
  const fs::path manifest = test::test_source_dir().parent_path() / "host/crowd/data/cmu16/manifest.json";
  Result<OpenedDatabase> opened = open_database(manifest, fs::path(), [](const std::string&) {});
  EXPECT_TRUE(opened.ok()) << opened.message();
  return std::move(opened.value().database);
}

// Four characters told to walk straight on at `speed` for 6 s.
CrowdSummary walk(const Database& db, float speed, bool speed_from_animation) {
  CrowdSessionOptions options;
  options.agents = 4;
  options.backend = "fast-box";
  options.speed_from_animation = speed_from_animation;
  Result<std::unique_ptr<CrowdSession>> session = CrowdSession::create(db, options);
  EXPECT_TRUE(session.ok()) << session.message();
  if (!session.ok()) return {};
  for (std::uint32_t b = 0; b < 4; ++b) EXPECT_TRUE((*session)->place(b, 4.0f * float(b), 0.0f, 0.0f).ok());
  const std::vector<glm::vec3> velocity(4, glm::vec3(0.0f, 0.0f, speed));
  for (int tick = 0; tick < 180; ++tick) EXPECT_TRUE((*session)->step(velocity, {}).ok());
  return (*session)->summary();
}

TEST(CrowdSpeed, PlayedSpeedNearerTheCommandAndLittleGlide) {
  const Database db = default_data();
  for (const float speed : {0.8f, 1.3f}) {
    SCOPED_TRACE(speed);
    const CrowdSummary summary = walk(db, speed, true);
    const CommandFigures& on = summary.command;
    const CommandFigures off = walk(db, speed, false).command;
    std::printf("%.1f m/s: played speed error %.3f (off %.3f), glide share %.3f (off %.3f)\n", double(speed),
                on.played_speed_error_median, off.played_speed_error_median, on.glide_share_of_travel,
                off.glide_share_of_travel);
    EXPECT_LT(on.played_speed_error_median, off.played_speed_error_median);
    // Beyond the bounds the notes say the data lacks slower motion.
    const bool noted = std::any_of(summary.notes.begin(), summary.notes.end(), [](const std::string& note) {
      return note.find("lacks slower motion") != std::string::npos;
    });
    EXPECT_EQ(noted, speed != kWithinBounds);
    if (speed == kWithinBounds) {
      EXPECT_LT(on.glide_share_of_travel, kMaxGlideShareWithinBounds);
    }
    EXPECT_LT(on.glide_share_of_travel, off.glide_share_of_travel);
  }
}

}  // namespace
}  // namespace mmvk::crowd
