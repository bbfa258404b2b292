// `mmvk query --pose-targets` on a real database: the result, the per-target
// distances and the explanation (only the targeted channels weighted), and
// bad targets files named with their field; --continuing-multiplier.
#include <gtest/gtest.h>

#include <fstream>

#include "support/cli_fixture.hpp"
#include "support/command.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;
using test::run_command;

class PoseQueryCli : public test::CliFixture {
 protected:
  void SetUp() override {
    CliFixture::SetUp();
    if (IsSkipped()) return;
    db_ = (dir_ / "walk.mmdb").string();
    const fs::path walk = data_ / "bandai-namco-nc/locomotion-normal/dataset-2_walk_normal_001.bvh";
    std::ofstream(dir_ / "m.json") << R"({"clips": [")" << walk.string() << R"("]})";
    const test::CommandResult built = run_command(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + db_);
    ASSERT_EQ(built.exit_code, 0) << built.output;
  }

  fs::path write_targets(const std::string& json) {
    const fs::path path = dir_ / "targets.json";
    std::ofstream(path) << json;
    return path;
  }

  std::string db_;
};

TEST_F(PoseQueryCli, PrintsTheMatchTheDistancesAndTheExplanation) {
  const fs::path targets = write_targets(R"({"targets": [
      {"bone": "@left_foot", "position": [0.1, 0.1, 0.25]},
      {"bone": "@right_foot", "position": [-0.1, 0.08, -0.2], "velocity": [0, 0, 0.5]}]})");
  const test::CommandResult result =
      run_command(mmvk_ + " query " + db_ + " --pose-targets " + targets.string() + " --explain --k 2");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("pose match: frame "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("@left_foot           position off by "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("velocity off by "), std::string::npos) << result.output;
  // The untargeted channels are off in the explanation.
  EXPECT_NE(result.output.find("hip_velocity                 weight 0 "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("left_foot_velocity           weight 0 "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("right_foot_velocity          weight 1 "), std::string::npos) << result.output;
}

// --continuing-multiplier reaches the search and the explanation.
TEST_F(PoseQueryCli, ContinuingMultiplierIsExplained) {
  const fs::path targets = write_targets(R"({"targets": [{"bone": "@left_foot", "position": [0.1, 0.1, 0.25]}]})");
  const test::CommandResult result =
      run_command(mmvk_ + " query " + db_ + " --pose-targets " + targets.string() +
                  " --continuing 40 --continuing-multiplier 0.5 --continuing-bias -0.25 --explain --frames 40");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("x continuing_multiplier 0.5 + continuing_bias -0.25 = cost"), std::string::npos)
      << result.output;
  const test::CommandResult bad = run_command(mmvk_ + " query " + db_ + " --pose-targets " + targets.string() +
                                              " --continuing 40 --continuing-multiplier -1");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("continuing_multiplier must be finite and >= 0"), std::string::npos) << bad.output;
}

TEST_F(PoseQueryCli, BadTargetsAreNamed) {
  const std::pair<std::string, std::string> cases[] = {
      {R"({"targets": [{"bone": "@left_foot", "position": [0, 0]}]})", "targets.json: targets[0].position: expected [x, y, z]"},
      {R"({"targets": [{"bone": "@left_hand", "position": [0, 0, 0]}]})",
       "targets.json: targets[0].position: the database has no bone_position channel for bone '@left_hand'"},
      {R"({"targets": [{"bone": "@left_foot"}]})", "targets.json: targets[0]: needs a \"position\" or a \"velocity\""},
  };
  for (const auto& [json, expected] : cases) {
    const fs::path targets = write_targets(json);
    const test::CommandResult result = run_command(mmvk_ + " query " + db_ + " --pose-targets " + targets.string());
    EXPECT_NE(result.exit_code, 0) << json;
    EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
  }
  const test::CommandResult both = run_command(mmvk_ + " query " + db_ + " --pose-targets x.json --queries q.f32");
  EXPECT_NE(both.exit_code, 0);
}

}  // namespace
}  // namespace mmvk
