#include "support/test_data.hpp"

#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

namespace mmvk::test {

std::optional<std::filesystem::path> find_data_dir() {
  const char* from_env = std::getenv("MMVK_DATA");
  const std::filesystem::path dir = from_env && *from_env ? from_env : MMVK_DEFAULT_DATA_DIR;
  if (std::filesystem::is_directory(dir)) return dir;
  const char* required = std::getenv("MMVK_REQUIRE_DATA");
  if (required && std::string(required) == "1") {
    ADD_FAILURE() << "motion data folder " << dir << " not found, and MMVK_REQUIRE_DATA=1";
  }
  return std::nullopt;
}

std::filesystem::path test_source_dir() { return MMVK_TEST_SOURCE_DIR; }

std::optional<std::filesystem::path> cli_binary() {
#if defined(MMVK_CLI_PATH)
  return std::filesystem::path(MMVK_CLI_PATH);
#else
  return std::nullopt;
#endif
}

namespace {

// Removes the temporary directories of a test when it ends, and those made
// outside a test (a suite's shared setup) when the program ends, unless
// something failed: then they stay for a look (a failure's message names
// its files). Thousands of runs must not fill /tmp.
class TempDirCleaner : public ::testing::EmptyTestEventListener {
 public:
  void add(std::filesystem::path dir, bool in_test) {
    (in_test ? test_dirs_ : program_dirs_).push_back(std::move(dir));
  }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (!info.result()->Failed()) remove(test_dirs_);
    test_dirs_.clear();
  }
  void OnTestProgramEnd(const ::testing::UnitTest& unit) override {
    if (unit.Passed()) remove(program_dirs_);
    program_dirs_.clear();
  }

 private:
  static void remove(const std::vector<std::filesystem::path>& dirs) {
    for (const std::filesystem::path& dir : dirs) {
      std::error_code ignored;  // best effort: a leftover directory fails no test
      std::filesystem::remove_all(dir, ignored);
    }
  }
  std::vector<std::filesystem::path> test_dirs_, program_dirs_;
};

TempDirCleaner& temp_dir_cleaner() {
  // Owned by GoogleTest's listener list once appended.
  static TempDirCleaner* cleaner = [] {
    auto* made = new TempDirCleaner;
    ::testing::UnitTest::GetInstance()->listeners().Append(made);
    return made;
  }();
  return *cleaner;
}

}  // namespace

std::filesystem::path make_temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = "mmvk-test-" + std::to_string(::getpid());
  if (info) name += std::string("-") + info->test_suite_name() + "-" + info->name();
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  temp_dir_cleaner().add(dir, info != nullptr);
  return dir;
}

}  // namespace mmvk::test
