#include "suite_vulkan.hpp"

#include <cstdio>
#include <string>

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/vulkan_search.hpp"
#endif

namespace mmvk::bench {

// The suite's one set of backends (a process-wide object is fine in a
// benchmark's main program, never in the library). No cache directory:
// every run measures the same cold start.
crowd::HostBackends& suite_backends() {
  static crowd::HostBackends backends;
  return backends;
}

void prepare_vulkan_context() { (void)suite_backends(); }

void note_vulkan_device(const SearchBackend& backend) {
  static bool noted = false;
  if (noted || crowd::HostBackends::on_cpu(backend.name())) return;
  noted = true;
  std::fprintf(stderr, "suite: Vulkan device %s\n", backend.device().c_str());
}

#if defined(MMVK_HAS_VULKAN)

vulkan::VulkanSearch* as_vulkan_search(SearchBackend& backend) { return dynamic_cast<vulkan::VulkanSearch*>(&backend); }

double last_kernel_seconds(const vulkan::VulkanSearch& search) { return search.last_kernel_seconds().value_or(0.0); }

#else

vulkan::VulkanSearch* as_vulkan_search(SearchBackend&) { return nullptr; }
double last_kernel_seconds(const vulkan::VulkanSearch&) { return 0.0; }

#endif

}  // namespace mmvk::bench
