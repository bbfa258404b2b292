// The mmvk command line under hostile input (issue 13): every case ends with
// an exit code in 1..127 (never a signal, never 0) and a message naming what
// was wrong. Uses one small real BVH from the data folder.
#include <sys/wait.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli_fixture.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

struct Ran {
  int exit_code = -1;    // the exit status, or -1 when killed by a signal
  std::string output;    // stdout and stderr together (unless redirected)
};

Ran run(const std::string& command, bool merge_stderr = true) {
  Ran ran;
  std::FILE* pipe = ::popen((command + (merge_stderr ? " 2>&1" : "")).c_str(), "r");
  if (!pipe) return ran;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) ran.output.append(buffer, n);
  const int status = ::pclose(pipe);
  ran.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return ran;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A failure as the issue requires: a clean exit code below 128 and every
// `parts` in the output.
void expect_clean_error(const Ran& ran, const std::vector<std::string>& parts, const std::string& what) {
  EXPECT_GE(ran.exit_code, 1) << what << "\n" << ran.output;
  EXPECT_LE(ran.exit_code, 127) << what << "\n" << ran.output;
  for (const std::string& part : parts) {
    EXPECT_NE(ran.output.find(part), std::string::npos) << what << ": no '" << part << "' in\n" << ran.output;
  }
}

class HostileCli : public test::CliFixture {
 protected:
  void SetUp() override {
    CliFixture::SetUp();
    if (IsSkipped()) return;
    bvh_ = data_ / "tiny" / "cmu_amc2bvh_131_09_frames300-419.bvh";
    fs::create_directories(dir_ / "clips");
    fs::copy_file(bvh_, dir_ / "clips" / "walk.bvh");
    db_ = (dir_ / "walk.mmdb").string();
    const Ran built = run(mmvk_ + " build " + (dir_ / "clips").string() + " --edge-rule clamp -o " + db_);
    ASSERT_EQ(built.exit_code, 0) << built.output;
    // One raw query: the database's first row, exported.
    const Ran exported = run(mmvk_ + " export " + db_ + " --features " + (dir_ / "rows.f32").string());
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
    const std::string rows = read_text(dir_ / "rows.f32");
    dims_ = 27;
    std::ofstream(dir_ / "q.f32", std::ios::binary) << rows.substr(0, 4 * dims_);
  }

  std::string query(const std::string& options) const {
    return mmvk_ + " query " + db_ + " --queries " + (dir_ / "q.f32").string() + " --normalized " + options;
  }

  // A copy of the BVH whose `line` (1-based) has its first number replaced
  // (or the whole line, with whole_line).
  fs::path corrupt_bvh(const std::string& name, int line, const std::string& value, bool whole_line = false) const {
    std::istringstream in(read_text(bvh_));
    std::ostringstream out;
    std::string text;
    for (int n = 1; std::getline(in, text); ++n) {
      if (n == line) text = whole_line ? value : value + text.substr(text.find(' '));
      out << text << "\n";
    }
    const fs::path folder = dir_ / name;
    fs::create_directories(folder);
    std::ofstream(folder / "walk.bvh") << out.str();
    return folder;
  }

  fs::path bvh_;
  std::string db_;
  std::uint32_t dims_ = 0;
};

TEST_F(HostileCli, ThreadCountsBeyondTheMaximumAreErrors) {
  for (const char* count : {"100000", "4294967297", "18446744073709551617"}) {
    expect_clean_error(run(query(std::string("--threads ") + count)), {"--threads"}, count);
    expect_clean_error(run(mmvk_ + " build " + (dir_ / "clips").string() + " -o " + (dir_ / "t.mmdb").string() +
                           " --threads " + count),
                       {"--threads"}, count);
    expect_clean_error(run(mmvk_ + " clusters " + db_ + " -o " + (dir_ / "t.mmkc").string() + " --threads " + count),
                       {"--threads"}, count);
  }
}

TEST_F(HostileCli, AFullStdoutIsAnError) {
  // stderr to the pipe, then stdout to the full device.
  const std::string full = " 2>&1 > /dev/full";
  expect_clean_error(run(query("") + full, false), {"standard output"}, "query");
  expect_clean_error(run(mmvk_ + " inspect " + db_ + full, false), {"standard output"}, "inspect");
  expect_clean_error(run(mmvk_ + " inspect --json " + db_ + full, false), {"standard output"}, "inspect --json");
  expect_clean_error(run(mmvk_ + " export " + db_ + " --features " + (dir_ / "e.f32").string() + full, false),
                     {"standard output"}, "export");
}

TEST_F(HostileCli, DirectoriesWhereFilesBelongAreNamed) {
  expect_clean_error(run(mmvk_ + " inspect " + dir_.string()), {dir_.string(), "is a directory"}, "inspect DIR");
  expect_clean_error(run(mmvk_ + " query " + db_ + " --queries " + dir_.string()),
                     {dir_.string(), "is a directory"}, "--queries DIR");
  std::ofstream(dir_ / "m.json") << R"({"clips": [{"file": "."}]})";
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + (dir_ / "m.mmdb").string()),
                     {"is a directory"}, "clip file .");
}

TEST_F(HostileCli, ImpossibleMotionNamesClipAndFrame) {
  // Line 187 is "Frame Time:", so line 190 is frame 2; its first value is
  // the root's X position.
  const fs::path folder = corrupt_bvh("huge", 190, "1e30");
  expect_clean_error(run(mmvk_ + " build " + folder.string() + " --edge-rule clamp -o " + (dir_ / "h.mmdb").string()),
                     {"walk.bvh", "clip 'walk'", "frame 1", "physically impossible", "limit"}, "1e30");
}

TEST_F(HostileCli, BadFrameRatesAreNamed) {
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "clips").string() + " --fps 1e-9 -o " +
                         (dir_ / "f.mmdb").string()),
                     {"fps", "outside the supported"}, "--fps 1e-9");
  const fs::path folder = corrupt_bvh("frame_time", 187, "Frame Time: 1e-30", true);
  expect_clean_error(run(mmvk_ + " build " + folder.string() + " -o " + (dir_ / "g.mmdb").string()),
                     {"walk.bvh", "Frame Time", "frames/s"}, "Frame Time 1e-30");
}

TEST_F(HostileCli, ADatabaseWithoutCandidatesIsABuildError) {
  // 120 frames at 120 fps, and the default schema looks 1 s ahead: with the
  // exclude edge rule no frame is left.
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "clips").string() + " -o " + (dir_ / "e.mmdb").string()),
                     {"no frame", "can be jumped to"}, "0 candidates");
}

TEST_F(HostileCli, DuplicateManifestKeysAreNamed) {
  std::ofstream(dir_ / "d.json") << R"({"edge_rule": "clamp", "clips": [{"file": "clips/walk.bvh", "loop": true, "loop": false}]})";
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "d.json").string() + " -o " + (dir_ / "d.mmdb").string()),
                     {"d.json", "duplicate key \"loop\""}, "duplicate key");
}

TEST_F(HostileCli, HugeNormalizedQueriesAreRejected) {
  std::vector<float> huge(dims_, 1e30f);
  std::ofstream(dir_ / "huge.f32", std::ios::binary)
      .write(reinterpret_cast<const char*>(huge.data()), std::streamsize(huge.size() * 4));
  const Ran ran = run(mmvk_ + " query " + db_ + " --queries " + (dir_ / "huge.f32").string() + " --normalized");
  expect_clean_error(ran, {"query 0", "overflow"}, "1e30 query");
  EXPECT_EQ(ran.output.find("inf"), std::string::npos) << ran.output;
}

TEST_F(HostileCli, OptionsABackendIgnoresAreErrors) {
  expect_clean_error(run(query("--backend fast-box --clusters " + (dir_ / "none.mmkc").string())),
                     {"--clusters", "fast-box"}, "--clusters with fast-box");
  expect_clean_error(run(query("--backend reference --nprobe 3")), {"--nprobe", "reference"}, "--nprobe with reference");
}

TEST_F(HostileCli, BadOptionsFailBeforeTheWork) {
  const Ran nprobe = run(query("--backend clusters-nprobe --nprobe 0"));
  expect_clean_error(nprobe, {"--nprobe"}, "--nprobe 0");
  EXPECT_EQ(nprobe.output.find("training"), std::string::npos) << nprobe.output;

  const Ran explain = run(query("--explain --frames 99999999"));
  expect_clean_error(explain, {"99999999"}, "--explain --frames 99999999");
  EXPECT_EQ(explain.output.find("\n0\t"), std::string::npos) << "results printed before the error:\n" << explain.output;

  // The output folder is checked before the build: this input would fail to
  // build too, so the message shows which check came first.
  const fs::path folder = corrupt_bvh("late", 190, "1e30");
  const Ran out = run(mmvk_ + " build " + folder.string() + " -o " + (dir_ / "missing" / "x.mmdb").string());
  expect_clean_error(out, {(dir_ / "missing").string()}, "-o into a missing folder");
  EXPECT_EQ(out.output.find("physically impossible"), std::string::npos) << out.output;
}

TEST_F(HostileCli, InspectEscapesControlCharacters) {
  std::ofstream(dir_ / "c.json") << R"({"edge_rule": "clamp", "clips": [{"file": "clips/walk.bvh", "name": "red\u001b[31mclip\u0007", "tags": ["t\u0001ag"]}]})";
  const std::string db = (dir_ / "c.mmdb").string();
  const Ran built = run(mmvk_ + " build " + (dir_ / "c.json").string() + " -o " + db);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const Ran inspected = run(mmvk_ + " inspect " + db);
  ASSERT_EQ(inspected.exit_code, 0) << inspected.output;
  EXPECT_EQ(inspected.output.find('\x1b'), std::string::npos);
  EXPECT_EQ(inspected.output.find('\x07'), std::string::npos);
  EXPECT_EQ(inspected.output.find('\x01'), std::string::npos);
  EXPECT_NE(inspected.output.find("red\\x1b[31mclip\\x07"), std::string::npos) << inspected.output;
}

// Huge inputs (issue 13, allocation failures): refused up front with the
// limit named, before anything that size is allocated. Sparse files: no disk
// space is used.
TEST_F(HostileCli, HugeQueryFilesAreRefusedBeforeReading) {
  const fs::path queries = dir_ / "huge.f32";
  std::ofstream(queries, std::ios::binary).put('\0');
  fs::resize_file(queries, std::uintmax_t{4} * dims_ * ((std::uintmax_t{1} << 20) + 1));  // kMaxBatch + 1 rows
  const Ran out = run(mmvk_ + " query " + db_ + " --queries " + queries.string() + " --normalized");
  expect_clean_error(out, {queries.string(), "1048577 queries", "over the limit of 1048576"}, "a huge query file");
}

TEST_F(HostileCli, HugeDatabaseFilesAreRefusedBeforeReading) {
  const fs::path db = dir_ / "huge.mmdb";
  std::ofstream(db, std::ios::binary) << "MMVKDB";
  fs::resize_file(db, (std::uintmax_t{4} << 30) + 1);
  const Ran out = run(mmvk_ + " inspect " + db.string());
  expect_clean_error(out, {db.string(), "4294967297 bytes", "kMaxFileBytes"}, "a 4 GiB + 1 database");
}

}  // namespace
}  // namespace mmvk
