#include "suite_vulkan.hpp"

#include <cstdio>
#include <memory>

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/backends.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#endif

namespace mmvk::bench {

#if defined(MMVK_HAS_VULKAN)

namespace {

struct ContextHolder {
  bool tried = false;
  std::unique_ptr<vulkan::Context> context;
  std::string error;
};

ContextHolder& holder() {
  static ContextHolder h;
  return h;
}

}  // namespace

void prepare_vulkan_context() { (void)holder(); }

void add_vulkan_backends(BackendRegistry& registry) {
  vulkan::ContextSource source = []() -> Result<vulkan::Context*> {
    ContextHolder& h = holder();
    if (!h.tried) {
      h.tried = true;
      Result<std::unique_ptr<vulkan::Context>> created = vulkan::Context::create();
      if (created) {
        h.context = std::move(created).value();
        std::fprintf(stderr, "suite: Vulkan device %s\n", h.context->device_name().c_str());
      } else {
        h.error = created.message();
      }
    }
    if (!h.context) return make_error("no Vulkan context: " + h.error);
    return h.context.get();
  };
  if (Status added = vulkan::add_backends(registry, std::move(source)); !added) {
    std::fprintf(stderr, "suite: %s\n", added.message().c_str());
  }
}

vulkan::VulkanSearch* as_vulkan_search(SearchBackend& backend) { return dynamic_cast<vulkan::VulkanSearch*>(&backend); }

double last_kernel_seconds(const vulkan::VulkanSearch& search) { return search.last_kernel_seconds().value_or(0.0); }

#else

void prepare_vulkan_context() {}
void add_vulkan_backends(BackendRegistry&) {}
vulkan::VulkanSearch* as_vulkan_search(SearchBackend&) { return nullptr; }
double last_kernel_seconds(const vulkan::VulkanSearch&) { return 0.0; }

#endif

}  // namespace mmvk::bench
