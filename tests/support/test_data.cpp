#include "support/test_data.hpp"

#include <cstdlib>
#include <string>

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
  return dir;
}

}  // namespace mmvk::test
