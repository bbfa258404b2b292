// How Vulkan tests get their Context: a test skips when no Vulkan device
// exists and MMVK_REQUIRE_VULKAN is unset, and fails when it is set (CI sets
// it and pins lavapipe), so a missing driver never passes silently.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "mmvk/vulkan/context.hpp"

namespace mmvk::test {

inline bool vulkan_required() {
  const char* value = std::getenv("MMVK_REQUIRE_VULKAN");
  return value != nullptr && *value != '\0' && std::string(value) != "0";
}

// A Context, or nullptr with `reason` set (the caller skips or fails).
inline std::unique_ptr<vulkan::Context> make_test_context(std::string& reason,
                                                          const vulkan::ContextOptions& options = {}) {
  Result<std::unique_ptr<vulkan::Context>> context = vulkan::Context::create(options);
  if (context.ok()) return std::move(context).value();
  reason = "no usable Vulkan device: " + context.message();
  return nullptr;
}

}  // namespace mmvk::test

// Binds `var` (std::unique_ptr<Context>) or skips the test; fails instead
// when MMVK_REQUIRE_VULKAN is set.
#define MMVK_VULKAN_CONTEXT(var, options)                                       \
  std::string mmvk_vulkan_reason_;                                              \
  std::unique_ptr<::mmvk::vulkan::Context> var =                                \
      ::mmvk::test::make_test_context(mmvk_vulkan_reason_, options);            \
  if (!var) {                                                                   \
    if (::mmvk::test::vulkan_required()) FAIL() << mmvk_vulkan_reason_;         \
    GTEST_SKIP() << mmvk_vulkan_reason_ << " (set MMVK_REQUIRE_VULKAN=1 to fail)"; \
  }
