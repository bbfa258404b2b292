// Messages that lead somewhere: each names what was wrong and what would be
// right (an unknown tag lists the database's tags, a mistyped --data the
// nearest shipped set, `mmvk --version` the format it writes, a database
// without animation its possible causes rather than one the user never chose).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "support/command.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk {
namespace {


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
  EXPECT_EQ(mask.message(),
            "unknown tag 'jump': the database's tags are walk, run, fast, gait:stand, gait:walk, gait:jog, gait:run, "
            "gait:start, gait:stop (exact, case-sensitive)");
}

TEST(Messages, MissingAnimationNamesEveryCauseWhenTheFileDoesNotSay) {
  const std::string message = missing_animation_error("crowd controller", "").message;
  EXPECT_TRUE(contains(message, "skeletons differ")) << message;
  EXPECT_TRUE(contains(message, "--no-animation")) << message;
  EXPECT_TRUE(contains(message, "format 1")) << message;
}

TEST(Messages, MissingAnimationGivesTheRecordedCauseAlone) {
  const std::string message = missing_animation_error("crowd controller", "built with --no-animation").message;
  EXPECT_EQ(message, "crowd controller: the database has no animation section: built with --no-animation; rebuild it "
                     "with `mmvk build` from clips of one skeleton");
}

}  // namespace
}  // namespace mmvk
