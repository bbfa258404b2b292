#include "backends/host_backends.hpp"

#include <utility>

#include "backends/driver_cache.hpp"

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/lazy_context.hpp"
#endif

namespace mmvk::crowd {

#if defined(MMVK_HAS_VULKAN)
struct HostDevice {
  explicit HostDevice(vulkan::LazyContextOptions options) : context(std::move(options)) {}
  vulkan::LazyContext context;
};
#else
struct HostDevice {};
#endif

namespace {

// The CPU backends, and the Vulkan ones on `device`'s context with `limits`.
BackendRegistry assemble([[maybe_unused]] HostDevice& device, [[maybe_unused]] const DeviceSearchLimits& limits) {
  BackendRegistry registry = cpu_backends();
#if defined(MMVK_HAS_VULKAN)
  vulkan::VulkanSearchOptions options;
  options.max_batch = limits.max_batch;
  options.max_k = limits.max_k;
  options.max_tile = limits.max_tile;
  options.warm_up = limits.warm_up;
  // The Vulkan names differ from the CPU ones: a clash is a bug in mmvk.
  (void)device.context.add_backends(registry, options);
#endif
  return registry;
}

std::unique_ptr<HostDevice> make_device([[maybe_unused]] const HostBackendOptions& options) {
#if defined(MMVK_HAS_VULKAN)
  vulkan::LazyContextOptions lazy;
  lazy.context.device_index = options.device;
  lazy.context.application_name = options.application_name;
  lazy.cache_directory = options.cache_directory;
  return std::make_unique<HostDevice>(std::move(lazy));
#else
  return std::make_unique<HostDevice>();
#endif
}

}  // namespace

HostBackends::HostBackends(HostBackendOptions options)
    : options_(std::move(options)), device_(make_device(options_)), listed_(assemble(*device_, {})) {}

HostBackends::~HostBackends() = default;
HostBackends::HostBackends(HostBackends&&) noexcept = default;
HostBackends& HostBackends::operator=(HostBackends&&) noexcept = default;

bool HostBackends::on_cpu(std::string_view name) { return cpu_backends().find(name) != nullptr; }

std::optional<std::vector<VulkanDeviceSummary>> HostBackends::vulkan_devices() {
#if defined(MMVK_HAS_VULKAN)
  std::vector<VulkanDeviceSummary> summaries;
  if (const Result<std::vector<vulkan::DeviceInfo>> devices = vulkan::Context::enumerate_devices(); devices) {
    for (const vulkan::DeviceInfo& info : *devices) {
      const bool gpu = info.type != VK_PHYSICAL_DEVICE_TYPE_CPU && info.type != VK_PHYSICAL_DEVICE_TYPE_OTHER;
      summaries.push_back({info.name, gpu});
    }
  }
  return summaries;
#else
  return std::nullopt;
#endif
}

Result<std::unique_ptr<SearchBackend>> HostBackends::make(const BackendSpec& spec, const Database& database,
                                                          const DeviceSearchLimits& limits) {
  const BackendRegistry registry = assemble(*device_, limits);
  if (registry.find(spec.name) == nullptr) return registry.make(spec, database);  // the unknown name's error
  const bool cpu = on_cpu(spec.name);
  if (cpu && options_.device) {
    return make_error(options_.device_option + " picks a Vulkan device; backend '" + spec.name + "' runs on the CPU");
  }
  // Before the first Vulkan context (driver_cache.hpp): a full disk under
  // the driver's own shader cache would crash the driver.
  if (!cpu && driver_cache_note_.empty()) driver_cache_note_ = guard_driver_shader_cache();
  return registry.make(spec, database);
}

std::string HostBackends::pipeline_cache_note() const {
#if defined(MMVK_HAS_VULKAN)
  return device_->context.pipeline_cache_note();
#else
  return {};
#endif
}

Status HostBackends::save_pipeline_cache() const {
#if defined(MMVK_HAS_VULKAN)
  return device_->context.save_pipeline_cache();
#else
  return {};
#endif
}

}  // namespace mmvk::crowd
