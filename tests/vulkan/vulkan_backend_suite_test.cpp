// The shared backend suite (tests/support/backend_suite.hpp) for Vulkan
// brute force: once plainly and once with the Khronos validation layer,
// which must report zero messages.
#include <memory>

#include "mmvk/vulkan/vulkan_search.hpp"
#include "support/backend_suite.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

template <bool Validation>
struct VulkanFactory {
  std::unique_ptr<vulkan::Context> context;
  std::string error;

  VulkanFactory() {
    vulkan::ContextOptions options;
    options.validation = Validation;
    context = make_test_context(error, options);
  }
  ~VulkanFactory() {
    if (context && Validation) {
      const std::vector<std::string> messages = context->validation_messages();
      EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, the first: " << messages.front();
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

  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    if (!context) return make_error(error);
    vulkan::VulkanSearchOptions options;
    options.warm_up = false;  // compile only the variants a test uses
    Result<std::unique_ptr<vulkan::VulkanSearch>> search = vulkan::VulkanSearch::create(*context, db, options);
    if (!search) return search.error();
    return std::unique_ptr<SearchBackend>(std::move(search).value());
  }
};

using VulkanBackends = ::testing::Types<VulkanFactory<false>, VulkanFactory<true>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Vulkan, BackendSuite, VulkanBackends);

}  // namespace
}  // namespace mmvk::test
