// How Vulkan tests get their Context: a test skips when no Vulkan device
// exists and MMVK_REQUIRE_VULKAN is unset, and fails when it is set (CI sets
// it and pins lavapipe), so a missing driver never passes silently.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "mmvk/search/backends.hpp"
#include "mmvk/vulkan/backends.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_brute_force.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::test {

// The Vulkan types every Vulkan test names.
using vulkan::Context;
using vulkan::ContextOptions;
using vulkan::VulkanBruteForce;
using vulkan::VulkanSearch;
using vulkan::VulkanSearchOptions;

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

// VulkanSearch options without designated initializers (GCC warns about
// the members they leave out).
inline vulkan::VulkanSearchOptions search_options(std::uint32_t max_batch, std::uint32_t max_k,
                                                  std::uint32_t max_tile = 16, bool warm_up = true) {
  vulkan::VulkanSearchOptions options;
  options.max_batch = max_batch;
  options.max_k = max_k;
  options.max_tile = max_tile;
  options.warm_up = warm_up;
  return options;
}

// The Vulkan backends in a registry over one test Context, for the typed
// backend suites' factories: `error` says why there is no context (or why
// the backends could not be added); skip_reason() turns that into a skip,
// or a failure when MMVK_REQUIRE_VULKAN is set. warm_up is off: compile
// only the variants a test uses.
struct VulkanRegistryFactory {
  std::unique_ptr<vulkan::Context> context;
  BackendRegistry registry;
  std::string error;

  explicit VulkanRegistryFactory(const vulkan::ContextOptions& options = {}) {
    context = make_test_context(error, options);
    if (context) {
      const vulkan::VulkanSearchOptions search = search_options(1024, kMaxK, 16, false);
      if (Status added = vulkan::add_backends(registry, *context, search); !added) error = added.message();
    }
  }

  std::string skip_reason() {
    if (context) return {};
    if (vulkan_required()) {
      ADD_FAILURE() << error;
      return {};
    }
    return error;
  }
};

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
