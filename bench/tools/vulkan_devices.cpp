// mmvk_vulkan_devices: one line per Vulkan physical device the loader
// finds (the index `mmvk crowd --device` takes, the name, its type, the
// driver and the API version), for bench/gpu_check.sh and anyone checking
// which device a run will get. Context::create picks a discrete GPU first,
// then an integrated one, then the others (CPU devices such as lavapipe
// last), in this order.
//
//   build/bench/mmvk_vulkan_devices
//
// Exit status: 0 when at least one device exists; 1 with one line saying
// why when there is none (no loader, no driver, no device).
#include <cstddef>
#include <cstdio>
#include <vector>

#include "mmvk/vulkan/context.hpp"

namespace {

const char* type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

}  // namespace

int main() {
  const mmvk::Result<std::vector<mmvk::vulkan::DeviceInfo>> devices = mmvk::vulkan::Context::enumerate_devices();
  if (!devices) {
    std::printf("no Vulkan device: %s\n", devices.message().c_str());
    return 1;
  }
  if (devices->empty()) {
    std::printf("no Vulkan device: the loader found a driver but no physical device\n");
    return 1;
  }
  for (std::size_t i = 0; i < devices->size(); ++i) {
    const mmvk::vulkan::DeviceInfo& d = (*devices)[i];
    std::printf("device %zu: %s | %s | %s | Vulkan %u.%u.%u | subgroup %u | %llu MiB device-local\n", i,
                d.name.c_str(), type_name(d.type), d.driver.c_str(), VK_API_VERSION_MAJOR(d.api_version),
                VK_API_VERSION_MINOR(d.api_version), VK_API_VERSION_PATCH(d.api_version), d.subgroup_size,
                static_cast<unsigned long long>(d.device_local_bytes >> 20));
  }
  return 0;
}
