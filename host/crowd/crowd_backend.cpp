#include "crowd_backend.hpp"

#include <algorithm>
#include <utility>

#include "driver_cache.hpp"
#include "mmvk/backends.hpp"

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/lazy_context.hpp"
#endif

namespace mmvk::crowd {

// Defined in this one file: the header only holds a pointer to it.
#if defined(MMVK_HAS_VULKAN)
struct CrowdDevice {
  explicit CrowdDevice(vulkan::LazyContextOptions options) : context(std::move(options)) {}
  vulkan::LazyContext context;
};
#else
struct CrowdDevice {};
#endif

CrowdSearch::CrowdSearch() = default;
CrowdSearch::~CrowdSearch() = default;
CrowdSearch::CrowdSearch(CrowdSearch&&) noexcept = default;
CrowdSearch& CrowdSearch::operator=(CrowdSearch&&) noexcept = default;

namespace {

// Queries per Vulkan submit (max_batch); a larger tick is paged by the search.
constexpr std::uint32_t kPageQueries = 1024;

#if defined(MMVK_HAS_VULKAN)
const char* device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU, software Vulkan";
    default: return "other";
  }
}

// "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan device 0, CPU, software Vulkan)":
// the index the loader gives the device, so --device N can name it.
std::string describe_device(const vulkan::Context& context, std::optional<std::uint32_t> requested) {
  std::uint32_t index = requested.value_or(0);
  if (!requested) {
    if (auto devices = vulkan::Context::enumerate_devices(); devices) {
      for (std::uint32_t i = 0; i < devices->size(); ++i) {
        if ((*devices)[i].name == context.device_name()) {
          index = i;
          break;
        }
      }
    }
  }
  return context.device_name() + " (Vulkan device " + std::to_string(index) + ", " +
         device_type_name(context.properties().deviceType) + ")";
}
#endif

// The library's registry: the CPU backends, and the Vulkan ones on a
// context created (on `device`) only when one of them is made.
BackendRegistry crowd_registry([[maybe_unused]] CrowdSearch& out, [[maybe_unused]] std::optional<std::uint32_t> device,
                               [[maybe_unused]] const std::filesystem::path& cache_dir) {
  BackendRegistry registry = cpu_backends();
#if defined(MMVK_HAS_VULKAN)
  vulkan::LazyContextOptions options;
  options.context.device_index = device;
  options.context.application_name = "mmvk crowd";
  options.cache_directory = cache_dir;
  out.vulkan = std::make_unique<CrowdDevice>(std::move(options));
  // The names are distinct from the CPU ones; a clash would be a bug in mmvk.
  (void)out.vulkan->context.add_backends(registry);
#endif
  return registry;
}

}  // namespace

std::string resolve_backend(const std::string& name, [[maybe_unused]] std::optional<std::uint32_t> device,
                            std::uint32_t frames, std::string& reason) {
  reason.clear();
  if (name != "auto") return name;
#if defined(MMVK_HAS_VULKAN)
  if (device) {
    reason = "auto: Vulkan device " + std::to_string(*device) + " was asked for";
    return kAutoGpuBackend;
  }
  const Result<std::vector<vulkan::DeviceInfo>> devices = vulkan::Context::enumerate_devices();
  if (devices) {
    for (const vulkan::DeviceInfo& info : *devices) {
      if (info.type == VK_PHYSICAL_DEVICE_TYPE_CPU || info.type == VK_PHYSICAL_DEVICE_TYPE_OTHER) continue;
      reason = "auto: " + info.name + " is a GPU";
      return kAutoGpuBackend;
    }
  }
  reason = devices && !devices->empty() ? "auto: no GPU, " + devices->front().name + " runs Vulkan on the CPU"
                                        : std::string("auto: no Vulkan device");
#else
  reason = "auto: built without Vulkan";
#endif
  const bool large = frames > kAutoClusterFrames;
  reason += std::string("; the fastest CPU backend for ") + (large ? "over " : "up to ") +
            std::to_string(kAutoClusterFrames) + " frames";
  return large ? kAutoLargeCpuBackend : kAutoCpuBackend;
}

std::string crowd_backend_help() {
  CrowdSearch unused;
  const BackendRegistry registry = crowd_registry(unused, std::nullopt, {});
  // "auto" first, in the registry's layout: a rule over its entries, not one of them.
  std::size_t width = 0;
  for (const BackendEntry& entry : registry.entries()) width = std::max(width, entry.name.size());
  const std::string automatic = "  auto" + std::string(std::max<std::size_t>(width, 4) + 2 - 4, ' ') +
                                "the default: " + kAutoGpuBackend + " on a GPU, else " + kAutoCpuBackend + " (" +
                                kAutoLargeCpuBackend + " over " + std::to_string(kAutoClusterFrames) + " frames)\n";
  return automatic + registry.help();
}

Result<CrowdSearch> make_crowd_search(const std::string& asked, std::optional<std::uint32_t> device,
                                      const Database& database, std::uint32_t agents, ThreadPool& pool,
                                      const std::filesystem::path& cache_dir) {
  CrowdSearch out;
  const std::string name = resolve_backend(asked, device, database.frame_count(), out.choice);
  const BackendRegistry registry = crowd_registry(out, device, cache_dir);
  const BackendEntry* entry = registry.find(name);
  if (!entry) return make_error("unknown backend '" + name + "' (known: auto, " + registry.names() + ")");
  BackendSpec spec;
  spec.name = name;
  spec.pool = &pool;
  spec.max_batch = std::min(kPageQueries, std::max<std::uint32_t>(agents, 1));
  spec.max_k = 1;
  // Before the first Vulkan context: a full disk under the driver's own
  // shader cache would crash the driver (driver_cache.hpp).
  if (name.starts_with("vulkan")) out.driver_cache_note = guard_driver_shader_cache();
  MMVK_ASSIGN_OR_RETURN(out.backend, registry.make(spec, database));
  out.deferred = out.backend->make_async(agents);
#if defined(MMVK_HAS_VULKAN)
  // The registry creates the context only for a Vulkan backend.
  if (const vulkan::Context* context = out.vulkan->context.created()) {
    out.device = describe_device(*context, device);
    out.pipeline_cache_note = out.vulkan->context.pipeline_cache_note();
    return out;
  }
#endif
  if (device) return make_error("--device picks a Vulkan device; backend '" + name + "' runs on the CPU");
  out.device = name == "reference" ? std::string("cpu, 1 thread")
                                   : "cpu, " + std::to_string(pool.thread_count()) + " threads";
  return out;
}

Status save_crowd_pipeline_cache([[maybe_unused]] const CrowdSearch& search) {
#if defined(MMVK_HAS_VULKAN)
  if (search.vulkan) return search.vulkan->context.save_pipeline_cache();
#endif
  return {};
}

}  // namespace mmvk::crowd
