// The mmvk command line under hostile input (issue 13): every case ends with
// an exit code in 1..127 (never a signal, never 0) and a message naming what
// was wrong. Uses one small real BVH from the data folder.
#include <sys/wait.h>
#include <unistd.h>

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

// Issue 23: an output that is the same file as an input, or as another
// output, is refused before any work, naming both options; the file is
// left as it was.
TEST_F(HostileCli, OutputsThatAreInputsAreRefused) {
  const std::string before = read_text(db_);
  const auto expect_refused = [&](const std::string& args, const std::vector<std::string>& parts) {
    expect_clean_error(run(mmvk_ + " " + args), parts, args);
    EXPECT_EQ(read_text(db_), before) << args;
  };
  expect_refused("export " + db_ + " --features " + db_, {"the database", "--features", "name the same file"});
  expect_refused("export " + db_ + " --features " + (dir_ / "x.f32").string() + " --sidecar " + db_,
                 {"--sidecar", "name the same file"});
  expect_refused("clusters " + db_ + " -o " + db_, {"the database", "-o", "name the same file"});
  expect_refused("query " + db_ + " --queries " + (dir_ / "q.f32").string() + " --normalized --out " + db_,
                 {"--out", "name the same file"});
  // Another spelling of the same file (and a hard link) is the same file.
  fs::create_hard_link(db_, dir_ / "link.mmdb");
  expect_refused("clusters " + (dir_ / "link.mmdb").string() + " -o " + (dir_ / "clips" / ".." / "walk.mmdb").string(),
                 {"name the same file"});
  // Two outputs on one path.
  const Ran twice = run(mmvk_ + " export " + db_ + " --features " + (dir_ / "a.f32").string() + " --animation " +
                        (dir_ / "a.f32").string());
  expect_clean_error(twice, {"--features", "--animation", "one output would replace the other"}, "two outputs");
  EXPECT_FALSE(fs::exists(dir_ / "a.f32"));
  // build: the output may not be the manifest or a clip it reads.
  std::ofstream(dir_ / "m.json") << R"({"edge_rule": "clamp", "clips": ["clips/walk.bvh"]})";
  const std::string manifest = read_text(dir_ / "m.json");
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + (dir_ / "m.json").string()),
                     {"the manifest", "-o", "name the same file"}, "build -o manifest");
  EXPECT_EQ(read_text(dir_ / "m.json"), manifest);
  const std::string clip = read_text(dir_ / "clips" / "walk.bvh");
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "m.json").string() + " -o " + (dir_ / "clips" / "walk.bvh").string()),
                     {"the input", "name the same file"}, "build -o clip");
  EXPECT_EQ(read_text(dir_ / "clips" / "walk.bvh"), clip);
}

// Issue 23: the temp file of an output is created exclusively, so a symlink
// planted at the old writer's name ("<out>.tmp-<pid>") redirects nothing.
TEST_F(HostileCli, APlantedTempSymlinkRedirectsNothing) {
  std::ofstream(dir_ / "victim") << "precious";
  // The CLI's pid is not known in advance: plant a range of them.
  const int base = ::getpid();
  for (int pid = base; pid < base + 200; ++pid) {
    fs::create_symlink(dir_ / "victim", dir_ / ("out.tsv.tmp-" + std::to_string(pid)));
  }
  const Ran ran = run(query("--out " + (dir_ / "out.tsv").string()));
  ASSERT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_EQ(read_text(dir_ / "victim"), "precious");
  EXPECT_NE(read_text(dir_ / "out.tsv").find("# mmvk query"), std::string::npos);
}

// Issue 23: overflow found at build time is reported there, naming the clip
// or the schema channel and the field.
TEST_F(HostileCli, CostOverflowIsABuildErrorNamingClipAndField) {
  std::ofstream(dir_ / "mult.json") << R"({"edge_rule": "clamp", "clips": [{"file": "clips/walk.bvh", "name": "w", "cost_multiplier": 3e38}]})";
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "mult.json").string() + " -o " + (dir_ / "mult.mmdb").string()),
                     {"mult.json", "clip 'w'", "cost_multiplier", "overflow"}, "cost_multiplier 3e38");
  std::ofstream(dir_ / "weight.json") << R"({"edge_rule": "clamp", "clips": ["clips/walk.bvh"], "schema": {"channels": [
      {"name": "hip", "kind": "root_velocity", "weight": 1e38},
      {"name": "traj", "kind": "trajectory_position", "offsets_seconds": [0.5]}]}})";
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "weight.json").string() + " -o " + (dir_ / "weight.mmdb").string()),
                     {"weight.json", "channel 'hip'", "weight", "overflow"}, "weight 1e38");
  EXPECT_FALSE(fs::exists(dir_ / "mult.mmdb"));
  EXPECT_FALSE(fs::exists(dir_ / "weight.mmdb"));
}

// Issue 23: messages name the option and the target the user gave.
TEST_F(HostileCli, LenientOptionsAndFieldsAreErrors) {
  expect_clean_error(run(query("--continuing 4294967295")), {"--continuing", "[0, 119]"}, "--continuing none");
  expect_clean_error(run(query("--weights left_foot_position=2,left_foot_position=3")),
                     {"--weights", "left_foot_position", "twice"}, "--weights twice");
  std::ofstream(dir_ / "rav.json") << R"({"channels": [{"name": "turn", "kind": "root_angular_velocity", "bone": "Hips"}]})";
  expect_clean_error(run(mmvk_ + " build " + (dir_ / "clips").string() + " --schema " + (dir_ / "rav.json").string() +
                         " -o " + (dir_ / "rav.mmdb").string()),
                     {"rav.json", "bone", "root_angular_velocity channel reads no bone"}, "bone on root_angular_velocity");
  // Pose targets: duplicate keys, bytes after the JSON, NULs, huge targets.
  const auto pose = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return run(mmvk_ + " query " + db_ + " --pose-targets " + (dir_ / name).string());
  };
  expect_clean_error(pose("dup.json", R"({"targets": [{"bone": "@left_foot", "position": [0, 0, 0], "position": [1, 1, 1]}]})"),
                     {"dup.json", "duplicate key \"position\""}, "duplicate pose key");
  expect_clean_error(pose("nul.json", std::string(R"({"targets": [{"bone": "@left_foot", "position": [0, 0, 0]}]})") +
                                          std::string(3, '\0')),
                     {"nul.json", "NUL byte"}, "trailing NULs");
  expect_clean_error(pose("huge.json", R"({"targets": [{"bone": "@left_foot", "position": [1e30, 0, 0]}]})"),
                     {"huge.json", "targets[0].position", "too far"}, "huge target");
}

// Issue 23: hashes print one way (0x and 16 hex digits) everywhere.
TEST_F(HostileCli, HashesPrintInHexEverywhere) {
  const Ran text = run(mmvk_ + " inspect " + db_);
  ASSERT_EQ(text.exit_code, 0) << text.output;
  const std::size_t at = text.output.find("content hash: 0x");
  ASSERT_NE(at, std::string::npos) << text.output;
  const std::string hash = text.output.substr(at + 14, 18);
  const Ran json = run(mmvk_ + " inspect --json " + db_);
  EXPECT_NE(json.output.find("\"content_hash\": \"" + hash + "\""), std::string::npos) << json.output;
  // A table of another database names both hashes the same way.
  std::ofstream(dir_ / "o.json") << R"({"edge_rule": "clamp", "mirror": true, "clips": ["clips/walk.bvh"]})";
  const std::string other = (dir_ / "o.mmdb").string();
  ASSERT_EQ(run(mmvk_ + " build " + (dir_ / "o.json").string() + " -o " + other).exit_code, 0);
  ASSERT_EQ(run(mmvk_ + " clusters " + other + " -o " + (dir_ / "o.mmkc").string()).exit_code, 0);
  const Ran foreign = run(query("--backend clusters --clusters " + (dir_ / "o.mmkc").string()));
  expect_clean_error(foreign, {"another database", "this database's is " + hash}, "a foreign table");
}

// Issue 23: names that are not UTF-8 (a Latin-1 file name becomes a clip
// name) are replaced in every JSON output instead of aborting after an
// output was already replaced.
TEST_F(HostileCli, NamesThatAreNotUtf8AreReplacedInEveryJsonOutput) {
  fs::create_directories(dir_ / "latin1");
  fs::copy_file(bvh_, dir_ / "latin1" / "w\xe9lk.bvh");
  const std::string db = (dir_ / "latin1.mmdb").string();
  const Ran built = run(mmvk_ + " build " + (dir_ / "latin1").string() + " --edge-rule clamp -o " + db);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const std::string features = (dir_ / "l.f32").string(), animation = (dir_ / "a.f32").string();
  const Ran exported = run(mmvk_ + " export " + db + " --features " + features + " --animation " + animation);
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  const Ran inspected = run(mmvk_ + " inspect --json " + db + " > " + (dir_ / "i.json").string());
  ASSERT_EQ(inspected.exit_code, 0) << inspected.output;
  for (const fs::path& json : {fs::path(features + ".json"), fs::path(animation + ".json"), dir_ / "i.json"}) {
    const std::string text = read_text(json);
    EXPECT_NE(text.find("w\xef\xbf\xbdlk"), std::string::npos) << json;  // U+FFFD for the 0xE9 byte
    EXPECT_EQ(text.find("w\xe9lk"), std::string::npos) << json;
  }
}

// Issue 23: a manifest may name any file (.. and absolute paths are
// allowed), but one that is not BVH is rejected without echoing its content.
TEST_F(HostileCli, ANonBvhClipIsRejectedWithoutEchoingIt) {
  fs::create_directories(dir_ / "secret");
  std::ofstream(dir_ / "secret" / "shadow") << "root:$6$saltsalt$hashhashhash:19000:0:99999:7:::\n";
  fs::create_directories(dir_ / "m");
  std::ofstream(dir_ / "m" / "rel.json") << R"({"clips": ["../secret/shadow"]})";
  std::ofstream(dir_ / "m" / "abs.json") << R"({"clips": [")" << (dir_ / "secret" / "shadow").string() << R"("]})";
  for (const char* manifest : {"rel.json", "abs.json"}) {
    const Ran ran = run(mmvk_ + " build " + (dir_ / "m" / manifest).string() + " -o " + (dir_ / "s.mmdb").string());
    expect_clean_error(ran, {"shadow", "not a BVH file"}, manifest);
    EXPECT_EQ(ran.output.find("root:"), std::string::npos) << ran.output;
    EXPECT_EQ(ran.output.find("hash"), std::string::npos) << ran.output;
  }
  // Relative to the manifest, not to the working directory: ../clips/walk.bvh builds.
  std::ofstream(dir_ / "m" / "up.json") << R"({"edge_rule": "clamp", "clips": ["../clips/walk.bvh"]})";
  const Ran up = run("cd / && " + mmvk_ + " build " + (dir_ / "m" / "up.json").string() + " -o " + (dir_ / "up.mmdb").string());
  EXPECT_EQ(up.exit_code, 0) << up.output;
}

}  // namespace
}  // namespace mmvk
