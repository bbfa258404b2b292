// VulkanClusterSearch: the cluster kernels on VulkanSearch's slots.
#include "mmvk/vulkan/vulkan_cluster_search.hpp"

#include <string>
#include <utility>

#include "cluster_kernel.hpp"
#include "vulkan_search_impl.hpp"

namespace mmvk::vulkan {

namespace {

using detail::ClusterKernel;
using detail::PageCommands;

class ClusterRun final : public detail::SearchKernel {
 public:
  explicit ClusterRun(ClusterKernel kernel) : kernel_(std::move(kernel)) {}
  // The cluster kernels keep their scratch in set 1; one pair keeps set
  // 0's binding valid.
  std::uint64_t scratch_pairs_per_query(std::uint32_t) const override { return 1; }
  Status record(const Context& context, const PageCommands& page) const override {
    return kernel_.record(context, page.commands, page.slot, page.descriptors, page.count, page.k);
  }
  // Counted on the GPU.
  std::uint64_t rows_evaluated(std::uint32_t slot, std::uint32_t count) const override {
    return kernel_.rows_evaluated(slot, count);
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> warm_up_variants() const override {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> variants;
    for (const std::uint32_t kc : kernel_.k_classes()) variants.emplace_back(kc, 1);
    return variants;
  }
  std::vector<std::string_view> kernel_names() const override { return kernel_.kernel_names(); }
  std::uint64_t device_bytes() const override { return kernel_.device_bytes(); }

 private:
  ClusterKernel kernel_;
};

}  // namespace

VulkanClusterSearch::VulkanClusterSearch(std::unique_ptr<Impl> impl, bool exact)
    : VulkanSearch(std::move(impl)), exact_(exact) {}

Result<std::unique_ptr<VulkanClusterSearch>> VulkanClusterSearch::create(Context& context, const Database& database,
                                                                         const ClusterTable& table,
                                                                         const VulkanSearchOptions& options,
                                                                         const VulkanClusterOptions& cluster_options) {
  if (context.device_lost()) return context.device_lost_error();
  if (const Status valid = validate_cluster_table(table, database); !valid) {
    return make_error("VulkanSearch: the cluster table does not belong to this database or is malformed: " +
                      valid.message());
  }
  MMVK_ASSIGN_OR_RETURN(std::unique_ptr<Impl> impl, Impl::begin(context, database, options, false));
  MMVK_TRY(impl->create_slots(1));
  detail::ClusterKernelOptions kernel_options;
  kernel_options.max_batch = options.max_batch;
  kernel_options.max_k = options.max_k;
  kernel_options.slots = options.slots;
  kernel_options.nprobe = cluster_options.nprobe;
  kernel_options.scratch_bytes = cluster_options.scratch_bytes;
  kernel_options.force_staging = options.force_staging_upload;
  for (const SearchSlot& slot : impl->slots) kernel_options.slot_queries.push_back({&slot.queries, &slot.params, &slot.weights});
  MMVK_ASSIGN_OR_RETURN(ClusterKernel kernel, ClusterKernel::create(context, impl->command_pool.get(),
                                                                    impl->set_layout.get(), impl->shape, database,
                                                                    table, kernel_options));
  impl->kernel = std::make_unique<ClusterRun>(std::move(kernel));
  MMVK_TRY(impl->finish());
  const bool exact = cluster_options.nprobe == 0;
  return std::unique_ptr<VulkanClusterSearch>(new VulkanClusterSearch(std::move(impl), exact));
}

}  // namespace mmvk::vulkan
