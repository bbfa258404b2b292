#include "crowd_backend.hpp"

#include <algorithm>

#include "mmvk/cluster_search.hpp"
#include "mmvk/cluster_table.hpp"
#include "mmvk/fast_search.hpp"
#include "mmvk/reference_search.hpp"

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/vulkan_async_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#endif

namespace mmvk::crowd {

namespace {

// Queries per backend call: the controller's chunk size and Vulkan's
// max_batch.
constexpr std::uint32_t kMaxBatch = 1024;

#if defined(MMVK_HAS_VULKAN)
const char* device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU (software Vulkan)";
    default: return "other";
  }
}

Status make_vulkan(CrowdSearch& out, const std::string& name, std::optional<std::uint32_t> device,
                   const Database& database, std::uint32_t agents, const ClusterTable* clusters) {
  vulkan::ContextOptions context_options;
  context_options.device_index = device;
  context_options.application_name = "mmvk crowd";
  MMVK_ASSIGN_OR_RETURN(out.context, vulkan::Context::create(context_options));
  vulkan::VulkanSearchOptions options;
  options.max_batch = std::min(kMaxBatch, std::max<std::uint32_t>(agents, 1));
  options.max_k = 1;
  if (name == "vulkan-clusters") options.mode = vulkan::SearchMode::ClustersExact;
  if (name == "vulkan-nprobe") options.mode = vulkan::SearchMode::NProbe;
  MMVK_ASSIGN_OR_RETURN(auto search, vulkan::VulkanSearch::create(*out.context, database, options, clusters));
  out.deferred = std::make_unique<vulkan::VulkanAsyncSearch>(*search, agents);
  out.backend = std::move(search);
  // Which device: the index the loader gives it, so --device N can name it.
  std::uint32_t index = device.value_or(0);
  if (!device) {
    if (auto devices = vulkan::Context::enumerate_devices(); devices) {
      for (std::uint32_t i = 0; i < devices->size(); ++i) {
        if ((*devices)[i].name == out.context->device_name()) {
          index = i;
          break;
        }
      }
    }
  }
  out.device = out.context->device_name() + " (Vulkan device " + std::to_string(index) + ", " +
               device_type_name(out.context->properties().deviceType) + ")";
  return {};
}
#endif

}  // namespace

std::string crowd_backend_names() {
  std::string names = "reference, fast-brute, fast-box (alias fast), clusters, clusters-nprobe";
#if defined(MMVK_HAS_VULKAN)
  names += ", vulkan, vulkan-clusters, vulkan-nprobe";
#endif
  return names;
}

Result<CrowdSearch> make_crowd_search(const std::string& name, std::optional<std::uint32_t> device,
                                      const Database& database, std::uint32_t agents, ThreadPool& pool) {
  CrowdSearch out;
  const std::string cpu = "cpu, " + std::to_string(pool.thread_count()) + " threads";
  const bool clustered = name == "clusters" || name == "clusters-nprobe" || name == "vulkan-clusters" ||
                         name == "vulkan-nprobe";
  std::optional<ClusterTable> table;
  if (clustered) {
    MMVK_ASSIGN_OR_RETURN(table, train_cluster_table(database, KMeansParams{}));
  }
  if (name == "reference") {
    out.backend = std::make_unique<ReferenceSearch>(database);
    out.device = "cpu, 1 thread";
  } else if (name == "fast-brute" || name == "fast-box" || name == "fast") {
    out.backend = std::make_unique<FastSearch>(database, pool, FastSearchOptions{.prune = name != "fast-brute"});
    out.device = cpu;
  } else if (name == "clusters" || name == "clusters-nprobe") {
    ClusterSearchOptions options;
    if (name == "clusters-nprobe") options.nprobe = 4;
    MMVK_ASSIGN_OR_RETURN(out.backend, ClusterSearch::create(database, *table, pool, options));
    out.device = cpu;
  } else if (name == "vulkan" || name == "vulkan-clusters" || name == "vulkan-nprobe") {
#if defined(MMVK_HAS_VULKAN)
    MMVK_TRY(make_vulkan(out, name, device, database, agents, table ? &*table : nullptr));
    return out;
#else
    return make_error("backend '" + name + "': this mmvk was built without Vulkan (MMVK_BUILD_VULKAN=OFF)");
#endif
  } else {
    return make_error("unknown backend '" + name + "' (known: " + crowd_backend_names() + ")");
  }
  if (device) return make_error("--device picks a Vulkan device; backend '" + name + "' runs on the CPU");
  out.deferred = std::make_unique<DeferredSearch>(*out.backend, kMaxBatch, agents);
  return out;
}

}  // namespace mmvk::crowd
