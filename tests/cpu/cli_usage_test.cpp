// The mmvk command line's help and usage errors, which CLI11 parses from one
// declaration per option: every command is listed and has a help that lists
// its options, and a usage error exits 2 with a message naming the option,
// before any file is read or written.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mmvk/database/database_io.hpp"
#include "support/command.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;
using test::run_command;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class CliUsage : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::optional<fs::path> binary = test::cli_binary();
    if (!binary) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
    dir_ = test::make_temp_dir();
    // No run gets past its parse; any cache would still be the test's own.
    mmvk_ = "XDG_CACHE_HOME=" + (dir_ / "cache").string() + " " + binary->string();
  }

  // Expects exit code 2 and every one of `parts` in the output.
  void expect_usage_error(const std::string& args, const std::vector<std::string>& parts) const {
    const auto ran = run_command(mmvk_ + " " + args);
    EXPECT_EQ(ran.exit_code, 2) << "mmvk " << args << "\n" << ran.output;
    for (const std::string& part : parts) {
      EXPECT_TRUE(contains(ran.output, part)) << "mmvk " << args << ": no '" << part << "' in\n" << ran.output;
    }
  }

  fs::path dir_;
  std::string mmvk_;
};

TEST_F(CliUsage, EveryCommandIsListedAndHasItsOwnHelp) {
  const auto listed = run_command(mmvk_ + " --help");
  ASSERT_EQ(listed.exit_code, 0) << listed.output;
  for (const char* command : {"build", "inspect", "export", "query", "crowd", "clusters"}) {
    EXPECT_TRUE(contains(listed.output, std::string("\n  ") + command + " ")) << command << "\n" << listed.output;
    const auto help = run_command(mmvk_ + " " + command + " --help");
    EXPECT_EQ(help.exit_code, 0) << command << "\n" << help.output;
    EXPECT_EQ(help.output.rfind(std::string("usage: mmvk ") + command + " ", 0), 0u) << help.output;
    EXPECT_TRUE(contains(help.output, "\noptions:\n")) << command << "\n" << help.output;
    EXPECT_TRUE(contains(help.output, "\n  -h, --help ")) << command << "\n" << help.output;
  }
}

TEST_F(CliUsage, HelpListsEachOptionWithItsValue) {
  const auto build = run_command(mmvk_ + " build --help");
  ASSERT_EQ(build.exit_code, 0) << build.output;
  for (const char* option : {"-o, --output FILE ", "--fps N ", "--schema FILE ", "--mirror ", "--edge-rule RULE ",
                             "--threads N ", "--no-animation ", "--quantize-rotations ", "--progress ",
                             "--no-progress "}) {
    EXPECT_TRUE(contains(build.output, std::string("\n  ") + option)) << option << "\n" << build.output;
  }
  const auto query = run_command(mmvk_ + " query --help");
  ASSERT_EQ(query.exit_code, 0) << query.output;
  for (const char* part : {"\n  --queries, --features FILE", "\n  --k K ", "\nquery options (applied to every query):\n",
                           "\n  --continuing-bias X ", "\n  --weights CHANNEL=W,...", "\nbackends (--backend NAME):\n"}) {
    EXPECT_TRUE(contains(query.output, part)) << part << "\n" << query.output;
  }
  const auto crowd = run_command(mmvk_ + " crowd --help");
  ASSERT_EQ(crowd.exit_code, 0) << crowd.output;
  for (const char* part : {"\n  --data NAME|PATH ", "\n  --foot-ik on|off ", "\nshipped motion sets",
                           "\n  cmu-walks ", "\nbackends:\n"}) {
    EXPECT_TRUE(contains(crowd.output, part)) << part << "\n" << crowd.output;
  }
}

TEST_F(CliUsage, UsageErrorsExitTwoAndNameTheProblem) {
  const std::string missing = (dir_ / "missing.mmdb").string();
  expect_usage_error("", {"usage: mmvk <command>"});
  expect_usage_error("frobnicate", {"unknown command 'frobnicate'"});
  expect_usage_error("build", {"usage: mmvk build "});
  expect_usage_error("clusters " + missing, {"usage: mmvk clusters "});  // -o is required
  expect_usage_error("inspect --bogus " + missing, {"mmvk inspect: unknown option '--bogus' (see mmvk inspect --help)"});
  expect_usage_error("inspect " + missing + " extra", {"mmvk inspect: unexpected argument 'extra'"});
  expect_usage_error("query " + missing + " --k", {"mmvk query: --k needs a value"});
  // Exactly one of --queries and --pose-targets.
  expect_usage_error("query " + missing, {"usage: mmvk query "});
  expect_usage_error("query " + missing + " --queries q.f32 --pose-targets t.json", {"usage: mmvk query "});
  // "--name=" is an empty value, named like any bad one.
  expect_usage_error("clusters " + missing + " -o " + (dir_ / "t.mmkc").string() + " --seed=",
                     {"--seed expects a non-negative integer, got ''"});
  expect_usage_error("query " + missing + " --queries q.f32 --k=-3", {"--k expects an integer in [1, 16], got '-3'"});
  EXPECT_TRUE(fs::is_empty(dir_)) << "a usage error wrote a file";
}

// Issue 34: "--" ends the options as POSIX says (it was "unknown option
// '--'"), and an empty --data names the option (it was ": no such file").
TEST_F(CliUsage, DoubleDashEndsTheOptionsAndEmptyDataIsNamed) {
  const std::string missing = (dir_ / "missing.mmdb").string();
  const auto inspect = run_command(mmvk_ + " inspect -- " + missing);
  EXPECT_EQ(inspect.exit_code, 1) << inspect.output;
  EXPECT_NE(inspect.output.find(missing + ": no such file"), std::string::npos) << inspect.output;
  EXPECT_EQ(inspect.output.find("unknown option"), std::string::npos) << inspect.output;
  const auto crowd = run_command(mmvk_ + " crowd --data ''");
  EXPECT_EQ(crowd.exit_code, 1) << crowd.output;
  EXPECT_NE(crowd.output.find("--data is empty: name a shipped motion set"), std::string::npos) << crowd.output;
  EXPECT_TRUE(fs::is_empty(dir_)) << "a usage error wrote a file";
}

// An option given twice takes its last value, as a shell alias expects: the
// bad first --threads is replaced, so the error is the missing input.
TEST_F(CliUsage, TheLastOfARepeatedOptionCounts) {
  const auto ran = run_command(mmvk_ + " build " + (dir_ / "absent").string() + " -o " + (dir_ / "x.mmdb").string() +
                               " --threads many --threads 2");
  EXPECT_EQ(ran.exit_code, 1) << ran.output;
  EXPECT_FALSE(contains(ran.output, "--threads")) << ran.output;
  EXPECT_TRUE(contains(ran.output, "absent")) << ran.output;
}

TEST_F(CliUsage, VersionPrintsTheFormatItWrites) {
  const auto ran = run_command(mmvk_ + " --version");
  EXPECT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_TRUE(contains(ran.output, "mmvk 0.")) << ran.output;
  EXPECT_TRUE(contains(ran.output, "writes .mmdb version " + std::to_string(kDatabaseFormatVersion))) << ran.output;
}

TEST_F(CliUsage, MistypedDataSuggestsTheNearestShippedSet) {
  const auto ran = run_command(mmvk_ + " crowd --data cmu-walk --agents 2 --seconds 0.1");
  EXPECT_NE(ran.exit_code, 0) << ran.output;
  EXPECT_TRUE(contains(ran.output, "cmu-walk: no such file or folder, nor a shipped motion set: did you mean "
                                   "'cmu-walks'? (shipped: cmu-walk-run, cmu-walks)"))
      << ran.output;
  // A path gets no guess: it was not a name.
  const auto path = run_command(mmvk_ + " crowd --data " + (dir_ / "nowhere").string() + " --agents 2");
  EXPECT_TRUE(contains(path.output, "nowhere: no such file or folder")) << path.output;
  EXPECT_FALSE(contains(path.output, "did you mean")) << path.output;
}

}  // namespace
}  // namespace mmvk
