#include "backends/crowd_backend.hpp"

#include <algorithm>
#include <utility>

#include "mmvk/search/backends.hpp"

namespace mmvk::crowd {

namespace {

// Queries per Vulkan submit (max_batch); a larger tick is paged by the search.
constexpr std::uint32_t kPageQueries = 1024;

}  // namespace

std::string resolve_backend(const std::string& name, std::optional<std::uint32_t> device,
                            std::uint32_t frames, std::string& reason) {
  reason.clear();
  if (name != "auto") return name;
  const std::optional<std::vector<VulkanDeviceSummary>> devices = HostBackends::vulkan_devices();
  if (devices && device) {
    reason = "auto: Vulkan device " + std::to_string(*device) + " was asked for";
    return kAutoGpuBackend;
  }
  if (devices) {
    for (const VulkanDeviceSummary& info : *devices) {
      if (!info.gpu) continue;
      reason = "auto: " + info.name + " is a GPU";
      return kAutoGpuBackend;
    }
  }
  if (!devices) {
    reason = "auto: built without Vulkan";
  } else {
    reason = devices->empty() ? std::string("auto: no Vulkan device")
                              : "auto: no GPU, " + devices->front().name + " runs Vulkan on the CPU";
  }
  const bool large = frames > kAutoClusterFrames;
  reason += std::string("; the fastest CPU backend for ") + (large ? "over " : "up to ") +
            std::to_string(kAutoClusterFrames) + " frames";
  return large ? kAutoLargeCpuBackend : kAutoCpuBackend;
}

std::string crowd_backend_help() {
  const HostBackends backends;
  const BackendRegistry& registry = backends.registry();
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
  HostBackendOptions options;
  options.application_name = "mmvk crowd";
  options.device = device;
  options.cache_directory = cache_dir;
  out.backends = HostBackends(std::move(options));
  if (!out.backends.registry().find(name)) {
    return make_error("unknown backend '" + name + "' (known: auto, " + out.backends.registry().names() + ")");
  }
  BackendSpec spec;
  spec.name = name;
  spec.pool = &pool;
  DeviceSearchLimits limits;
  limits.max_batch = std::min(kPageQueries, std::max<std::uint32_t>(agents, 1));
  limits.max_k = 1;
  MMVK_ASSIGN_OR_RETURN(out.backend, out.backends.make(spec, database, limits));
  out.deferred = out.backend->make_async(agents);
  out.device = out.backend->device();
  out.driver_cache_note = out.backends.driver_cache_note();
  out.pipeline_cache_note = out.backends.pipeline_cache_note();
  return out;
}

Status save_crowd_pipeline_cache(const CrowdSearch& search) { return search.backends.save_pipeline_cache(); }

}  // namespace mmvk::crowd
