// Where tests find their inputs. Real motion capture comes from MMVK_DATA, or
// else ../shared/data beside the checkout. When MMVK_REQUIRE_DATA=1 (CI sets
// it) a missing data folder fails the test instead of skipping it.
#pragma once

#include <filesystem>
#include <optional>

#include <gtest/gtest.h>

namespace mmvk::test {

// The data folder, or nullopt when it is missing (after recording a failure
// if data is required).
std::optional<std::filesystem::path> find_data_dir();

// tests/ in the source tree (for the malformed-BVH corpus and fixtures).
std::filesystem::path test_source_dir();

// The built `mmvk` command line, or nullopt when the build has no host
// programs (MMVK_BUILD_HOST=OFF).
std::optional<std::filesystem::path> cli_binary();

// A fresh, empty temporary directory unique to the running test, removed
// when the test ends unless it failed (made outside a test: when the
// program ends).
std::filesystem::path make_temp_dir();

}  // namespace mmvk::test

// Use at the top of a test body: binds `dir` to the data folder, or skips
// (fails when MMVK_REQUIRE_DATA=1) when there is none.
#define MMVK_REQUIRE_DATA_DIR(dir)                                        \
  const auto mmvk_data_dir_opt_ = ::mmvk::test::find_data_dir();          \
  if (!mmvk_data_dir_opt_) GTEST_SKIP() << "motion data not found (set MMVK_DATA)"; \
  const std::filesystem::path dir = *mmvk_data_dir_opt_
