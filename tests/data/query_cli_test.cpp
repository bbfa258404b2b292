// `mmvk query` end to end on a real database: every exact backend writes the
// same result lines as the reference, and bad query files get clear errors.
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/query_results.hpp"
#include "support/cli_fixture.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = 0;
  std::string output;  // stdout and stderr together
};

CommandResult run(const std::string& command) {
  CommandResult result;
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, n);
  result.exit_code = ::pclose(pipe);
  return result;
}

using test::read_text;
using test::result_lines;

class QueryCli : public test::CliFixture {
 protected:
  void SetUp() override {
    CliFixture::SetUp();
    if (IsSkipped()) return;
    db_ = (dir_ / "walks.mmdb").string();
    const fs::path walks = data_ / "bandai-namco-nc" / "locomotion-normal";
    std::ofstream(dir_ / "m.json") << R"({"mirror": true, "clips": [)"
                                   << R"({"file": ")" << (walks / "dataset-2_walk_normal_001.bvh").string() << R"("},)"
                                   << R"({"file": ")" << (walks / "dataset-2_run_normal_001.bvh").string() << R"("}]})";
    const CommandResult built = run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + db_);
    ASSERT_EQ(built.exit_code, 0) << built.output;
    const CommandResult exported = run(mmvk_ + " export " + db_ + " --features " + (dir_ / "features.f32").string());
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
  }

  // Queries: exported (normalized) rows plus noise, so minima are unique.
  fs::path write_queries(std::size_t count, std::uint32_t dims) {
    const std::string bytes = read_text(dir_ / "features.f32");
    const std::size_t frames = bytes.size() / (4 * dims);
    std::vector<float> rows(bytes.size() / 4);
    std::memcpy(rows.data(), bytes.data(), rows.size() * 4);
    std::mt19937 random(5);
    std::vector<float> queries;
    for (std::size_t q = 0; q < count; ++q) {
      const std::size_t frame = random() % frames;
      for (std::uint32_t d = 0; d < dims; ++d) {
        queries.push_back(rows[frame * dims + d] + float(int(random() % 2001) - 1000) * 1e-4f);
      }
    }
    const fs::path path = dir_ / "queries.f32";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(queries.data()),
                                                 std::streamsize(queries.size() * 4));
    return path;
  }

  std::string db_;
};

TEST_F(QueryCli, ExactBackendsWriteTheReferenceResults) {
  const fs::path queries = write_queries(23, 27);
  const std::string common = mmvk_ + " query " + db_ + " --queries " + queries.string() + " --normalized --k 5";
  const CommandResult reference = run(common + " --backend reference --out " + (dir_ / "reference.tsv").string());
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  const std::string expected = result_lines(dir_ / "reference.tsv");
  ASSERT_EQ(std::count(expected.begin(), expected.end(), '\n'), 23);
  std::vector<std::string> backends = {"fast-box", "fast-brute", "clusters"};
  // CI sets MMVK_REQUIRE_VULKAN=1; elsewhere a machine may have no device.
  const char* require_vulkan = std::getenv("MMVK_REQUIRE_VULKAN");
  if (require_vulkan && std::string(require_vulkan) == "1") backends.push_back("vulkan-brute");
  for (const std::string& backend : backends) {
    const fs::path out = dir_ / (backend + ".tsv");
    const CommandResult result = run(common + " --backend " + backend + " --out " + out.string());
    ASSERT_EQ(result.exit_code, 0) << backend << ": " << result.output;
    EXPECT_EQ(result_lines(out), expected) << backend;
  }
}

TEST_F(QueryCli, BadQueryFilesAreNamed) {
  const fs::path queries = dir_ / "short.f32";
  std::ofstream(queries, std::ios::binary) << std::string(4 * 27 + 2, '\0');
  const CommandResult result = run(mmvk_ + " query " + db_ + " --queries " + queries.string() + " --normalized");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("short.f32"), std::string::npos) << result.output;

  const CommandResult bad_k = run(mmvk_ + " query " + db_ + " --queries " + write_queries(1, 27).string() + " --k 17");
  EXPECT_NE(bad_k.exit_code, 0);
  EXPECT_NE(bad_k.output.find("k"), std::string::npos) << bad_k.output;

  const CommandResult bad_backend = run(mmvk_ + " query " + db_ + " --queries " + write_queries(1, 27).string() +
                                        " --backend nonsense");
  EXPECT_NE(bad_backend.exit_code, 0);
  EXPECT_NE(bad_backend.output.find("unknown backend 'nonsense'"), std::string::npos) << bad_backend.output;

  // Named before the database is read: with a missing database as well, the
  // backend is what the user hears about (no wait for a large load first).
  const CommandResult before_load = run(mmvk_ + " query " + (dir_ / "missing.mmdb").string() + " --queries " +
                                        write_queries(1, 27).string() + " --backend nonsense");
  EXPECT_NE(before_load.exit_code, 0);
  EXPECT_NE(before_load.output.find("unknown backend 'nonsense'"), std::string::npos) << before_load.output;
}

// --explain explains every query of the batch, --explain-queries only the
// named ones; a query's continuing frame is explained beside its winner.
TEST_F(QueryCli, ExplainCoversEveryQueryOrTheNamedOnes) {
  const std::string query = mmvk_ + " query " + db_ + " --queries " + write_queries(3, 27).string() + " --normalized";
  const CommandResult all = run(query + " --explain --continuing 40");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  for (const char* header : {"explain, query 0:\n", "explain, query 1:\n", "explain, query 2:\n"}) {
    EXPECT_NE(all.output.find(header), std::string::npos) << header << all.output;
  }
  const std::size_t first = all.output.find("explain, query 0:");
  EXPECT_NE(all.output.find("frame 40 (clip ", first), std::string::npos) << "the continuing frame\n" << all.output;

  const CommandResult named = run(query + " --explain-queries 2,0");
  ASSERT_EQ(named.exit_code, 0) << named.output;
  EXPECT_EQ(named.output.find("explain, query 1:"), std::string::npos) << named.output;
  const std::size_t two = named.output.find("explain, query 2:");
  const std::size_t zero = named.output.find("explain, query 0:");
  ASSERT_NE(two, std::string::npos) << named.output;
  ASSERT_NE(zero, std::string::npos) << named.output;
  EXPECT_LT(two, zero) << "explained in the order asked";

  const CommandResult beyond = run(query + " --explain-queries 3");
  EXPECT_NE(beyond.exit_code, 0);
  EXPECT_NE(beyond.output.find("--explain-queries"), std::string::npos) << beyond.output;
  EXPECT_NE(beyond.output.find("the batch has 3 queries"), std::string::npos) << beyond.output;
  EXPECT_EQ(beyond.output.find("\n0\t"), std::string::npos) << "results printed before the error:\n" << beyond.output;
}

// --help lists the backend registry itself: every name a --backend accepts.
TEST_F(QueryCli, HelpListsTheRegistry) {
  const CommandResult help = run(mmvk_ + " query --help");
  ASSERT_EQ(help.exit_code, 0) << help.output;
  for (const char* name : {"reference", "fast-brute", "fast-box", "clusters", "clusters-nprobe"}) {
    EXPECT_NE(help.output.find(std::string("\n  ") + name + " "), std::string::npos) << name << "\n" << help.output;
  }
  const char* require_vulkan = std::getenv("MMVK_REQUIRE_VULKAN");
  if (require_vulkan && std::string(require_vulkan) == "1") {
    for (const char* name : {"vulkan-brute", "vulkan-clusters", "vulkan-nprobe"}) {
      EXPECT_NE(help.output.find(std::string("\n  ") + name + " "), std::string::npos) << name;
    }
  }
  // The old names are gone: one name per backend.
  const CommandResult old = run(mmvk_ + " query " + db_ + " --queries " + write_queries(1, 27).string() +
                                " --backend nprobe");
  EXPECT_NE(old.exit_code, 0);
  EXPECT_NE(old.output.find("clusters-nprobe"), std::string::npos) << old.output;
}

}  // namespace
}  // namespace mmvk

namespace mmvk {
namespace {

// Every command parses its numbers through the same helpers (cli_args.hpp):
// the whole text must be a number of the right kind, and the error names
// the option. `build --threads 2.5` used to be taken as 2.
TEST_F(QueryCli, NumbersAreParsedStrictlyAndNamed) {
  const std::string query = mmvk_ + " query " + db_ + " --queries " + write_queries(2, 27).string() + " --normalized";
  const std::pair<const char*, const char*> bad[] = {
      {"--k", "2.5"},        {"--k", "0"},        {"--threads", "-1"},          {"--threads", "2x"},
      {"--nprobe", "0"},     {"--continuing", "1e3"}, {"--continuing-bias", "nan"}, {"--exclusion-window", ""},
      {"--frames", "4,x"}};
  for (const auto& [option, value] : bad) {
    std::string command = query + " " + option + "='" + value + "'";
    if (std::string(option) == "--nprobe") command += " --backend clusters-nprobe";
    if (std::string(option) == "--frames") command += " --explain";
    const CommandResult result = run(command);
    EXPECT_NE(result.exit_code, 0) << command;
    EXPECT_NE(result.output.find(std::string(option) + " expects"), std::string::npos) << command << "\n" << result.output;
  }
  for (const char* threads : {"2.5", "-2", "many"}) {
    const CommandResult built =
        run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + (dir_ / "t.mmdb").string() + " --threads " + threads);
    EXPECT_NE(built.exit_code, 0) << threads;
    EXPECT_NE(built.output.find("--threads expects"), std::string::npos) << built.output;
    EXPECT_FALSE(fs::exists(dir_ / "t.mmdb"));
  }
  const CommandResult fps = run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + (dir_ / "t.mmdb").string() +
                                " --fps 0");
  EXPECT_NE(fps.exit_code, 0);
  EXPECT_NE(fps.output.find("--fps expects a positive number"), std::string::npos) << fps.output;
}

}  // namespace
}  // namespace mmvk
