#include "mmvk/vulkan/backends.hpp"

#include <memory>
#include <optional>
#include <utility>

namespace mmvk::vulkan {

namespace {

BackendFactory factory(const ContextSource& context, const VulkanSearchOptions& base, SearchMode mode) {
  return [context, base, mode](const BackendSpec& spec, const Database& database)
             -> Result<std::unique_ptr<SearchBackend>> {
    if (!context) return make_error("backend '" + spec.name + "': no Vulkan context source");
    MMVK_ASSIGN_OR_RETURN(Context* device, context());
    VulkanSearchOptions options = base;
    options.mode = mode;
    options.nprobe = spec.nprobe;
    options.max_batch = spec.max_batch;
    options.max_k = spec.max_k;
    options.max_tile = spec.max_tile;
    options.warm_up = spec.warm_up;
    std::optional<ClusterTable> trained;
    const ClusterTable* table = nullptr;
    if (mode != SearchMode::BruteForce) {
      MMVK_ASSIGN_OR_RETURN(table, spec_cluster_table(spec, database, trained));
    }
    MMVK_ASSIGN_OR_RETURN(std::unique_ptr<VulkanSearch> search, VulkanSearch::create(*device, database, options, table));
    return std::unique_ptr<SearchBackend>(std::move(search));
  };
}

}  // namespace

Status add_backends(BackendRegistry& registry, Context& context, const VulkanSearchOptions& base) {
  return add_backends(registry, [&context]() -> Result<Context*> { return &context; }, base);
}

Status add_backends(BackendRegistry& registry, ContextSource context, const VulkanSearchOptions& base) {
  MMVK_TRY(registry.add({"vulkan-brute", "GPU, exact, every row", factory(context, base, SearchMode::BruteForce)}));
  MMVK_TRY(registry.add({"vulkan-clusters", "GPU, exact, rows pruned by k-means cluster bounds",
                         factory(context, base, SearchMode::ClustersExact), true}));
  MMVK_TRY(registry.add({"vulkan-nprobe", "GPU, approximate: the nprobe clusters with the nearest centroids",
                         factory(context, base, SearchMode::NProbe), true, true}));
  return {};
}

}  // namespace mmvk::vulkan
