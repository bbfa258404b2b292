// The Vulkan context: instance, physical device, logical device and one
// compute queue. Either mmvk creates them (Context::create) or it adopts the
// embedding application's own (Context::adopt), e.g. a crowd simulation
// that already renders with Vulkan; adopted handles are used, never
// destroyed. No global state: every VulkanSearch takes a Context&.
//
// Pipeline cache: every pipeline of every search on a Context goes through
// one VkPipelineCache. The application owns its contents: it passes a blob
// from an earlier run in (ContextOptions, merge_pipeline_cache_data(), or
// its own cache to adopt()) and takes the current one out
// (pipeline_cache_data()) to store it; mmvk writes no files
// (mmvk/vulkan/pipeline_cache_file.hpp is an opt-in helper that does, in a
// directory the application names). Drivers that compile at pipeline
// creation skip what the blob holds; lavapipe compiles at the first dispatch
// and keeps its own cache (Mesa's shader cache), see VulkanSearch::warm_up().
//
// Not thread-safe: use a Context (and the searches on it) from one thread at
// a time. With an adopted queue, the application must not use that queue
// concurrently with mmvk's submit calls (Vulkan's external sync rule).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

#include "mmvk/common/status.hpp"

namespace mmvk::vulkan {

// Lowers device limits as mmvk sees them, never raises them; 0 keeps the
// device's own. For an application that keeps part of the device for its
// own buffers, and for testing mmvk's "too large for this device" errors on
// any device.
struct DeviceLimitCaps {
  std::uint32_t max_storage_buffer_range = 0;   // bytes, caps maxStorageBufferRange
  std::uint32_t max_texel_buffer_elements = 0;  // texels, caps maxTexelBufferElements
  VkDeviceSize heap_bytes = 0;                  // bytes, caps the size of every memory heap
};

struct ContextOptions {
  // Index into vkEnumeratePhysicalDevices; nullopt picks the best device:
  // discrete GPU, then integrated, then virtual, then CPU (lavapipe).
  std::optional<std::uint32_t> device_index;
  // Enables VK_LAYER_KHRONOS_validation (with synchronization validation)
  // and a debug messenger that collects every warning and error.
  bool validation = false;
  std::string application_name = "mmvk";
  // Initial contents of the pipeline cache: a blob from
  // Context::pipeline_cache_data() of an earlier run. Empty = start empty.
  // A blob for another device or driver version, or a malformed one, is
  // ignored (pipeline_cache_note() says why); never an error.
  std::vector<std::byte> pipeline_cache_data;
  DeviceLimitCaps limit_caps;
};

// The application's handles, for Context::adopt. The device must support
// Vulkan 1.2 and `queue` must come from `queue_family`, which must support
// compute. mmvk enables no device feature or extension of its own.
struct AdoptedDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;
};

// One line per physical device, for tools and error messages.
struct DeviceInfo {
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t api_version = 0;
  std::string driver;                   // driver name and version text
  std::uint32_t subgroup_size = 0;      // lanes
  VkDeviceSize device_local_bytes = 0;  // the largest device-local heap
};

class Context {
 public:
  // Errors (never exits): no Vulkan driver or device, the requested index
  // out of range, no compute queue, validation requested but not installed.
  static Result<std::unique_ptr<Context>> create(const ContextOptions& options = {});
  // `pipeline_cache`: the application's own cache, used and never destroyed
  // (it must outlive the Context); null = mmvk creates an empty one (fill it
  // with merge_pipeline_cache_data()).
  static Result<std::unique_ptr<Context>> adopt(const AdoptedDevice& handles,
                                                VkPipelineCache pipeline_cache = VK_NULL_HANDLE);

  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queue_family() const { return queue_family_; }
  bool owns_device() const { return owns_device_; }

  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_properties_; }
  std::uint32_t subgroup_size() const { return subgroup_size_; }
  // Valid bits of the queue's timestamps; 0 = no timestamp support.
  std::uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
  std::string device_name() const { return properties_.deviceName; }
  // The device as a host shows it (every Vulkan backend's device()): its
  // name, the index vkEnumeratePhysicalDevices gives it (what
  // ContextOptions::device_index and the hosts' --device take) and its type:
  // "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan device 0, CPU, software Vulkan)".
  const std::string& description() const { return description_; }
  // VkPhysicalDeviceMaintenance3Properties::maxMemoryAllocationSize.
  VkDeviceSize max_memory_allocation_size() const { return max_allocation_size_; }

  // The cache every pipeline on this Context is created through.
  VkPipelineCache pipeline_cache() const { return pipeline_cache_; }
  // The cache's current contents (vkGetPipelineCacheData): the initial blob
  // plus what the searches on this Context have built since. Store it and
  // pass it back as ContextOptions::pipeline_cache_data in the next run.
  Result<std::vector<std::byte>> pipeline_cache_data() const;
  // Adds a blob's pipelines to the cache (for a blob found after the
  // Context was made, e.g. in a file named after its device). An error
  // says why the blob was not used; the cache is then unchanged and usable.
  Status merge_pipeline_cache_data(std::span<const std::byte> blob);
  // Why the initial blob was ignored; empty when none was given or it was
  // used. For a note to the user: an ignored blob is never an error.
  const std::string& pipeline_cache_note() const { return pipeline_cache_note_; }

  // Validation messages (warnings and errors) collected so far; empty when
  // validation is off. Tests assert it stays empty.
  std::vector<std::string> validation_messages() const;
  std::size_t validation_message_count() const;

  // The physical devices the loader reports (creates a throwaway instance).
  static Result<std::vector<DeviceInfo>> enumerate_devices();

  // For the debug messenger callback only.
  void record_validation_message(std::string message);

  // Device loss. Once a submit or a wait reports VK_ERROR_DEVICE_LOST (a
  // driver reset, a GPU hang, a removed device), the device is gone for
  // good: every later create(), submit() and wait() of a search on this
  // Context fails at once with device_lost_error(), and nothing crashes.
  // Recover by destroying the searches and the Context and creating new
  // ones (or by falling back to a CPU backend).
  bool device_lost() const { return !lost_call_.empty(); }
  // Says the device was lost, in which call, and what to do.
  Error device_lost_error() const;
  // For mmvk's checks: records the loss reported by `call`.
  void mark_device_lost(std::string call) const;

  // Fault injection, for tests of mmvk's error paths and of an
  // application's own handling of them: the next `count` calls named `call`
  // that go through mmvk's submit and wait paths ("vkQueueSubmit",
  // "vkWaitForFences", "vkGetFenceStatus") report `result`. A submit with
  // an injected fault is not made; a wait reports it after the real wait,
  // so no work is left running behind the error.
  void inject_fault(std::string call, VkResult result, std::uint32_t count = 1);
  // For mmvk's checks: the injected result of `call`, consuming one.
  std::optional<VkResult> take_injected_fault(std::string_view call) const;

 private:
  Context() = default;
  Status init_device_info(const DeviceLimitCaps& caps);
  void init_description();
  Status init_pipeline_cache(VkPipelineCache adopted, std::span<const std::byte> initial);

  // Declaration order = reverse destruction order; the destructor destroys
  // only what this Context created (owns_*).
  bool owns_instance_ = false;
  bool owns_device_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  bool owns_pipeline_cache_ = false;
  VkPipelineCache pipeline_cache_ = VK_NULL_HANDLE;
  std::string pipeline_cache_note_;

  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  std::uint32_t subgroup_size_ = 1;
  std::uint32_t timestamp_valid_bits_ = 0;
  VkDeviceSize max_allocation_size_ = 0;
  std::string description_;

  // Mutable: device loss and injected faults are observed by the const
  // paths that submit and wait (the Context is used from one thread).
  struct InjectedFault {
    std::string call;
    VkResult result = VK_SUCCESS;
    std::uint32_t count = 0;
  };
  mutable std::vector<InjectedFault> faults_;
  mutable std::string lost_call_;

  mutable std::mutex messages_mutex_;
  std::vector<std::string> messages_;
};

}  // namespace mmvk::vulkan
