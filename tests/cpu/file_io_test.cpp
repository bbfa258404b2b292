// The public file I/O (mmvk/common/file_io.hpp): float32 row files round-trip bit
// for bit, and wrong sizes are errors naming the file; the one writer
// (exclusive temp files, devices and FIFOs written in place, failures that
// keep the old file) and the one reader (regular files only, capped, never
// blocked by a FIFO). Device nodes are private ones made with mknod in the
// test's folder, never the machine's /dev.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "mmvk/common/file_io.hpp"
#include "support/device_nodes.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

TEST(FileIo, FloatRowsRoundTripBitForBit) {
  const fs::path dir = test::make_temp_dir();
  const std::vector<float> values = {0.0f, -0.0f, 1.5f, -3.25e-20f, std::numeric_limits<float>::infinity(),
                                     std::numeric_limits<float>::denorm_min()};
  ASSERT_TRUE(write_f32_rows(dir / "rows.f32", values).ok());
  Result<std::string> bytes = read_file(dir / "rows.f32");
  ASSERT_TRUE(bytes.ok()) << bytes.message();
  ASSERT_EQ(bytes->size(), values.size() * 4);
  // Little-endian on disk whatever the host: 1.5f is 0x3FC00000.
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[8 + 3]), 0x3F);
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[8 + 2]), 0xC0);
  for (const std::uint32_t cols : {1u, 2u, 3u, 6u}) {
    Result<std::vector<float>> read = read_f32_rows(dir / "rows.f32", cols);
    ASSERT_TRUE(read.ok()) << read.message();
    ASSERT_EQ(read->size(), values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>((*read)[i]), std::bit_cast<std::uint32_t>(values[i])) << i;
    }
  }
  EXPECT_TRUE(read_f32_rows(dir / "rows.f32", 3, 2).ok());
}

TEST(FileIo, FloatRowSizesAreCheckedAndNamed) {
  const fs::path dir = test::make_temp_dir();
  ASSERT_TRUE(write_f32_rows(dir / "six.f32", std::vector<float>(6, 1.0f)).ok());
  ASSERT_TRUE(write_file_atomically(dir / "odd.f32", std::string(10, '\0')).ok());
  ASSERT_TRUE(write_file_atomically(dir / "empty.f32", "").ok());
  auto expect_error = [](const Result<std::vector<float>>& result, const std::string& needle) {
    ASSERT_FALSE(result.ok()) << needle;
    EXPECT_NE(result.message().find(needle), std::string::npos) << result.message();
  };
  expect_error(read_f32_rows(dir / "six.f32", 4), "six.f32");            // not whole rows
  expect_error(read_f32_rows(dir / "odd.f32", 1), "odd.f32");            // not whole floats
  expect_error(read_f32_rows(dir / "empty.f32", 3), "empty.f32");        // no rows
  expect_error(read_f32_rows(dir / "six.f32", 3, 3), "expected 3 rows");  // another row count
  expect_error(read_f32_rows(dir / "six.f32", 0), "six.f32");            // no columns
  expect_error(read_f32_rows(dir / "missing.f32", 3), "missing.f32");    // unreadable
  // An expected count of zero rows accepts the empty file.
  Result<std::vector<float>> none = read_f32_rows(dir / "empty.f32", 3, 0);
  ASSERT_TRUE(none.ok()) << none.message();
  EXPECT_TRUE(none->empty());
}

TEST(FileIo, CodecAppendsAndDecodes) {
  std::string bytes = "head";
  const std::vector<float> values = {1.0f, -2.0f, 0.5f};
  append_f32_le(bytes, values);
  ASSERT_EQ(bytes.size(), 4 + values.size() * 4);
  std::vector<float> decoded(values.size());
  decode_f32_le(std::string_view(bytes).substr(4), decoded);
  EXPECT_EQ(decoded, values);
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(SafeWriter, ReplacesARegularFileAndKeepsItsMode) {
  const fs::path dir = test::make_temp_dir();
  const fs::path out = dir / "out.txt";
  std::ofstream(out) << "old";
  ::chmod(out.c_str(), 0600);
  ASSERT_TRUE(write_file_atomically(out, "new").ok());
  EXPECT_EQ(slurp(out), "new");
  struct stat st {};
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);  // a private file stays private
  EXPECT_EQ(entries(dir), 1u);          // no temp file left behind
}

TEST(SafeWriter, PlantedSymlinksAtTempNamesAreNeverFollowed) {
  const fs::path dir = test::make_temp_dir();
  const fs::path victim = dir / "victim";
  std::ofstream(victim) << "precious";
  // The old writer's predictable name, and a few guesses at the new one's.
  fs::create_symlink(victim, dir / ("out.tmp-" + std::to_string(::getpid())));
  for (int i = 0; i < 8; ++i) fs::create_symlink(victim, dir / ("out.tmp-00000000000" + std::to_string(i)));
  ASSERT_TRUE(write_file_atomically(dir / "out", "data").ok());
  EXPECT_EQ(slurp(victim), "precious");
  EXPECT_EQ(test::file_type(dir / "out"), "regular");
  EXPECT_EQ(slurp(dir / "out"), "data");
}

TEST(SafeWriter, ASymlinkToAFileReplacesTheFileAndKeepsTheLink) {
  const fs::path dir = test::make_temp_dir();
  std::ofstream(dir / "real") << "old";
  fs::create_symlink("real", dir / "link");
  ASSERT_TRUE(write_file_atomically(dir / "link", "new").ok());
  EXPECT_EQ(test::file_type(dir / "link"), "symlink");
  EXPECT_EQ(slurp(dir / "real"), "new");
}

TEST(SafeWriter, DanglingSymlinksAndDirectoriesAreErrors) {
  const fs::path dir = test::make_temp_dir();
  fs::create_symlink(dir / "elsewhere" / "file", dir / "dangling");
  const Status dangling = write_file_atomically(dir / "dangling", "x");
  ASSERT_FALSE(dangling.ok());
  EXPECT_TRUE(contains(dangling.message(), "symlink to a missing file")) << dangling.message();
  EXPECT_FALSE(check_writable(dir / "dangling").ok());
  EXPECT_FALSE(fs::exists(dir / "elsewhere"));
  fs::create_directories(dir / "folder");
  const Status folder = write_file_atomically(dir / "folder", "x");
  ASSERT_FALSE(folder.ok());
  EXPECT_TRUE(contains(folder.message(), "is a directory")) << folder.message();
  EXPECT_FALSE(check_writable(dir / "missing" / "out").ok());
}

TEST(SafeWriter, AnUncommittedOutputLeavesTheOldFile) {
  const fs::path dir = test::make_temp_dir();
  std::ofstream(dir / "out") << "old";
  {
    Result<OutputFile> out = OutputFile::open(dir / "out");
    ASSERT_TRUE(out.ok()) << out.message();
    EXPECT_FALSE(out->in_place());
    ASSERT_TRUE(out->write("half of the n").ok());
  }  // destroyed before commit(): an error on the way
  EXPECT_EQ(slurp(dir / "out"), "old");
  EXPECT_EQ(entries(dir), 1u);
}

TEST(SafeWriter, AFifoIsWrittenInPlace) {
  const fs::path dir = test::make_temp_dir();
  const fs::path fifo = dir / "pipe";
  ASSERT_TRUE(test::make_fifo(fifo));
  EXPECT_TRUE(check_writable(fifo).ok());
  EXPECT_TRUE(is_stream_path(fifo));
  std::future<std::string> reader = std::async(std::launch::async, [&] { return slurp(fifo); });
  ASSERT_TRUE(write_file_atomically(fifo, "through the pipe").ok());
  EXPECT_EQ(reader.get(), "through the pipe");
  EXPECT_EQ(test::file_type(fifo), "fifo");
  EXPECT_EQ(entries(dir), 1u);
}

TEST(SafeWriter, AnOpenDescriptorNameWritesThroughTheDescriptor) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const fs::path name = "/dev/fd/" + std::to_string(fds[1]);
  EXPECT_TRUE(is_stream_path(name));
  ASSERT_TRUE(check_writable(name).ok());
  ASSERT_TRUE(write_file_atomically(name, "to the descriptor").ok());
  ::close(fds[1]);
  char buffer[64] = {};
  const ssize_t got = ::read(fds[0], buffer, sizeof(buffer));
  ::close(fds[0]);
  EXPECT_EQ(std::string(buffer, got > 0 ? std::size_t(got) : 0), "to the descriptor");
  // A descriptor that is not open is an error, not a new file.
  EXPECT_FALSE(check_writable("/dev/fd/987654").ok());
}

TEST(SafeWriter, DeviceNodesAreWrittenInPlaceAndFullDevicesFail) {
  const fs::path dir = test::make_temp_dir();
  if (!test::make_device_node(dir / "null", test::MemoryDevice::Null) ||
      !test::make_device_node(dir / "full", test::MemoryDevice::Full)) {
    GTEST_SKIP() << "mknod is not permitted here";
  }
  ASSERT_TRUE(check_writable(dir / "null").ok());
  ASSERT_TRUE(write_file_atomically(dir / "null", "discarded").ok());
  EXPECT_EQ(test::file_type(dir / "null"), "character device");
  const Status full = write_file_atomically(dir / "full", "no room");
  ASSERT_FALSE(full.ok());
  EXPECT_TRUE(contains(full.message(), "full")) << full.message();
  EXPECT_TRUE(contains(full.message(), "No space left")) << full.message();
  EXPECT_EQ(test::file_type(dir / "full"), "character device");
  EXPECT_EQ(entries(dir), 2u);
}

TEST(SafeWriter, ACacheEntryReplacesWhateverStandsAtItsName) {
  const fs::path dir = test::make_temp_dir();
  std::ofstream(dir / "victim") << "precious";
  fs::create_symlink(dir / "victim", dir / "entry");
  ASSERT_TRUE(write_file_atomically(dir / "entry", "cached", OutputPolicy::CacheEntry).ok());
  EXPECT_EQ(test::file_type(dir / "entry"), "regular");
  EXPECT_EQ(slurp(dir / "victim"), "precious");
  ASSERT_TRUE(test::make_fifo(dir / "fifo-entry"));
  ASSERT_TRUE(write_file_atomically(dir / "fifo-entry", "cached", OutputPolicy::CacheEntry).ok());
  EXPECT_EQ(test::file_type(dir / "fifo-entry"), "regular");
}

TEST(SafeReader, NonRegularFilesAreRefusedWithoutBlocking) {
  const fs::path dir = test::make_temp_dir();
  ASSERT_TRUE(test::make_fifo(dir / "fifo"));
  fs::create_symlink(dir / "fifo", dir / "link-to-fifo");
  // Would block forever in open() or read() if the reader waited for a writer.
  for (const char* name : {"fifo", "link-to-fifo"}) {
    std::future<Result<std::string>> read =
        std::async(std::launch::async, [&] { return read_file(dir / name); });
    ASSERT_EQ(read.wait_for(std::chrono::seconds(20)), std::future_status::ready) << name;
    const Result<std::string> result = read.get();
    ASSERT_FALSE(result.ok()) << name;
    EXPECT_TRUE(contains(result.message(), "FIFO")) << result.message();
    EXPECT_TRUE(contains(result.message(), "not a regular file")) << result.message();
  }
  // A stream where the caller accepts one: no writer reads as empty.
  std::future<Result<std::string>> stream =
      std::async(std::launch::async, [&] { return read_file(dir / "fifo", ReadOptions{1024, true}); });
  ASSERT_EQ(stream.wait_for(std::chrono::seconds(20)), std::future_status::ready);
  const Result<std::string> empty = stream.get();
  ASSERT_TRUE(empty.ok()) << empty.message();
  EXPECT_TRUE(empty->empty());
}

TEST(SafeReader, EndlessDevicesFailAtOnceOrAtTheCap) {
  const fs::path dir = test::make_temp_dir();
  if (!test::make_device_node(dir / "zero", test::MemoryDevice::Zero)) GTEST_SKIP() << "mknod is not permitted here";
  fs::create_symlink(dir / "zero", dir / "cache-entry.mmdb");
  const Result<std::string> linked = read_file(dir / "cache-entry.mmdb");
  ASSERT_FALSE(linked.ok());
  EXPECT_TRUE(contains(linked.message(), "character device")) << linked.message();
  // Accepted as a stream, it is read up to the cap only.
  const Result<std::string> capped = read_file(dir / "zero", ReadOptions{1 << 20, true});
  ASSERT_FALSE(capped.ok());
  EXPECT_TRUE(contains(capped.message(), "over the limit of 1048576")) << capped.message();
}

TEST(SafeReader, RegularFilesOverTheCapAreRefusedBeforeReading) {
  const fs::path dir = test::make_temp_dir();
  std::ofstream(dir / "big") << std::string(2000, 'x');
  const Result<std::string> big = read_file(dir / "big", ReadOptions{1000, false});
  ASSERT_FALSE(big.ok());
  EXPECT_TRUE(contains(big.message(), "2000 bytes, over the limit of 1000")) << big.message();
  EXPECT_TRUE(read_file(dir / "big", ReadOptions{2000, false}).ok());
}

TEST(SameFile, NamesOfOneFileAreRecognised) {
  const fs::path dir = test::make_temp_dir();
  std::ofstream(dir / "a") << "a";
  std::ofstream(dir / "b") << "b";
  fs::create_hard_link(dir / "a", dir / "hard");
  fs::create_symlink(dir / "a", dir / "soft");
  fs::create_directories(dir / "sub");
  EXPECT_TRUE(same_file(dir / "a", dir / "hard"));
  EXPECT_TRUE(same_file(dir / "a", dir / "soft"));
  EXPECT_TRUE(same_file(dir / "a", dir / "sub" / ".." / "a"));
  EXPECT_FALSE(same_file(dir / "a", dir / "b"));
  // Outputs that do not exist yet: the same path, spelled two ways.
  EXPECT_TRUE(same_file(dir / "new", dir / "sub" / ".." / "new"));
  EXPECT_FALSE(same_file(dir / "new", dir / "other"));
  EXPECT_FALSE(same_file(dir / "a", dir / "new"));
}

}  // namespace
}  // namespace mmvk
