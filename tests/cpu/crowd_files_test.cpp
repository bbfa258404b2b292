// `mmvk crowd`'s files and bounds (issue 23) on the shipped CMU walks: every
// output checked before the simulation and never the same file as an input,
// inputs that are FIFOs or devices refused at once, bad cache entries
// rebuilt with a note naming them, time and memory bounded up front, and a
// summary for any file name. Device nodes are private ones made with mknod
// in the test's folder (skipped where mknod is refused), never /dev.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/command.hpp"
#include "support/device_nodes.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;
using test::run_command;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class CrowdFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto cli = test::cli_binary();
    if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
    dir_ = test::make_temp_dir();
    // Every run caches into the test's own folder, never the user's; a
    // `timeout` turns a run that blocks (on a FIFO) into a failure.
    mmvk_ = "XDG_CACHE_HOME=" + (dir_ / "cache").string() + " timeout 300 " + cli->string();
    // A copy of the shipped data, so that no check can touch the source tree.
    data_ = dir_ / "cmu131";
    fs::copy(test::test_source_dir().parent_path() / "host" / "crowd" / "data" / "cmu131", data_);
  }

  test::CommandResult crowd(const std::string& args) const {
    return run_command(mmvk_ + " crowd --backend fast-box --data " + (data_ / "manifest.json").string() + " " + args);
  }

  // A clean failure (exit 1..127) whose output has every part.
  static void expect_failure(const test::CommandResult& result, const std::vector<std::string>& parts,
                             const std::string& what) {
    EXPECT_GE(result.exit_code, 1) << what << "\n" << result.output;
    EXPECT_LE(result.exit_code, 127) << what << "\n" << result.output;
    for (const std::string& part : parts) {
      EXPECT_TRUE(contains(result.output, part)) << what << ": no '" << part << "' in\n" << result.output;
    }
  }

  // The cache entry the first run made.
  fs::path cache_entry() const {
    for (const auto& entry : fs::directory_iterator(dir_ / "cache" / "mmvk")) {
      if (entry.path().extension() == ".mmdb") return entry.path();
    }
    return {};
  }

  fs::path dir_;
  fs::path data_;
  std::string mmvk_;
};

TEST_F(CrowdFiles, OutputsAreCheckedBeforeTheSimulation) {
  const auto missing = crowd("--agents 5 --seconds 1 --html " + (dir_ / "missing" / "c.html").string());
  expect_failure(missing, {"--html", (dir_ / "missing").string()}, "--html in a missing folder");
  EXPECT_FALSE(contains(missing.output, "building the database")) << missing.output;
  fs::create_directories(dir_ / "folder");
  expect_failure(crowd("--agents 5 --seconds 1 --summary " + (dir_ / "folder").string()),
                 {"--summary", "is a directory"}, "--summary DIR");
  const std::string same = (dir_ / "f").string();
  const auto twice = crowd("--agents 5 --seconds 1 --html " + same + " --summary " + same);
  expect_failure(twice, {"--summary", "--html", "one output would replace the other"}, "--html f --summary f");
  EXPECT_FALSE(contains(twice.output, "building the database")) << twice.output;
  EXPECT_FALSE(fs::exists(same));
}

TEST_F(CrowdFiles, OutputsThatAreInputsAreRefused) {
  const fs::path scenario = dir_ / "s.json";
  std::ofstream(scenario) << R"({"agents": [{"start": [0, 0], "goals": [[4, 0]]}]})";
  const std::string text = read_text(scenario);
  expect_failure(crowd("--scenario " + scenario.string() + " --summary " + scenario.string()),
                 {"--scenario", "--summary", "name the same file"}, "--summary over --scenario");
  EXPECT_EQ(read_text(scenario), text);
  const fs::path clip = data_ / "131_09.bvh";
  const std::string bvh = read_text(clip);
  expect_failure(crowd("--agents 5 --seconds 1 --html " + clip.string()), {"a clip of --data", "--html"},
                 "--html over a clip");
  EXPECT_EQ(read_text(clip), bvh);
  const fs::path manifest = data_ / "manifest.json";
  const std::string json = read_text(manifest);
  expect_failure(crowd("--agents 5 --seconds 1 --summary " + manifest.string()), {"--data", "--summary"},
                 "--summary over --data");
  EXPECT_EQ(read_text(manifest), json);
}

TEST_F(CrowdFiles, TimeOptionsAreBoundedAndNamed) {
  expect_failure(crowd("--rate 1e-6"), {"--rate 1e-06", "1 to 1000"}, "--rate 1e-6");
  expect_failure(crowd("--rate 1e9"), {"--rate 1e+09", "1 to 1000"}, "--rate 1e9");
  expect_failure(crowd("--seconds 0.01"), {"--seconds 0.01", "0 ticks"}, "0 ticks");
  expect_failure(crowd("--seconds 1e9"), {"--seconds 1e+09", "10000000 ticks"}, "too many ticks");
  expect_failure(crowd("--search-interval 1e-300"), {"--search-interval 1e-300", "0.001 to 3600"},
                 "--search-interval 1e-300");
}

TEST_F(CrowdFiles, MemoryIsBoundedUpFront) {
  // The most agents --agents allows (the search's batch limit), for an hour with a page.
  const auto huge = crowd("--agents 1048576 --seconds 3600 --html " + (dir_ / "h.html").string());
  expect_failure(huge, {"1048576 agents", "would need about", "GiB", "lower --agents"}, "1M agents for an hour");
  EXPECT_FALSE(contains(huge.output, "out of memory")) << huge.output;
  EXPECT_FALSE(fs::exists(dir_ / "h.html"));
}

TEST_F(CrowdFiles, ScenarioFilesAreStrictAndBounded) {
  const auto scenario = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return crowd("--scenario " + (dir_ / name).string());
  };
  expect_failure(scenario("dup.json", R"({"agents": [{"start": [0, 0], "goals": [[4, 0]], "start": [1, 1]}]})"),
                 {"dup.json", "duplicate key \"start\""}, "duplicate key");
  expect_failure(scenario("nul.json", std::string(R"({"agents": [{"start": [0, 0], "goals": [[4, 0]]}]})") +
                                          std::string(4, '\0')),
                 {"nul.json", "NUL byte"}, "trailing NULs");
  expect_failure(scenario("tail.json", R"({"agents": [{"start": [0, 0], "goals": [[4, 0]]}]} {})"),
                 {"tail.json", "not valid JSON"}, "trailing JSON");
  // A FIFO nobody writes to fails at once instead of blocking.
  ASSERT_TRUE(test::make_fifo(dir_ / "fifo.json"));
  expect_failure(crowd("--scenario " + (dir_ / "fifo.json").string()), {"--scenario", "FIFO", "not a regular file"},
                 "--scenario FIFO");
  if (test::make_device_node(dir_ / "zero", test::MemoryDevice::Zero)) {
    expect_failure(crowd("--scenario " + (dir_ / "zero").string()), {"--scenario", "character device"},
                   "--scenario zero device");
    EXPECT_EQ(test::file_type(dir_ / "zero"), "character device");
  }
}

TEST_F(CrowdFiles, BadCacheEntriesAreRebuiltWithANote) {
  const std::string run = "--agents 5 --seconds 1";
  const auto first = crowd(run);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const fs::path entry = cache_entry();
  ASSERT_FALSE(entry.empty());
  const std::string good = read_text(entry);

  // A database without animation under the entry's name.
  const auto built = run_command(mmvk_ + " build " + (data_ / "manifest.json").string() + " --no-animation -o " +
                                 (dir_ / "plain.mmdb").string());
  ASSERT_EQ(built.exit_code, 0) << built.output;
  fs::copy_file(dir_ / "plain.mmdb", entry, fs::copy_options::overwrite_existing);
  auto again = crowd(run);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(contains(again.output, entry.string() + " is not usable (it has no animation: built with --no-animation)")) << again.output;
  EXPECT_EQ(read_text(entry), good);

  // A database of other motion (one clip of the set).
  std::ofstream(dir_ / "one.json") << R"({"fps": 30, "clips": [{"file": ")" << (data_ / "131_09.bvh").string()
                                   << R"(", "name": "walk_left_09"}]})";
  ASSERT_EQ(run_command(mmvk_ + " build " + (dir_ / "one.json").string() + " -o " + (dir_ / "one.mmdb").string()).exit_code,
            0);
  fs::copy_file(dir_ / "one.mmdb", entry, fs::copy_options::overwrite_existing);
  again = crowd(run);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(contains(again.output, entry.string() + " is not usable")) << again.output;
  EXPECT_EQ(read_text(entry), good);

  // A symlink to a FIFO: refused without blocking, replaced by a regular file.
  ASSERT_TRUE(test::make_fifo(dir_ / "fifo"));
  fs::remove(entry);
  fs::create_symlink(dir_ / "fifo", entry);
  again = crowd(run);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(contains(again.output, entry.string() + " is not usable")) << again.output;
  EXPECT_TRUE(contains(again.output, "FIFO")) << again.output;
  EXPECT_EQ(test::file_type(entry), "regular");
  EXPECT_EQ(test::file_type(dir_ / "fifo"), "fifo");

  // A symlink to an endless device: refused at once, the device untouched.
  if (test::make_device_node(dir_ / "zero", test::MemoryDevice::Zero)) {
    fs::remove(entry);
    fs::create_symlink(dir_ / "zero", entry);
    again = crowd(run);
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_TRUE(contains(again.output, "character device")) << again.output;
    EXPECT_EQ(test::file_type(entry), "regular");
    EXPECT_EQ(test::file_type(dir_ / "zero"), "character device");
  }
}

TEST_F(CrowdFiles, TheSummaryTakesAnyFileName) {
  // Not UTF-8: a Latin-1 file name.
  const fs::path scenario = dir_ / "sc\xe9na\xffrio.json";
  std::ofstream(scenario) << R"({"agents": [{"start": [0, 0], "goals": [[4, 0]]}]})";
  const fs::path summary = dir_ / "summary.json";
  const auto ran = crowd("--seconds 1 --scenario '" + scenario.string() + "' --summary " + summary.string());
  ASSERT_EQ(ran.exit_code, 0) << ran.output;
  const nlohmann::json json = nlohmann::json::parse(read_text(summary), nullptr, false);
  ASSERT_FALSE(json.is_discarded()) << read_text(summary);
  EXPECT_TRUE(contains(json["scenario"].get<std::string>(), "\xef\xbf\xbd")) << json["scenario"];
}

TEST_F(CrowdFiles, AFifoOutputIsWrittenInPlace) {
  ASSERT_TRUE(test::make_fifo(dir_ / "page"));
  const std::string reader = "cat " + (dir_ / "page").string() + " > " + (dir_ / "copy.html").string() + " & ";
  const auto ran = run_command(reader + mmvk_ + " crowd --backend fast-box --data " + (data_ / "manifest.json").string() +
                               " --agents 5 --seconds 1 --html " + (dir_ / "page").string() + "; wait");
  ASSERT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_EQ(test::file_type(dir_ / "page"), "fifo");
  EXPECT_TRUE(contains(read_text(dir_ / "copy.html"), "mmvk-data")) << read_text(dir_ / "copy.html").size();
}

// Issue 34: the cache entry the run reads is an input: `--html ENTRY` made
// the entry an HTML page.
TEST_F(CrowdFiles, TheCacheEntryIsAnInput) {
  ASSERT_EQ(crowd("--agents 3 --seconds 0.2").exit_code, 0);
  const fs::path entry = cache_entry();
  ASSERT_FALSE(entry.empty());
  const std::string bytes = read_text(entry);
  const auto ran = crowd("--agents 3 --seconds 0.2 --html " + entry.string());
  expect_failure(ran, {"the cache entry", "--html", "name the same file"}, "--html over the cache entry");
  EXPECT_EQ(read_text(entry), bytes);
}

// Issue 34: an output FIFO nobody reads blocked the run forever (the
// second of two outputs on one FIFO, after the reader of the first left,
// hung the same way); it fails after kFifoReaderWait (10 s).
TEST_F(CrowdFiles, AFifoWithoutAReaderFailsInsteadOfHanging) {
  ASSERT_TRUE(test::make_fifo(dir_ / "page"));
  const auto start = std::chrono::steady_clock::now();
  const auto ran = crowd("--agents 3 --seconds 0.2 --html " + (dir_ / "page").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  expect_failure(ran, {"page: is a FIFO that no reader opened within 10 s"}, "--html FIFO without a reader");
  EXPECT_NE(ran.exit_code, 124) << "timed out (blocked): " << ran.output;
  EXPECT_LT(seconds, 120.0);
  EXPECT_EQ(test::file_type(dir_ / "page"), "fifo");
}

// Issue 34: past `ulimit -f` the kernel killed the run with SIGXFSZ and left
// its temp file; ignored, the write fails with EFBIG and the temp goes.
TEST_F(CrowdFiles, AFileSizeLimitIsAnErrorNotASignal) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  // 64 blocks of 512 bytes: the page is megabytes.
  const auto ran = run_command("ulimit -f 64 && " + mmvk_ + " crowd --backend fast-box --data " +
                               (data_ / "manifest.json").string() + " --agents 3 --seconds 0.5 --html " +
                               (out / "page.html").string());
  expect_failure(ran, {"page.html", "File too large"}, "ulimit -f");
  EXPECT_TRUE(fs::is_empty(out)) << "a temp file was left";
  for (const auto& entry : fs::recursive_directory_iterator(dir_ / "cache")) {
    EXPECT_FALSE(contains(entry.path().filename().string(), ".tmp-")) << entry.path();
  }
}

// Issue 34: a database not named *.mmdb was read as a manifest ("a NUL
// byte at offset 7"); it is known by its magic.
TEST_F(CrowdFiles, ADatabaseIsKnownByItsContent) {
  const fs::path db = dir_ / "walks.bin";
  const auto built = run_command(mmvk_ + " build " + (data_ / "manifest.json").string() + " -o " + db.string());
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const auto ran = run_command(mmvk_ + " crowd --backend fast-box --data " + db.string() + " --agents 3 --seconds 0.2");
  EXPECT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_FALSE(contains(ran.output, "NUL byte")) << ran.output;
}

}  // namespace
}  // namespace mmvk
