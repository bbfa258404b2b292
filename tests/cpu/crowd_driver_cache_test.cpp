// The guard of Mesa's shader disk cache (host/crowd/backends/driver_cache.hpp): a
// driver whose cache folder is full or unwritable died with SIGBUS in its
// cache thread (issue 34); the host turns the driver's disk cache off first.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "backends/driver_cache.hpp"

namespace mmvk::crowd {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class DriverCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("mmvk-driver-cache-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    for (const char* name : {"MESA_SHADER_CACHE_DIR", "MESA_SHADER_CACHE_DISABLE"}) {
      const char* value = std::getenv(name);
      saved_.emplace_back(name, value ? std::optional<std::string>(value) : std::nullopt);
      ::unsetenv(name);
    }
  }
  void TearDown() override {
    for (const auto& [name, value] : saved_) {
      if (value) ::setenv(name.c_str(), value->c_str(), 1);
      else ::unsetenv(name.c_str());
    }
    std::filesystem::remove_all(dir_);
  }
  std::filesystem::path dir_;
  std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

TEST_F(DriverCache, AWritableFolderWithRoomIsUsed) {
  EXPECT_EQ(driver_cache_problem(dir_), "");
  // Not there yet: Mesa creates it in the folder above.
  EXPECT_EQ(driver_cache_problem(dir_ / "mesa_shader_cache" / "deeper"), "");
  // The probe file is gone again.
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

TEST_F(DriverCache, AFullDiskOrAFileIsAProblem) {
  const std::string full = driver_cache_problem(dir_, std::numeric_limits<std::uint64_t>::max());
  EXPECT_TRUE(contains(full, "MiB free (under ")) << full;
  const std::filesystem::path file = dir_ / "mesa_shader_cache";
  std::ofstream(file) << "not a folder";
  const std::string not_folder = driver_cache_problem(file);
  EXPECT_TRUE(contains(not_folder, "mesa_shader_cache is not a folder")) << not_folder;
}

TEST_F(DriverCache, TheGuardTurnsTheDriversCacheOffOnlyWhenItMust) {
  ::setenv("MESA_SHADER_CACHE_DIR", dir_.c_str(), 1);
  EXPECT_EQ(guard_driver_shader_cache(), "");
  EXPECT_EQ(std::getenv("MESA_SHADER_CACHE_DISABLE"), nullptr);
  const std::filesystem::path file = dir_ / "cache-file";
  std::ofstream(file) << "x";
  ::setenv("MESA_SHADER_CACHE_DIR", file.c_str(), 1);
  const std::string note = guard_driver_shader_cache();
  EXPECT_TRUE(contains(note, "is not a folder, so the driver runs with its disk cache off")) << note;
  ASSERT_NE(std::getenv("MESA_SHADER_CACHE_DISABLE"), nullptr);
  EXPECT_STREQ(std::getenv("MESA_SHADER_CACHE_DISABLE"), "true");
  // The user's own setting stands.
  ::setenv("MESA_SHADER_CACHE_DISABLE", "false", 1);
  EXPECT_EQ(guard_driver_shader_cache(), "");
  EXPECT_STREQ(std::getenv("MESA_SHADER_CACHE_DISABLE"), "false");
}

}  // namespace
}  // namespace mmvk::crowd
