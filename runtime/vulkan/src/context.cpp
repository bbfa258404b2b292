#include "mmvk/vulkan/context.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "check.hpp"
#include "pipeline_cache_blob.hpp"

namespace mmvk::vulkan {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  // Only warnings and errors count; the loader also reports info lines.
  if ((severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) != 0) {
    static_cast<Context*>(user)->record_validation_message(data != nullptr && data->pMessage != nullptr ? data->pMessage
                                                                                                         : "(no message)");
  }
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messenger_info(Context* context) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = debug_callback;
  info.pUserData = context;
  return info;
}

bool layer_available(const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

int type_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

const char* device_type_text(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU, software Vulkan";
    default: return "other";
  }
}

// A queue family with compute, preferring one with timestamps.
std::optional<std::uint32_t> find_compute_family(VkPhysicalDevice device) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  std::optional<std::uint32_t> found;
  for (std::uint32_t i = 0; i < count; ++i) {
    if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0 || families[i].queueCount == 0) continue;
    if (!found || (families[*found].timestampValidBits == 0 && families[i].timestampValidBits != 0)) found = i;
  }
  return found;
}

std::string version_string(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

// The properties read beyond VkPhysicalDeviceProperties, in one
// vkGetPhysicalDeviceProperties2 chain (all core in Vulkan 1.2). Filled in
// place: the chain points into the struct itself.
struct ChainedProperties {
  VkPhysicalDeviceDriverProperties driver{};
  VkPhysicalDeviceMaintenance3Properties maintenance3{};
  VkPhysicalDeviceSubgroupProperties subgroup{};
  VkPhysicalDeviceProperties2 properties{};

  explicit ChainedProperties(VkPhysicalDevice device) {
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    maintenance3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES;
    maintenance3.pNext = &driver;
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    subgroup.pNext = &maintenance3;
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(device, &properties);
  }
  ChainedProperties(const ChainedProperties&) = delete;
  ChainedProperties& operator=(const ChainedProperties&) = delete;
};

// The largest device-local heap, bytes.
VkDeviceSize device_local_bytes(VkPhysicalDevice device) {
  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(device, &memory);
  VkDeviceSize largest = 0;
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if ((memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0) {
      largest = std::max(largest, memory.memoryHeaps[h].size);
    }
  }
  return largest;
}

Result<std::vector<VkPhysicalDevice>> physical_devices(VkInstance instance) {
  std::uint32_t count = 0;
  MMVK_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  MMVK_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  devices.resize(count);
  return devices;
}

Result<VkInstance> create_instance(const ContextOptions& options, Context* context) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = options.application_name.c_str();
  app.pEngineName = "mmvk";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  const std::array<VkValidationFeatureEnableEXT, 1> enabled_features = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT validation_features{};
  VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(context);
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  if (options.validation) {
    if (!layer_available(kValidationLayer)) {
      return make_error(std::string("Vulkan context: validation requested but ") + kValidationLayer +
                        " is not installed (Debian: vulkan-validationlayers)");
    }
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    validation_features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    validation_features.enabledValidationFeatureCount = static_cast<std::uint32_t>(enabled_features.size());
    validation_features.pEnabledValidationFeatures = enabled_features.data();
    // Chained so messages from vkCreateInstance itself are collected too.
    validation_features.pNext = &messenger;
    info.pNext = &validation_features;
  }
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    return make_error("Vulkan context: no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER)");
  }
  MMVK_VK_CHECK(result);
  return instance;
}

}  // namespace

Context::~Context() {
  if (owns_pipeline_cache_ && pipeline_cache_ != VK_NULL_HANDLE) {
    vkDestroyPipelineCache(device_, pipeline_cache_, nullptr);
  }
  if (owns_device_ && device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    vkDestroyDevice(device_, nullptr);
  }
  if (owns_instance_ && instance_ != VK_NULL_HANDLE) {
    if (messenger_ != VK_NULL_HANDLE) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy != nullptr) destroy(instance_, messenger_, nullptr);
    }
    vkDestroyInstance(instance_, nullptr);
  }
}

Result<std::unique_ptr<Context>> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> context(new Context());
  Result<VkInstance> instance = create_instance(options, context.get());
  if (!instance) return instance.error();
  context->instance_ = *instance;
  context->owns_instance_ = true;

  if (options.validation) {
    const VkDebugUtilsMessengerCreateInfoEXT info = messenger_info(context.get());
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(context->instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (create == nullptr) return make_error("Vulkan context: vkCreateDebugUtilsMessengerEXT is not available");
    MMVK_VK_CHECK(create(context->instance_, &info, nullptr, &context->messenger_));
  }

  Result<std::vector<VkPhysicalDevice>> devices = physical_devices(context->instance_);
  if (!devices) return devices.error();
  if (devices->empty()) return make_error("Vulkan context: no Vulkan device found (the loader reports no physical device)");

  // Candidates: Vulkan 1.2+ with a compute queue, ranked by device type;
  // enumeration order breaks ties.
  std::optional<std::uint32_t> chosen;
  if (options.device_index) {
    if (*options.device_index >= devices->size()) {
      return make_error("Vulkan context: device_index " + std::to_string(*options.device_index) + " is out of range (" +
                        std::to_string(devices->size()) + " devices)");
    }
    chosen = *options.device_index;
  } else {
    int best_rank = 1 << 30;
    for (std::uint32_t i = 0; i < devices->size(); ++i) {
      VkPhysicalDeviceProperties props;
      vkGetPhysicalDeviceProperties((*devices)[i], &props);
      if (props.apiVersion < VK_API_VERSION_1_2 || !find_compute_family((*devices)[i])) continue;
      if (type_rank(props.deviceType) < best_rank) {
        best_rank = type_rank(props.deviceType);
        chosen = i;
      }
    }
    if (!chosen) return make_error("Vulkan context: no device supports Vulkan 1.2 with a compute queue");
  }
  context->physical_device_ = (*devices)[*chosen];
  vkGetPhysicalDeviceProperties(context->physical_device_, &context->properties_);
  if (context->properties_.apiVersion < VK_API_VERSION_1_2) {
    return make_error("Vulkan context: device '" + std::string(context->properties_.deviceName) + "' supports Vulkan " +
                      version_string(context->properties_.apiVersion) + ", mmvk needs 1.2");
  }
  const std::optional<std::uint32_t> family = find_compute_family(context->physical_device_);
  if (!family) return make_error("Vulkan context: device '" + std::string(context->properties_.deviceName) + "' has no compute queue");
  context->queue_family_ = *family;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{};
  queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queue_info.queueFamilyIndex = *family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  VkDeviceCreateInfo device_info{};
  device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  MMVK_VK_CHECK(vkCreateDevice(context->physical_device_, &device_info, nullptr, &context->device_));
  context->owns_device_ = true;
  vkGetDeviceQueue(context->device_, *family, 0, &context->queue_);
  MMVK_TRY(context->init_device_info(options.limit_caps));
  MMVK_TRY(context->init_pipeline_cache(VK_NULL_HANDLE, options.pipeline_cache_data));
  return context;
}

Result<std::unique_ptr<Context>> Context::adopt(const AdoptedDevice& handles, VkPipelineCache pipeline_cache) {
  if (handles.instance == VK_NULL_HANDLE || handles.physical_device == VK_NULL_HANDLE ||
      handles.device == VK_NULL_HANDLE || handles.queue == VK_NULL_HANDLE) {
    return make_error("Vulkan context: adopt() needs an instance, a physical device, a device and a queue");
  }
  std::unique_ptr<Context> context(new Context());
  context->instance_ = handles.instance;
  context->physical_device_ = handles.physical_device;
  context->device_ = handles.device;
  context->queue_ = handles.queue;
  context->queue_family_ = handles.queue_family;
  vkGetPhysicalDeviceProperties(context->physical_device_, &context->properties_);
  if (context->properties_.apiVersion < VK_API_VERSION_1_2) {
    return make_error("Vulkan context: the adopted device supports Vulkan " +
                      version_string(context->properties_.apiVersion) + ", mmvk needs 1.2");
  }
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(context->physical_device_, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(context->physical_device_, &count, families.data());
  if (handles.queue_family >= count || (families[handles.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
    return make_error("Vulkan context: adopted queue family " + std::to_string(handles.queue_family) +
                      " does not exist or has no compute support");
  }
  MMVK_TRY(context->init_device_info({}));
  MMVK_TRY(context->init_pipeline_cache(pipeline_cache, {}));
  return context;
}

Status Context::init_device_info(const DeviceLimitCaps& caps) {
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
  VkPhysicalDeviceLimits& limits = properties_.limits;
  if (caps.max_storage_buffer_range != 0) {
    limits.maxStorageBufferRange = std::min(limits.maxStorageBufferRange, caps.max_storage_buffer_range);
  }
  if (caps.max_texel_buffer_elements != 0) {
    limits.maxTexelBufferElements = std::min(limits.maxTexelBufferElements, caps.max_texel_buffer_elements);
  }
  if (caps.heap_bytes != 0) {
    for (std::uint32_t h = 0; h < memory_properties_.memoryHeapCount; ++h) {
      memory_properties_.memoryHeaps[h].size = std::min(memory_properties_.memoryHeaps[h].size, caps.heap_bytes);
    }
  }
  const ChainedProperties chained(physical_device_);
  subgroup_size_ = std::max<std::uint32_t>(1, chained.subgroup.subgroupSize);
  max_allocation_size_ = chained.maintenance3.maxMemoryAllocationSize;

  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &count, families.data());
  timestamp_valid_bits_ = queue_family_ < count ? families[queue_family_].timestampValidBits : 0;
  if (properties_.limits.timestampPeriod <= 0.0f) timestamp_valid_bits_ = 0;
  init_description();
  return {};
}

void Context::init_description() {
  // The index is looked up rather than remembered from create(), so that an
  // adopted device gets it too; the instance lists its devices in one order.
  std::string index;
  if (Result<std::vector<VkPhysicalDevice>> devices = physical_devices(instance_); devices) {
    for (std::size_t i = 0; i < devices->size(); ++i) {
      if ((*devices)[i] == physical_device_) index = "Vulkan device " + std::to_string(i) + ", ";
    }
  }
  description_ = device_name() + " (" + index + device_type_text(properties_.deviceType) + ")";
}

Status Context::init_pipeline_cache(VkPipelineCache adopted, std::span<const std::byte> initial) {
  if (adopted != VK_NULL_HANDLE) {
    pipeline_cache_ = adopted;
    return {};
  }
  if (!initial.empty()) {
    // Checked here rather than left to the driver: the spec has drivers
    // check the header too, but a blob read from a user's disk may be
    // anything, and a rejected blob must only cost a note.
    const Status usable = detail::check_pipeline_cache_blob(initial, properties_);
    if (!usable) {
      pipeline_cache_note_ = usable.message() + "; starting with an empty cache";
      initial = {};
    }
  }
  VkPipelineCacheCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
  info.initialDataSize = initial.size();
  info.pInitialData = initial.empty() ? nullptr : initial.data();
  const VkResult created = vkCreatePipelineCache(device_, &info, nullptr, &pipeline_cache_);
  if (created != VK_SUCCESS && !initial.empty()) {
    pipeline_cache_note_ = std::string("pipeline cache: the driver refused the blob (") + detail::vk_result_name(created) +
                           "); starting with an empty cache";
    info.initialDataSize = 0;
    info.pInitialData = nullptr;
    MMVK_VK_CHECK(vkCreatePipelineCache(device_, &info, nullptr, &pipeline_cache_));
  } else {
    MMVK_VK_CHECK(created);
  }
  owns_pipeline_cache_ = true;
  return {};
}

Status Context::merge_pipeline_cache_data(std::span<const std::byte> blob) {
  MMVK_TRY(detail::check_pipeline_cache_blob(blob, properties_));
  VkPipelineCacheCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
  info.initialDataSize = blob.size();
  info.pInitialData = blob.data();
  VkPipelineCache loaded = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreatePipelineCache(device_, &info, nullptr, &loaded));
  const VkResult merged = vkMergePipelineCaches(device_, pipeline_cache_, 1, &loaded);
  vkDestroyPipelineCache(device_, loaded, nullptr);
  MMVK_VK_CHECK(merged);
  return {};
}

Result<std::vector<std::byte>> Context::pipeline_cache_data() const {
  // The size can grow between the two calls only if another thread builds
  // pipelines, which a Context does not allow; VK_INCOMPLETE is an error.
  std::size_t size = 0;
  MMVK_VK_CHECK(vkGetPipelineCacheData(device_, pipeline_cache_, &size, nullptr));
  std::vector<std::byte> data(size);
  MMVK_VK_CHECK(vkGetPipelineCacheData(device_, pipeline_cache_, &size, data.data()));
  data.resize(size);
  return data;
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard lock(messages_mutex_);
  return messages_;
}

std::size_t Context::validation_message_count() const {
  std::lock_guard lock(messages_mutex_);
  return messages_.size();
}

void Context::record_validation_message(std::string message) {
  std::lock_guard lock(messages_mutex_);
  messages_.push_back(std::move(message));
}

Result<std::vector<DeviceInfo>> Context::enumerate_devices() {
  Result<VkInstance> instance = create_instance(ContextOptions{}, nullptr);
  if (!instance) return instance.error();
  Result<std::vector<VkPhysicalDevice>> devices = physical_devices(*instance);
  std::vector<DeviceInfo> infos;
  if (devices) {
    for (VkPhysicalDevice device : *devices) {
      const ChainedProperties chained(device);
      const VkPhysicalDeviceProperties& props = chained.properties.properties;
      infos.push_back(DeviceInfo{props.deviceName, props.deviceType, props.apiVersion,
                                 std::string(chained.driver.driverName) + " " + chained.driver.driverInfo,
                                 chained.subgroup.subgroupSize, device_local_bytes(device)});
    }
  }
  vkDestroyInstance(*instance, nullptr);
  if (!devices) return devices.error();
  return infos;
}

Error Context::device_lost_error() const {
  return make_error("Vulkan: the device '" + device_name() + "' was lost (VK_ERROR_DEVICE_LOST from " + lost_call_ +
                    "; a driver reset, a GPU hang or a removed device): the searches in flight have no results and "
                    "nothing more can run on this Context; destroy its searches and the Context and create new ones "
                    "(or use a CPU backend)");
}

void Context::mark_device_lost(std::string call) const {
  if (lost_call_.empty()) lost_call_ = std::move(call);
}

void Context::inject_fault(std::string call, VkResult result, std::uint32_t count) {
  faults_.push_back({std::move(call), result, count});
}

std::optional<VkResult> Context::take_injected_fault(std::string_view call) const {
  for (auto fault = faults_.begin(); fault != faults_.end(); ++fault) {
    if (fault->call != call || fault->count == 0) continue;
    const VkResult result = fault->result;
    if (--fault->count == 0) faults_.erase(fault);
    return result;
  }
  return std::nullopt;
}

}  // namespace mmvk::vulkan
