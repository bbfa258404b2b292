// The shared backend suite (tests/support/backend_suite.hpp) for Vulkan
// brute force: once plainly and once with the Khronos validation layer,
// which must report zero messages.
#include <memory>

#include "mmvk/search/backends.hpp"
#include "mmvk/vulkan/backends.hpp"
#include "support/backend_data_suite.hpp"
#include "support/backend_suite.hpp"
#include "vulkan_test_env.hpp"

namespace mmvk::test {
namespace {

template <bool Validation>
struct VulkanFactory : VulkanRegistryFactory {
  VulkanFactory() : VulkanRegistryFactory(options()) {}
  ~VulkanFactory() {
    if (context && Validation) {
      const std::vector<std::string> messages = context->validation_messages();
      EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, the first: " << messages.front();
    }
  }

  static vulkan::ContextOptions options() {
    vulkan::ContextOptions options;
    options.validation = Validation;
    return options;
  }

  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    if (!context) return make_error(error);
    return registry.make(BackendSpec{.name = "vulkan-brute"}, db);  // warm_up off (VulkanRegistryFactory)
  }
};

using VulkanBackends = ::testing::Types<VulkanFactory<false>, VulkanFactory<true>>;
INSTANTIATE_TYPED_TEST_SUITE_P(Vulkan, BackendSuite, VulkanBackends);
// Real features, and every channel kind (the data suite needs the motion data).
INSTANTIATE_TYPED_TEST_SUITE_P(Vulkan, BackendDataSuite, VulkanBackends);

}  // namespace
}  // namespace mmvk::test
