// Issue 23: the mmvk command line, run as root, against device nodes. As
// root the old writer renamed its temp file over `--out /dev/null`, which
// broke the whole machine. Here every output and input is a private node
// made with mknod in the test's own folder (a null, full or zero device:
// major 1), never the machine's /dev; the test skips where mknod is refused
// (not root, or a nodev file system) and checks that every node is still a
// character device afterwards.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/command.hpp"
#include "support/device_nodes.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;
using test::run_command;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class DeviceNodesCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto cli = test::cli_binary();
    if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
    dir_ = test::make_temp_dir();
    if (!test::make_device_node(dir_ / "null", test::MemoryDevice::Null) ||
        !test::make_device_node(dir_ / "null2", test::MemoryDevice::Null) ||
        !test::make_device_node(dir_ / "full", test::MemoryDevice::Full) ||
        !test::make_device_node(dir_ / "zero", test::MemoryDevice::Zero)) {
      GTEST_SKIP() << "mknod is not permitted here (not root, or a nodev file system)";
    }
    fs::create_symlink(dir_ / "null", dir_ / "link-to-null");
    mmvk_ = "XDG_CACHE_HOME=" + (dir_ / "cache").string() + " timeout 300 " + cli->string();
    // A small database from one shipped clip, and one query row.
    const fs::path shipped = test::test_source_dir().parent_path() / "host" / "crowd" / "data" / "cmu131";
    fs::create_directories(dir_ / "clips");
    fs::copy_file(shipped / "131_09.bvh", dir_ / "clips" / "walk.bvh");
    db_ = (dir_ / "walk.mmdb").string();
    const auto built = run_command(mmvk_ + " build " + (dir_ / "clips").string() + " -o " + db_);
    ASSERT_EQ(built.exit_code, 0) << built.output;
    const auto exported = run_command(mmvk_ + " export " + db_ + " --features " + (dir_ / "rows.f32").string());
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
    fs::copy_file(dir_ / "rows.f32", dir_ / "q.f32");
    fs::resize_file(dir_ / "q.f32", 27 * 4);
  }

  void TearDown() override {
    if (IsSkipped()) return;
    for (const char* node : {"null", "null2", "full", "zero"}) {
      EXPECT_EQ(test::file_type(dir_ / node), "character device") << node << " was replaced";
    }
    EXPECT_EQ(test::file_type(dir_ / "link-to-null"), "symlink");
    // No temp file was left beside the nodes.
    for (const auto& entry : fs::directory_iterator(dir_)) {
      EXPECT_FALSE(contains(entry.path().filename().string(), ".tmp-")) << entry.path();
    }
  }

  std::string node(const char* name) const { return (dir_ / name).string(); }
  std::string query(const std::string& options) const {
    return mmvk_ + " query " + db_ + " --queries " + node("q.f32") + " --normalized " + options;
  }

  fs::path dir_;
  std::string mmvk_;
  std::string db_;
};

TEST_F(DeviceNodesCli, OutputsToANullDeviceAreWrittenInPlace) {
  for (const std::string& command :
       {query("--out " + node("null")), query("--out " + node("link-to-null")),
        mmvk_ + " export " + db_ + " --features " + node("null") + " --sidecar " + node("null2"),
        mmvk_ + " clusters " + db_ + " -o " + node("null") + " --clusters 4",
        mmvk_ + " build " + (dir_ / "clips").string() + " -o " + node("null"),
        mmvk_ + " crowd --backend fast-box --data " + db_ + " --agents 3 --seconds 1 --summary " + node("null") +
            " --html " + node("null")}) {
    const auto ran = run_command(command);
    EXPECT_EQ(ran.exit_code, 0) << command << "\n" << ran.output;
  }
}

// A default sidecar would be a new file beside the device (in /dev).
TEST_F(DeviceNodesCli, DefaultSidecarsBesideADeviceAreRefused) {
  // Issue 34: --trace on a device made NODE.json beside it, as export did not.
  for (const std::string& command : {mmvk_ + " export " + db_ + " --features " + node("null"),
                                     mmvk_ + " export " + db_ + " --animation " + node("null"),
                                     mmvk_ + " crowd --backend fast-box --data " + db_ +
                                         " --agents 3 --seconds 0.2 --trace " + node("null")}) {
    const auto ran = run_command(command);
    EXPECT_GE(ran.exit_code, 1) << command << "\n" << ran.output;
    EXPECT_LE(ran.exit_code, 127) << command << "\n" << ran.output;
    EXPECT_TRUE(contains(ran.output, "is a device or FIFO")) << command << "\n" << ran.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "null.json"));
}

TEST_F(DeviceNodesCli, AFullDeviceIsAnError) {
  for (const std::string& command :
       {query("--out " + node("full")), mmvk_ + " export " + db_ + " --features " + node("full") + " --sidecar " +
                                             node("null"),
        mmvk_ + " crowd --backend fast-box --data " + db_ + " --agents 3 --seconds 1 --summary " + node("full")}) {
    const auto ran = run_command(command);
    EXPECT_GE(ran.exit_code, 1) << command << "\n" << ran.output;
    EXPECT_LE(ran.exit_code, 127) << command << "\n" << ran.output;
    EXPECT_TRUE(contains(ran.output, "No space left on device")) << command << "\n" << ran.output;
  }
}

TEST_F(DeviceNodesCli, DevicesAreNoInputs) {
  for (const std::string& command :
       {mmvk_ + " inspect " + node("zero"), mmvk_ + " query " + node("zero") + " --queries " + node("q.f32"),
        mmvk_ + " build " + node("zero") + " -o " + (dir_ / "z.mmdb").string(),
        mmvk_ + " query " + db_ + " --pose-targets " + node("zero"),
        mmvk_ + " crowd --backend fast-box --data " + node("zero")}) {
    const auto ran = run_command(command);
    EXPECT_GE(ran.exit_code, 1) << command << "\n" << ran.output;
    EXPECT_LE(ran.exit_code, 127) << command << "\n" << ran.output;
    EXPECT_TRUE(contains(ran.output, "character device") || contains(ran.output, "not a regular file"))
        << command << "\n" << ran.output;
  }
  // --queries is documented to take a stream: a device is read up to the cap.
  const auto stream = run_command(query("").replace(query("").find(node("q.f32")), node("q.f32").size(), node("zero")));
  EXPECT_GE(stream.exit_code, 1) << stream.output;
  EXPECT_LE(stream.exit_code, 127) << stream.output;
  EXPECT_TRUE(contains(stream.output, "over the limit")) << stream.output;
}

}  // namespace
}  // namespace mmvk
