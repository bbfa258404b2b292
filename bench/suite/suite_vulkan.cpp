#include "suite_vulkan.hpp"

#include <cstdio>
#include <memory>

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/backends.hpp"
#include "mmvk/vulkan/lazy_context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#endif

namespace mmvk::bench {

#if defined(MMVK_HAS_VULKAN)

namespace {

// The suite's one context (a process-wide object is fine in a benchmark's
// main program, never in the library). No cache directory: every run
// measures the same cold start.
vulkan::LazyContext& lazy_context() {
  static vulkan::LazyContext context;
  return context;
}

}  // namespace

void prepare_vulkan_context() { (void)lazy_context(); }

void add_vulkan_backends(BackendRegistry& registry) {
  vulkan::LazyContext& lazy = lazy_context();
  // The helper makes the context; this source also says which device it is.
  vulkan::ContextSource source = [&lazy]() -> Result<vulkan::Context*> {
    const bool first = lazy.created() == nullptr;
    Result<vulkan::Context*> context = lazy.get();
    if (!context) return make_error("no Vulkan context: " + context.message());
    if (first) std::fprintf(stderr, "suite: Vulkan device %s\n", (*context)->device_name().c_str());
    return context;
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
