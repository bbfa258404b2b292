// What a writer leaves (issue 34): the temp files of writers killed
// mid-write are removed by the next writer in their folder, and a FIFO
// output nobody reads fails after a wait instead of blocking forever.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <string>
#include <thread>

#include "mmvk/common/file_io.hpp"
#include "support/device_nodes.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The PID of a process that has exited (and been reaped): no process has it.
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return long(child);
}

std::string temp_of(const std::string& target, long pid) {
  return target + ".tmp-" + std::to_string(pid) + "-0123456789ab";
}

TEST(OutputLeftovers, TempsOfDeadWritersAreReapedByTheNextWriter) {
  const fs::path dir = test::make_temp_dir();
  const long dead = dead_pid();
  const fs::path stale = dir / temp_of("crowd-cmu-0a.mmdb", dead);
  const fs::path live = dir / temp_of("other.mmdb", long(::getppid()));  // a running process's
  const fs::path own = dir / temp_of("mine.mmdb", long(::getpid()));
  const fs::path unrelated = dir / "notes.tmp-12-not-a-temp";
  const fs::path old_style = dir / "old.mmdb.tmp-0123456789ab";  // no PID: not known to be stale
  for (const fs::path& path : {stale, live, own, unrelated, old_style}) std::ofstream(path) << "partial";
  fs::create_symlink(dir / "nowhere", dir / temp_of("link.mmdb", dead));

  ASSERT_TRUE(write_file_atomically(dir / "out.json", "{}\n").ok());
  EXPECT_FALSE(fs::exists(stale)) << "the dead writer's temp was kept";
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(own));
  EXPECT_TRUE(fs::exists(unrelated));
  EXPECT_TRUE(fs::exists(old_style));
  EXPECT_TRUE(fs::is_symlink(dir / temp_of("link.mmdb", dead))) << "a link is never removed";
  fs::remove_all(dir);
}

TEST(OutputLeftovers, TempsCarryTheWritersPid) {
  const fs::path dir = test::make_temp_dir();
  Result<OutputFile> out = OutputFile::open(dir / "page.html");
  ASSERT_TRUE(out.ok()) << out.message();
  bool found = false;
  for (const auto& entry : fs::directory_iterator(dir)) {
    found |= contains(entry.path().filename().string(), "page.html.tmp-" + std::to_string(::getpid()) + "-");
  }
  EXPECT_TRUE(found);
  ASSERT_TRUE(out->write("x").ok());
  ASSERT_TRUE(out->commit().ok());
  fs::remove_all(dir);
}

TEST(OutputLeftovers, AFifoWithoutAReaderFailsAfterTheWait) {
  const fs::path dir = test::make_temp_dir();
  ASSERT_TRUE(test::make_fifo(dir / "fifo"));
  // Before, open() blocked until a reader came: forever. Run it aside so
  // that a regression fails the test instead of hanging it.
  auto opened = std::async(std::launch::async, [&] {
    return OutputFile::open(dir / "fifo", OutputPolicy::UserPath, std::chrono::milliseconds(300)).status();
  });
  ASSERT_EQ(opened.wait_for(std::chrono::seconds(30)), std::future_status::ready) << "open() blocked on the FIFO";
  const Status status = opened.get();
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "fifo: is a FIFO that no reader opened within 0.3 s; not written"))
      << status.message();
  EXPECT_EQ(test::file_type(dir / "fifo"), "fifo");
  EXPECT_EQ(kFifoReaderWait, std::chrono::seconds(10));  // the wait docs/files-and-limits.md gives
  fs::remove_all(dir);
}

TEST(OutputLeftovers, AFifoWithAReaderIsWrittenBlocking) {
  const fs::path dir = test::make_temp_dir();
  ASSERT_TRUE(test::make_fifo(dir / "fifo"));
  // A reader that comes after the writer started waiting.
  auto read = std::async(std::launch::async, [&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    std::ifstream in(dir / "fifo", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  });
  const std::string bytes(1 << 20, 'm');  // more than a pipe holds: the writes block, as they should
  ASSERT_TRUE(write_file_atomically(dir / "fifo", bytes).ok());
  EXPECT_EQ(read.get(), bytes);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mmvk
