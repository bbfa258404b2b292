// `mmvk clusters` end to end: a saved table is deterministic, `mmvk query
// --clusters` reuses it with the reference's results and without training,
// a table from another database stays an error, bad options are named; and
// `mmvk query` keeps the Vulkan pipeline cache in $XDG_CACHE_HOME/mmvk,
// ignoring a damaged file with a note.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "support/command.hpp"
#include "support/query_results.hpp"
#include "support/cli_fixture.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::run_command;

using test::read_text;
using test::result_lines;

bool vulkan_required() {
  const char* value = std::getenv("MMVK_REQUIRE_VULKAN");
  return value != nullptr && std::string(value) == "1";
}

class ClustersCli : public test::CliFixture {
 protected:
  void SetUp() override {
    CliFixture::SetUp();
    if (IsSkipped()) return;
    const fs::path walks = data_ / "bandai-namco-nc" / "locomotion-normal";
    db_ = build("walks", walks / "dataset-2_walk_normal_001.bvh", walks / "dataset-2_run_normal_001.bvh");
    other_db_ = build("other", walks / "dataset-2_walk_normal_002.bvh", walks / "dataset-2_run_normal_002.bvh");
    // Queries: the database's own normalized rows (every 7th).
    const CommandResult exported = run_command(mmvk_ + " export " + db_ + " --features " + (dir_ / "f.f32").string());
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
    const std::string rows = read_text(dir_ / "f.f32");
    std::string queries;
    for (std::size_t at = 0; at + 27 * 4 <= rows.size(); at += 7 * 27 * 4) queries += rows.substr(at, 27 * 4);
    queries_ = (dir_ / "q.f32").string();
    std::ofstream(queries_, std::ios::binary) << queries;
  }

  std::string build(const std::string& name, const fs::path& first, const fs::path& second) {
    const fs::path manifest = dir_ / (name + ".json");
    std::ofstream(manifest) << R"({"clips": [{"file": ")" << first.string() << R"("}, {"file": ")" << second.string()
                            << R"("}]})";
    const std::string db = (dir_ / (name + ".mmdb")).string();
    const CommandResult built = run_command(mmvk_ + " build " + manifest.string() + " -o " + db);
    EXPECT_EQ(built.exit_code, 0) << built.output;
    return db;
  }

  std::string query(const std::string& db, const std::string& options) const {
    return mmvk_ + " query " + db + " --queries " + queries_ + " --normalized --k 3 " + options;
  }

  std::string db_;
  std::string other_db_;
  std::string queries_;
};

TEST_F(ClustersCli, SavedTableIsDeterministicAndReusedByQuery) {
  const std::string table = (dir_ / "t.mmkc").string();
  const std::string train = mmvk_ + " clusters " + db_ + " --clusters 9 --iterations 6 --seed 5 --no-progress -o ";
  const CommandResult trained = run_command(train + table);
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  EXPECT_NE(trained.output.find("9 clusters"), std::string::npos) << trained.output;
  ASSERT_EQ(run_command(train + (dir_ / "again.mmkc").string()).exit_code, 0);
  EXPECT_EQ(read_text(table), read_text(dir_ / "again.mmkc")) << "training is deterministic";

  const CommandResult reference = run_command(query(db_, "--backend reference --out " + (dir_ / "ref.tsv").string()));
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  std::vector<std::string> backends = {"clusters"};
  if (vulkan_required()) backends.push_back("vulkan-clusters");
  for (const std::string& backend : backends) {
    const fs::path out = dir_ / (backend + ".tsv");
    const CommandResult result =
        run_command(query(db_, "--backend " + backend + " --clusters " + table + " --out " + out.string()));
    ASSERT_EQ(result.exit_code, 0) << backend << ": " << result.output;
    EXPECT_EQ(result.output.find("training"), std::string::npos) << "the saved table was not reused: " << result.output;
    EXPECT_EQ(result_lines(out), result_lines(dir_ / "ref.tsv")) << backend;
  }
}

TEST_F(ClustersCli, TableFromAnotherDatabaseIsAnError) {
  const std::string table = (dir_ / "t.mmkc").string();
  ASSERT_EQ(run_command(mmvk_ + " clusters " + db_ + " -o " + table + " --clusters 6").exit_code, 0);
  for (const char* backend : {"clusters", "clusters-nprobe"}) {
    const CommandResult result = run_command(query(other_db_, std::string("--backend ") + backend + " --clusters " + table));
    EXPECT_NE(result.exit_code, 0) << backend << ": " << result.output;
    EXPECT_NE(result.output.find("database"), std::string::npos) << result.output;
  }
}

TEST_F(ClustersCli, ProgressBarOnRequestOnly) {
  const CommandResult shown = run_command(mmvk_ + " clusters " + db_ + " -o " + (dir_ / "a.mmkc").string() + " --progress");
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("[##############################] 100%"), std::string::npos) << shown.output;
  // The first report is always drawn (later ones at most every 100 ms).
  EXPECT_NE(shown.output.find("0%  seeding"), std::string::npos) << shown.output;
  // Not a terminal here: no bar unless asked.
  const CommandResult quiet = run_command(mmvk_ + " clusters " + db_ + " -o " + (dir_ / "b.mmkc").string());
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find('['), std::string::npos) << quiet.output;
}

TEST_F(ClustersCli, BadOptionsAreNamed) {
  const std::string base = mmvk_ + " clusters " + db_ + " -o " + (dir_ / "x.mmkc").string();
  for (const char* bad : {"--clusters 0", "--clusters 2.5", "--iterations x", "--seed -1", "--training-frames ''"}) {
    const CommandResult result = run_command(base + " " + bad);
    EXPECT_EQ(result.exit_code, 2) << bad << ": " << result.output;
    EXPECT_NE(result.output.find("expects"), std::string::npos) << bad << ": " << result.output;
    EXPECT_FALSE(fs::exists(dir_ / "x.mmkc")) << bad;
  }
  EXPECT_EQ(run_command(mmvk_ + " clusters " + db_).exit_code, 2) << "-o is required";
  const CommandResult too_many = run_command(base + " --clusters 100000000");
  EXPECT_EQ(too_many.exit_code, 1) << too_many.output;
  EXPECT_NE(too_many.output.find("exceeds"), std::string::npos) << too_many.output;
  const CommandResult missing = run_command(mmvk_ + " clusters " + (dir_ / "nope.mmdb").string() + " -o x.mmkc");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("nope.mmdb"), std::string::npos) << missing.output;
}

TEST_F(ClustersCli, QueryKeepsThePipelineCacheAndIgnoresADamagedOne) {
  if (!vulkan_required()) GTEST_SKIP() << "Vulkan not required here (MMVK_REQUIRE_VULKAN)";
  const fs::path cache = dir_ / "cache";
  const std::string env = "XDG_CACHE_HOME=" + cache.string() + " MESA_SHADER_CACHE_DIR=" + (dir_ / "mesa").string() + " ";
  const CommandResult reference = run_command(query(db_, "--backend reference --out " + (dir_ / "ref.tsv").string()));
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  const CommandResult first = run_command(env + query(db_, "--backend vulkan-brute --out " + (dir_ / "v1.tsv").string()));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_EQ(first.output.find("note"), std::string::npos) << first.output;
  fs::path file;
  for (const auto& entry : fs::directory_iterator(cache / "mmvk")) {
    if (entry.path().extension() == ".pipeline-cache") file = entry.path();
  }
  ASSERT_FALSE(file.empty()) << "no pipeline cache file under " << (cache / "mmvk");

  std::ofstream(file, std::ios::binary | std::ios::trunc) << "damaged";
  const CommandResult damaged = run_command(env + query(db_, "--backend vulkan-brute --out " + (dir_ / "v2.tsv").string()));
  ASSERT_EQ(damaged.exit_code, 0) << damaged.output;
  EXPECT_NE(damaged.output.find("note:"), std::string::npos) << damaged.output;
  EXPECT_NE(damaged.output.find(file.filename().string()), std::string::npos) << damaged.output;
  EXPECT_EQ(result_lines(dir_ / "v2.tsv"), result_lines(dir_ / "ref.tsv"));
  EXPECT_NE(read_text(file), "damaged") << "the next run replaces a damaged file";
  const CommandResult again = run_command(env + query(db_, "--backend vulkan-brute --out " + (dir_ / "v3.tsv").string()));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find("note"), std::string::npos) << again.output;
}

}  // namespace
}  // namespace mmvk
