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
#include <vulkan/vulkan.h>

#include <cstdint>
#include <cstdio>
#include <vector>

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

// The largest device-local heap, MiB.
std::uint64_t device_local_mib(VkPhysicalDevice device) {
  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(device, &memory);
  std::uint64_t largest = 0;
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if ((memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0 && memory.memoryHeaps[h].size > largest) {
      largest = memory.memoryHeaps[h].size;
    }
  }
  return largest >> 20;
}

}  // namespace

int main() {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "mmvk_vulkan_devices";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  VkInstance instance = VK_NULL_HANDLE;
  if (const VkResult result = vkCreateInstance(&info, nullptr, &instance); result != VK_SUCCESS) {
    std::printf("no Vulkan device: vkCreateInstance failed (VkResult %d: no driver the loader can use)\n", int(result));
    return 1;
  }
  std::uint32_t count = 0;
  VkResult result = vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  if (result == VK_SUCCESS && count > 0) result = vkEnumeratePhysicalDevices(instance, &count, devices.data());
  if (result != VK_SUCCESS || count == 0) {
    std::printf("no Vulkan device: the loader found a driver but %s\n",
                result != VK_SUCCESS ? "vkEnumeratePhysicalDevices failed" : "no physical device");
    vkDestroyInstance(instance, nullptr);
    return 1;
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    VkPhysicalDeviceSubgroupProperties subgroup{};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    subgroup.pNext = &driver;
    VkPhysicalDeviceProperties2 properties{};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(devices[i], &properties);
    const VkPhysicalDeviceProperties& p = properties.properties;
    std::printf("device %u: %s | %s | %s %s | Vulkan %u.%u.%u | subgroup %u | %llu MiB device-local\n", i,
                p.deviceName, type_name(p.deviceType), driver.driverName, driver.driverInfo,
                VK_API_VERSION_MAJOR(p.apiVersion), VK_API_VERSION_MINOR(p.apiVersion),
                VK_API_VERSION_PATCH(p.apiVersion), subgroup.subgroupSize,
                static_cast<unsigned long long>(device_local_mib(devices[i])));
  }
  vkDestroyInstance(instance, nullptr);
  return 0;
}
