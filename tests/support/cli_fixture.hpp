// The common start of the tests that run the `mmvk` command line on real
// data: skips without the motion data or the CLI binary, and gives the
// binary's path, the data folder and a fresh temporary folder.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace mmvk::test {

class CliFixture : public ::testing::Test {
 protected:
  // Derived SetUp()s call this first and return when IsSkipped().
  void SetUp() override {
    const auto data = find_data_dir();
    if (!data) GTEST_SKIP() << "motion data not found (set MMVK_DATA)";
    const auto cli = cli_binary();
    if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
    data_ = *data;
    mmvk_ = cli->string();
    dir_ = make_temp_dir();
  }

  std::filesystem::path data_;
  std::string mmvk_;
  std::filesystem::path dir_;
};

}  // namespace mmvk::test
