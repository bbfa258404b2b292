#include "mmvk/vulkan/backends.hpp"

#include <memory>
#include <optional>
#include <utility>

#include "mmvk/vulkan/vulkan_brute_force.hpp"
#include "mmvk/vulkan/vulkan_cluster_search.hpp"

namespace mmvk::vulkan {

namespace {

BackendFactory brute_force_factory(const ContextSource& context, const VulkanSearchOptions& options) {
  return [context, options](const BackendSpec& spec, const Database& database) -> Result<std::unique_ptr<SearchBackend>> {
    if (!context) return make_error("backend '" + spec.name + "': no Vulkan context source");
    MMVK_ASSIGN_OR_RETURN(Context* device, context());
    MMVK_ASSIGN_OR_RETURN(std::unique_ptr<VulkanBruteForce> search, VulkanBruteForce::create(*device, database, options));
    return std::unique_ptr<SearchBackend>(std::move(search));
  };
}

// `probe`: vulkan-nprobe (spec.nprobe clusters per query), else exact.
BackendFactory cluster_factory(const ContextSource& context, const VulkanSearchOptions& options, bool probe) {
  return [context, options, probe](const BackendSpec& spec,
                                   const Database& database) -> Result<std::unique_ptr<SearchBackend>> {
    if (!context) return make_error("backend '" + spec.name + "': no Vulkan context source");
    if (probe && spec.nprobe == 0) return make_error("backend '" + spec.name + "': nprobe must be at least 1");
    MMVK_ASSIGN_OR_RETURN(Context* device, context());
    std::optional<ClusterTable> trained;
    MMVK_ASSIGN_OR_RETURN(const ClusterTable* table, spec_cluster_table(spec, database, trained));
    VulkanClusterOptions cluster_options;
    cluster_options.nprobe = probe ? spec.nprobe : 0;
    MMVK_ASSIGN_OR_RETURN(std::unique_ptr<VulkanClusterSearch> search,
                          VulkanClusterSearch::create(*device, database, *table, options, cluster_options));
    return std::unique_ptr<SearchBackend>(std::move(search));
  };
}

}  // namespace

Status add_backends(BackendRegistry& registry, Context& context, const VulkanSearchOptions& options) {
  return add_backends(registry, [&context]() -> Result<Context*> { return &context; }, options);
}

Status add_backends(BackendRegistry& registry, ContextSource context, const VulkanSearchOptions& options) {
  MMVK_TRY(registry.add({"vulkan-brute", "GPU, exact, every row", brute_force_factory(context, options)}));
  MMVK_TRY(registry.add({"vulkan-clusters", "GPU, exact, rows pruned by k-means cluster bounds",
                         cluster_factory(context, options, false), true}));
  MMVK_TRY(registry.add({"vulkan-nprobe", "GPU, approximate: the nprobe clusters with the nearest centroids",
                         cluster_factory(context, options, true), true, true}));
  return {};
}

}  // namespace mmvk::vulkan
