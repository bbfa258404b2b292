// Messages that lead somewhere: each names what was wrong and what would be
// right (an unknown tag lists the database's tags, a mistyped --data the
// nearest shipped set, `mmvk --version` the format it writes, a database
// without animation its possible causes rather than one the user never chose).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/animation_data.hpp"
#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "support/command.hpp"
#include "support/motion_fixtures.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

Database tagged_database() {
  std::vector<MotionClip> clips(2);
  clips[0].meta.name = "walk";
  clips[0].meta.tags = {"walk"};
  clips[0].motion = test::walker(90, 1.4f, 0.0f, 0.3f, 0.4f);
  clips[1].meta.name = "run";
  clips[1].meta.tags = {"run", "fast"};
  clips[1].motion = test::walker(90, 3.5f, 0.5f, -0.2f, 0.6f);
  MotionBuildSettings settings;
  settings.edge_rule = EdgeRule::Clamp;
  Result<Database> database = build_database_from_motions(clips, settings);
  EXPECT_TRUE(database.ok()) << database.message();
  return std::move(*database);
}

TEST(Messages, UnknownTagListsTheKnownOnes) {
  const Database database = tagged_database();
  const std::vector<std::string> jump = {"jump"};
  const Result<TagMask> mask = database.tag_mask(jump);
  ASSERT_FALSE(mask.ok());
  EXPECT_EQ(mask.message(), "unknown tag 'jump': the database's tags are walk, run, fast (exact, case-sensitive)");
}

TEST(Messages, MissingAnimationNamesEveryCause) {
  const std::string message = missing_animation_error("crowd controller").message;
  EXPECT_TRUE(contains(message, "skeletons differ")) << message;
  EXPECT_TRUE(contains(message, "--no-animation")) << message;
  EXPECT_TRUE(contains(message, "format 1")) << message;
}

class MessagesCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::optional<fs::path> binary = test::cli_binary();
    if (!binary) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
    dir_ = test::make_temp_dir();
    mmvk_ = "XDG_CACHE_HOME=" + (dir_ / "cache").string() + " " + binary->string();
  }
  fs::path dir_;
  std::string mmvk_;
};

TEST_F(MessagesCli, VersionPrintsTheFormatItWrites) {
  const auto ran = test::run_command(mmvk_ + " --version");
  EXPECT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_TRUE(contains(ran.output, "mmvk 0.")) << ran.output;
  EXPECT_TRUE(contains(ran.output, "writes .mmdb version " + std::to_string(kDatabaseFormatVersion))) << ran.output;
}

TEST_F(MessagesCli, MistypedDataSuggestsTheNearestShippedSet) {
  const auto ran = test::run_command(mmvk_ + " crowd --data cmu-walk --agents 2 --seconds 0.1");
  EXPECT_NE(ran.exit_code, 0) << ran.output;
  EXPECT_TRUE(contains(ran.output, "cmu-walk: no such file or folder, nor a shipped motion set: did you mean "
                                   "'cmu-walks'? (shipped: cmu-walk-run, cmu-walks)"))
      << ran.output;
  // A path gets no guess: it was not a name.
  const auto path = test::run_command(mmvk_ + " crowd --data " + (dir_ / "nowhere").string() + " --agents 2");
  EXPECT_TRUE(contains(path.output, "nowhere: no such file or folder")) << path.output;
  EXPECT_FALSE(contains(path.output, "did you mean")) << path.output;
}

}  // namespace
}  // namespace mmvk
